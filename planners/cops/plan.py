"""Plans Π = (Πt, Πc) as plain data.

A :class:`Plan` holds one trajectory s_0 s_1 ... s_T per robot (Πt) and the
communication collection Πc of tuples (t, r, r', b): at time step t robot r sends
information b to robot r'. Information labels are robot names (the information
that robot held at t = 0) and :data:`MASTER` (``"m"``), the plan itself.

Time step t means: first the communication of step t happens at the locations
s_t, then every robot moves from s_t to s_{t+1}. Within one step the tuples are
listed in a causal order (a robot receives a label before it passes it on), so an
executive can process them in list order.

JSON (``Plan.to_json``), keys sorted::

    {"communications": [[t, sender, receiver, info], ...],
     "explore": {robot: frontier},      # robots that explore from their final location
     "holdings": {robot: [labels]},      # information each robot holds at t = 0
     "horizon": T,
     "masters": [robots holding m at t = 0],
     "meta": {"cost": .., "gap": .., "objective": .., "reward": .., "solve_time_s": ..,
              "solver": .., "status": ..},
     "phase": "pre" | "post" | "cycle-pre" | ...,
     "requirements": [{"sinks": [...], "sources": [...]}],
     "trajectories": {robot: [s_0, ..., s_T]},
     "version": 1}
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

MASTER = "m"
PLAN_FORMAT_VERSION = 1


@dataclass(frozen=True, order=True)
class Communication:
    """(t, r, r', b): at step ``t`` robot ``sender`` sends ``info`` to ``receiver``."""

    t: int
    sender: str
    receiver: str
    info: str

    def as_list(self) -> list[Any]:
        return [self.t, self.sender, self.receiver, self.info]


@dataclass(frozen=True)
class Requirement:
    """An intermittent-connectivity constraint (src, snk): every sink receives, by the
    end of the plan, all information every source held at t = 0."""

    sources: tuple[str, ...]
    sinks: tuple[str, ...]

    def as_dict(self) -> dict[str, list[str]]:
        return {"sinks": list(self.sinks), "sources": list(self.sources)}


@dataclass(frozen=True)
class Step:
    """Robot's part of time step t: it is at ``location``, takes part in ``sends`` and
    ``receives`` (communications of step t), then does ``action``:
    ``"move"`` (to ``next_location``), ``"stay"``, ``"explore"`` (last step of a
    pre-exploration plan, at a frontier) or ``"end"``."""

    t: int
    location: str
    action: str
    next_location: str | None
    sends: tuple[Communication, ...]
    receives: tuple[Communication, ...]


@dataclass
class Plan:
    horizon: int
    trajectories: dict[str, list[str]]
    communications: list[Communication] = field(default_factory=list)
    masters: list[str] = field(default_factory=list)
    holdings: dict[str, list[str]] = field(default_factory=dict)
    requirements: list[Requirement] = field(default_factory=list)
    explore: dict[str, str] = field(default_factory=dict)
    phase: str = "plan"
    meta: dict[str, Any] = field(default_factory=dict)

    # -- access ----------------------------------------------------------------------
    @property
    def robots(self) -> list[str]:
        return sorted(self.trajectories)

    def location(self, robot: str, t: int) -> str:
        traj = self.trajectories[robot]
        return traj[min(max(t, 0), len(traj) - 1)]

    def final_positions(self) -> dict[str, str]:
        return {r: traj[-1] for r, traj in self.trajectories.items()}

    def communications_at(self, t: int) -> list[Communication]:
        return [c for c in self.communications if c.t == t]

    def moves(self, robot: str) -> int:
        """Number of transitions (moves to another location) of ``robot``."""
        traj = self.trajectories[robot]
        return sum(1 for a, b in zip(traj, traj[1:]) if a != b)

    def steps(self, robot: str) -> list[Step]:
        traj = self.trajectories[robot]
        out = []
        for t, loc in enumerate(traj):
            nxt = traj[t + 1] if t + 1 < len(traj) else None
            if nxt is None:
                action = "explore" if robot in self.explore else "end"
            else:
                action = "move" if nxt != loc else "stay"
            out.append(Step(t, loc, action, nxt,
                            tuple(c for c in self.communications if c.t == t and c.sender == robot),
                            tuple(c for c in self.communications if c.t == t and c.receiver == robot)))
        return out

    def master_receivers(self) -> set[str]:
        """Robots that hold m at the end of the plan."""
        return set(self.masters) | {c.receiver for c in self.communications if c.info == MASTER}

    def frontier_assignment(self) -> dict[str, list[str]]:
        """frontier -> robots sent to explore it, in frontier-index order (Algorithm 1's i)."""
        out: dict[str, list[str]] = {}
        for r in sorted(self.explore):
            out.setdefault(self.explore[r], []).append(r)
        return out

    def exploration_index(self, robot: str) -> int:
        """Robot's frontier index i for Algorithm 1."""
        return self.frontier_assignment()[self.explore[robot]].index(robot)

    # -- communication phases (the executive's Communication Action) ----------------------
    def leader(self, t: int, location: str) -> str | None:
        """Communication leader l_s^t: the robot at ``location`` that takes part in
        external communication at step t, else the first robot there by name."""
        present = sorted(r for r in self.trajectories if self.location(r, t) == location)
        if not present:
            return None
        for c in self.communications:
            if c.t != t:
                continue
            ls, lr = self.location(c.sender, t), self.location(c.receiver, t)
            if ls != lr:
                if ls == location:
                    return c.sender
                if lr == location:
                    return c.receiver
        return present[0]

    def communication_phases(self, t: int, robot: str) -> dict[str, list[Communication]]:
        """PreIntCom(t, r), ExtCom(t, r) and PostIntCom(t, r) as the paper defines them."""
        pre, ext, post = [], [], []
        for c in self.communications:
            if c.t != t or robot not in (c.sender, c.receiver):
                continue
            ls, lr = self.location(c.sender, t), self.location(c.receiver, t)
            if ls != lr:
                ext.append(c)
            elif c.receiver == self.leader(t, ls):
                pre.append(c)
            else:
                post.append(c)
        return {"PreIntCom": pre, "ExtCom": ext, "PostIntCom": post}

    # -- serialisation ------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "version": PLAN_FORMAT_VERSION,
            "phase": self.phase,
            "horizon": self.horizon,
            "trajectories": {r: list(self.trajectories[r]) for r in sorted(self.trajectories)},
            "communications": [c.as_list() for c in self.communications],
            "masters": sorted(self.masters),
            "holdings": {r: sorted(self.holdings[r]) for r in sorted(self.holdings)},
            "requirements": [q.as_dict() for q in self.requirements],
            "explore": {r: self.explore[r] for r in sorted(self.explore)},
            "meta": {k: self.meta[k] for k in sorted(self.meta)},
        }

    def to_json(self, indent: int | None = None) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, indent=indent)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Plan":
        try:
            version = d.get("version", PLAN_FORMAT_VERSION)
            if version != PLAN_FORMAT_VERSION:
                raise ValueError(f"plan format version {version} is not supported")
            comms = []
            for c in d.get("communications", []):
                if len(c) != 4:
                    raise ValueError(f"communication {c!r} must be [t, sender, receiver, info]")
                comms.append(Communication(int(c[0]), str(c[1]), str(c[2]), str(c[3])))
            return cls(
                horizon=int(d["horizon"]),
                trajectories={str(r): [str(s) for s in traj] for r, traj in d["trajectories"].items()},
                communications=comms,
                masters=[str(r) for r in d.get("masters", [])],
                holdings={str(r): [str(b) for b in bs] for r, bs in d.get("holdings", {}).items()},
                requirements=[Requirement(tuple(q["sources"]), tuple(q["sinks"]))
                              for q in d.get("requirements", [])],
                explore={str(r): str(s) for r, s in d.get("explore", {}).items()},
                phase=str(d.get("phase", "plan")),
                meta=dict(d.get("meta", {})),
            )
        except (KeyError, TypeError, AttributeError) as e:
            raise ValueError(f"malformed plan: {e}") from None

    @classmethod
    def from_json(cls, text: str) -> "Plan":
        return cls.from_dict(json.loads(text))


