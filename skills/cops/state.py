"""The COPS state of an agent (its information storage, the cycle plan it executes,
where in the cycle it is) and the ids of the messages that carry it.

Messages (radio kind ``cops``) are ``{"type": "info" | "ack" | "hello", ...}``. An
info message carries one plan communication (t, r, r', b) of one part of one
cycle; its payload is the sender's whole knowledge (topology, information
freshness, lost robots) and, for b = m, the cycle plan.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ...planners.cops import Communication, CyclePlan
from ...planners.cops.plan import Plan
from ...planners.cops.topology import Topology
from ..base import AgentContext

KIND = "cops"
PARTS = ("pre", "explore", "post", "done")


@dataclass
class Knowledge:
    """What an agent holds (the paper's information storage).

    ``freshness[r]``: newest cycle whose information of robot r this agent holds.
    ``received`` / ``acked``: ids of info messages received / acknowledged to us.
    ``heard[r]``: newest sim time r was heard from (by anyone whose knowledge we have);
    ``declared[r]``: newest time r was declared lost. r counts as lost while it was
    declared lost after it was last heard from.
    ``map_chunks``: on voxel worlds, the pieces of robots' onboard maps this agent
    holds ("r1/4" -> (flat indices, values)), carried like the rest of the
    information until they reach the base station's map.
    ``finished[r]``: the final plan's cycle, for a robot that got it at the base with
    its part done (its communications in that plan count as done).
    ``gone_home[r]``: when robot r left the plan for home (its endurance barely
    covered the way, or it could not make a move of the plan): it takes part in no
    plan any more."""

    topology: Topology = field(default_factory=Topology)
    freshness: dict[str, int] = field(default_factory=dict)
    declared: dict[str, float] = field(default_factory=dict)
    received: set[str] = field(default_factory=set)
    acked: set[str] = field(default_factory=set)
    heard: dict[str, float] = field(default_factory=dict)
    pending_plan: dict[str, Any] | None = None
    map_chunks: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    finished: dict[str, int] = field(default_factory=dict)
    gone_home: dict[str, float] = field(default_factory=dict)

    @property
    def retired(self) -> set[str]:
        """Robots that take part in no plan any more: declared lost, or gone home."""
        return self.lost | self.gone_home.keys()

    @property
    def lost(self) -> set[str]:
        return {r for r, t in self.declared.items() if t > self.heard.get(r, -math.inf)}

    def payload(self) -> dict[str, Any]:
        return {"topology": self.topology.to_dict(), "freshness": dict(self.freshness),
                "declared": dict(self.declared), "heard": dict(self.heard), "map": dict(self.map_chunks),
                "finished": dict(self.finished), "gone_home": dict(self.gone_home)}

    def collect_map(self, robot: str, onboard_map: Any) -> None:
        """Add what ``robot``'s onboard map gained since the last call as a chunk."""
        flat, values = onboard_map.take_changes()
        if len(flat):
            self.map_chunks[f"{robot}/{len(self.map_chunks)}"] = (flat, values)  # unique: the dict only grows

    def absorb(self, payload: dict[str, Any]) -> None:
        for key, chunk in payload.get("map", {}).items():
            self.map_chunks.setdefault(key, chunk)
        self.topology.merge(Topology.from_dict(payload["topology"]))
        for mine, theirs in ((self.freshness, payload["freshness"]), (self.declared, payload["declared"]),
                             (self.heard, payload["heard"]), (self.finished, payload.get("finished", {})),
                (self.gone_home, payload.get("gone_home", {}))):
            for r, v in theirs.items():
                mine[r] = max(mine.get(r, -math.inf), v)


@dataclass
class CopsState:
    """An agent's COPS state (blackboard key ``cops``)."""

    knowledge: Knowledge = field(default_factory=Knowledge)
    cycle: int = -1
    plan: CyclePlan | None = None
    part: str = "done"
    step: int = 0
    final: bool = False
    delta_t_s: float = 60.0
    lost_timeout_s: float = 1200.0
    recall_after_s: float = 1800.0
    base_location: str | None = None
    explored_in: dict[str, int] = field(default_factory=dict)
    planned_s: float = 0.0
    #: Why the last move of the plan failed (None: no move failed).
    transition_failed: str | None = None

    def part_plan(self) -> Plan | None:
        if self.plan is None:
            return None
        return {"pre": self.plan.pre, "post": self.plan.post}.get(self.part)

    def plan_message(self) -> dict[str, Any]:
        """The cycle plan m as a message carries it."""
        return {"cycle": self.plan.to_dict(), "final": self.final, "delta_t_s": self.delta_t_s,
                "lost_timeout_s": self.lost_timeout_s, "recall_after_s": self.recall_after_s,
                "base_location": self.base_location}

    def adopt(self, msg: dict[str, Any]) -> None:
        """Take the cycle plan m of ``msg`` and continue from the step it arrived at."""
        m = msg["plan"]
        self.plan = CyclePlan.from_dict(m["cycle"])
        self.cycle, self.final = int(msg["cycle"]), bool(m["final"])
        self.delta_t_s, self.lost_timeout_s = float(m["delta_t_s"]), float(m["lost_timeout_s"])
        self.recall_after_s = float(m["recall_after_s"])
        self.base_location = m["base_location"]
        self.part, self.step = msg["part"], int(msg["t"])


def message_id(cycle: int, part: str, c: Communication) -> str:
    return f"{cycle}:{part}:{c.t}:{c.sender}>{c.receiver}:{c.info}"


def final_plan_id(cycle: int, robot: str) -> str:
    """Id of the final plan the leader hands to ``robot`` at the base."""
    return f"{cycle}:final:{robot}"


def collect_own_map(ctx: AgentContext, kn: Knowledge) -> None:
    """Put what the agent's robot mapped since the last call into its knowledge (robots
    with an onboard voxel map only)."""
    onboard = getattr(ctx.robot, "onboard_map", None)
    if onboard is not None:
        kn.collect_map(ctx.name, onboard)
