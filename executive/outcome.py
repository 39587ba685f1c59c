"""Whether a mission succeeded, and why not: the same rule for every team strategy.

A mission succeeded when

1. its team strategy says so (:meth:`TeamStrategy.succeeded`: by default every
   robot's tree ended in SUCCESS; COPS also needs the base station's), robots lost to
   a fault or a flat battery aside (they are listed, not held against the team),
   as long as one robot is left;
2. every robot that was not lost left its start: it travelled at least
   ``MIN_DISTANCE_M``;
3. the team explored something: at least ``MIN_PROGRESS_FRACTION`` of the world
   beyond what it saw from its start (the first coverage sample), unless less than
   ``MUCH_LEFT_FRACTION`` of the world was left unexplored then.

Each rule that fails adds one line to :attr:`Outcome.reasons`; each tree that did not
end in SUCCESS adds the node it failed at and the failure its behaviours logged
(``explore_failed``, ``homing_failed``, ...). A tree that ended in SUCCESS although
its exploration ended in a failure (the planner raised, say, and the tree went home)
adds a line to :attr:`Outcome.notes`: the mission still succeeded, for a reason the
console shows. ``delve run`` prints both, and ``report.json`` holds them under
``outcome``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import py_trees
from py_trees.common import Status

if TYPE_CHECKING:
    from .agent import Agent
    from .teams import TeamStrategy

#: A robot that travelled less than this never left its start (m).
MIN_DISTANCE_M = 1.0
#: The least share of the world a team must explore beyond its start view ...
MIN_PROGRESS_FRACTION = 0.02
#: ... when at least this share was left to explore at the start.
MUCH_LEFT_FRACTION = 0.10
#: Events that end a robot's exploration, well or not.
EXPLORATION_ENDS = ("explore_failed", "exploration_complete", "planner_homing", "endurance_low",
                    "homing_timer", "exploration_over")


@dataclass(frozen=True)
class Outcome:
    """The verdict on a mission: ``succeeded``, whether the run hit its duration
    (``timed_out``), one line per reason it did not succeed, and the robots lost with
    why."""

    succeeded: bool
    timed_out: bool
    reasons: tuple[str, ...] = ()
    lost: dict[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"timed_out": self.timed_out, "reasons": list(self.reasons), "notes": list(self.notes),
                "lost": dict(self.lost)}


def failing_node(root: py_trees.behaviour.Behaviour) -> py_trees.behaviour.Behaviour:
    """The node a FAILURE came from: down the FAILURE children (a selector's last
    one, which failed after the others), to a node none of whose children failed."""
    node = root
    while True:
        failed = [c for c in node.children if c.status == Status.FAILURE]
        if not failed:
            return node
        node = failed[-1] if isinstance(node, py_trees.composites.Selector) else failed[0]


def is_failure(event: dict[str, Any], failure_events: tuple[str, ...] = ()) -> bool:
    """Whether a behaviour says in ``event`` why it failed: every ``*_failed`` event,
    and the team strategy's own (``TeamStrategy.FAILURE_EVENTS``)."""
    return event["event"].endswith("_failed") or event["event"] in failure_events


def failure_event(events: list[dict[str, Any]], agent: str, failure_events: tuple[str, ...] = ()) -> str | None:
    """The last failure an agent's behaviours logged, as ``event: reason, detail``."""
    for e in reversed(events):
        if e.get("agent") == agent and is_failure(e, failure_events):
            words = [str(e[k]) for k in ("reason", "detail") if e.get(k) not in (None, "")]
            return e["event"] + (": " + ", ".join(words) if words else "")
    return None


def _last_word(events: list[dict[str, Any]], agent: str, failure_events: tuple[str, ...]) -> str | None:
    """Why a robot that ended well did nothing: its last failure or exploration end."""
    for e in reversed(events):
        if e.get("agent") != agent:
            continue
        if e["event"] == "exploration_complete":
            crumbs = e.get("blacklisted_voxels")
            return "exploration complete" + (f" with {crumbs} frontier voxels blacklisted" if crumbs else "")
        if is_failure(e, failure_events):
            return failure_event([e], agent, failure_events)
    return None


def exploration_failure(events: list[dict[str, Any]], agent: str) -> str | None:
    """The failure an agent's exploration ended with, when its last exploration end
    (:data:`EXPLORATION_ENDS`) was one; else None."""
    ends = (e for e in reversed(events) if e.get("agent") == agent and e["event"] in EXPLORATION_ENDS)
    last = next(ends, None)
    return failure_event([last], agent) if last is not None and last["event"] == "explore_failed" else None


class Judged(Protocol):
    """What the outcome reads of a mission (a :class:`~delve.executive.runner.Mission`)."""

    duration_s: float
    lost: dict[str, str]
    robots: dict[str, Any]
    robot_agents: list[Agent]
    state: Any  # MissionState: its events and coverage samples
    team: TeamStrategy
    timed_out: bool


def agent_reason(mission: Judged, agent: "Agent", timed_out: bool) -> str:
    """One line: why ``agent``'s tree did not end in SUCCESS."""
    status = agent.root.status
    if status == Status.FAILURE:
        node = failing_node(agent.root)
        why = failure_event(mission.state.events, agent.name, mission.team.FAILURE_EVENTS)
        feedback = node.feedback_message if node.feedback_message not in (why or "") else ""
        return (f"{agent.name}: FAILURE at {node.name!r}" + (f" ({feedback})" if feedback else "")
                + (f": {why}" if why else ""))
    when = (f"when the run stopped at its duration ({mission.duration_s:g} s)" if timed_out
            else "when the mission ended")
    return f"{agent.name}: had not finished {when}"


def mission_outcome(mission: Judged) -> Outcome:
    """The :class:`Outcome` of a finished mission (see the module docstring)."""
    timed_out = bool(mission.timed_out)
    reasons: list[str] = []
    team = mission.team
    if not team.succeeded(mission):
        reasons += [agent_reason(mission, a, timed_out) for a in team.judged_agents(mission)
                    if a.root.status != Status.SUCCESS]
        if not reasons:
            reasons.append(f"the team strategy ({type(team).__name__}) judged the mission failed")
    if mission.robots and all(name in mission.lost for name in mission.robots):
        lost = ", ".join(f"{n} ({why})" for n, why in mission.lost.items())
        reasons.append(f"every robot was lost: {lost}")
    for name, robot in mission.robots.items():
        if name not in mission.lost and robot.distance_m < MIN_DISTANCE_M:
            word = _last_word(mission.state.events, name, mission.team.FAILURE_EVENTS)
            reasons.append(f"{name}: never left its start ({robot.distance_m:.1f} m travelled)"
                           + (f"; {word}" if word else ""))
    samples = mission.state.samples
    if samples:
        start, end = samples[0].team, samples[-1].team
        if end - start < MIN_PROGRESS_FRACTION and 1.0 - start >= MUCH_LEFT_FRACTION:
            gain = max(end - start, 0.0)
            reasons.append(f"the team explored {gain:.1%} of the world beyond what it saw at "
                           f"its start (at least {MIN_PROGRESS_FRACTION:.0%} expected, {1.0 - start:.0%} was "
                           f"unexplored)")
    notes = []
    for agent in mission.robot_agents:
        failure = exploration_failure(mission.state.events, agent.name)
        if agent.root.status == Status.SUCCESS and failure:
            notes.append(f"{agent.name}: SUCCESS, but its exploration ended with {failure}")
    return Outcome(succeeded=not reasons, timed_out=timed_out, reasons=tuple(reasons),
                   lost=dict(mission.lost), notes=tuple(notes))