def idle_plan(positions: Mapping[str, str], masters: Iterable[str], phase: str,
              holdings: Mapping[str, Iterable[str]] | None = None, horizon: int = 0) -> Plan:
    """A plan in which nobody moves or communicates."""
    return Plan(horizon=horizon,
                trajectories={r: [positions[r]] * (horizon + 1) for r in sorted(positions)},
                masters=sorted(masters),
                holdings={r: sorted(b) for r, b in (holdings or {}).items()},
                phase=phase,
                meta={"cost": 0.0, "reward": 0.0, "objective": 0.0, "status": "trivial",
                      "gap": 0.0, "solve_time_s": 0.0, "solver": None})


def worst_gap(plans: Iterable[Plan]) -> float | None:
    """The largest optimality gap (``meta["gap"]``) of ``plans``; None when one is unknown."""
    gaps = [p.meta.get("gap") for p in plans]
    if any(g is None for g in gaps):
        return None
    return max(gaps, default=0.0)


#: Default minimum exploration time of a cycle, in plan steps (ΔT each).
DEFAULT_MIN_EXPLORATION_STEPS = 4


@dataclass(frozen=True)
class ExplorationTask:
    """A robot's exploration phase: from ``frontier`` with Algorithm 1 index ``index``,
    starting at step ``start_step`` of the pre-exploration plan, for ``steps`` steps of
    ΔT, back at the frontier to join the post-exploration plan at ``return_step``."""

    frontier: str
    index: int
    start_step: int
    steps: int
    return_step: int

    def as_dict(self) -> dict[str, Any]:
        return {"frontier": self.frontier, "index": self.index, "return_step": self.return_step,
                "start_step": self.start_step, "steps": self.steps}


@dataclass
class CyclePlan:
    """One COPS cycle: pre-exploration plan, exploration phase, post-exploration plan."""

    pre: Plan
    post: Plan
    exploration: dict[str, ExplorationTask]
    meta: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"exploration": {r: self.exploration[r].as_dict() for r in sorted(self.exploration)},
                "meta": {k: self.meta[k] for k in sorted(self.meta)},
                "post": self.post.to_dict(), "pre": self.pre.to_dict(), "version": PLAN_FORMAT_VERSION}

    def to_json(self, indent: int | None = None) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, indent=indent)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "CyclePlan":
        try:
            return cls(pre=Plan.from_dict(d["pre"]), post=Plan.from_dict(d["post"]),
                       exploration={str(r): ExplorationTask(str(e["frontier"]), int(e["index"]),
                                                            int(e["start_step"]), int(e["steps"]),
                                                            int(e["return_step"]))
                                    for r, e in d.get("exploration", {}).items()},
                       meta=dict(d.get("meta", {})))
        except (KeyError, TypeError) as e:
            raise ValueError(f"malformed cycle plan: {e}") from None

    @classmethod
    def from_json(cls, text: str) -> "CyclePlan":
        return cls.from_dict(json.loads(text))
