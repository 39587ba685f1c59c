"""Motion: the Transition Action of a plan step and its Action Timer, exploration
(Algorithm 1) with its timer, and the transit back to the return node."""
from __future__ import annotations

import math
from abc import abstractmethod
from typing import Any

from py_trees.common import Status

from ...planners.cops.topology import Topology
from .base import CopsSkill
from .state import CopsState


class TransitionAction(CopsSkill):
    """Transition Action: move to the plan's next location s_{t+1} and set t = t + 1.

    At the last step of a part it moves on, once at the part's last location:
    pre-exploration to exploration (a robot the plan sends exploring) or to
    post-exploration, post-exploration to done. A robot that adopted the plan away
    from where the plan has it (coming home by the standing order) goes there first.

    Reads/writes ``cops``; drives the robot through its NetworkView's routes.
    Returns RUNNING while moving, SUCCESS on arrival (at once for a stay), FAILURE
    when the location cannot be reached (its reason kept in ``cops``,
    ``transition_failed``).
    """

    def initialise(self) -> None:
        self.reset_drive()

    def update(self) -> Status:
        st = self.state
        plan = st.part_plan()
        if plan is None:
            return Status.FAILURE
        last = st.step >= plan.horizon
        moving = self.drive_to(plan.location(self.ctx.name, min(st.step + 1, plan.horizon)), arrive=True) \
            if self.ctx.robot is not None else None
        if moving == Status.FAILURE:
            st.transition_failed = self.feedback_message
        if moving is not None:
            return moving
        if last:
            self._next_part(st)
        else:
            st.step += 1
        return Status.SUCCESS

    def _next_part(self, st: CopsState) -> None:
        if st.part == "pre":
            st.part = "explore" if self.ctx.name in st.plan.exploration else "post"
        else:
            st.part = "done"
        st.step = 0

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()


class _PlanTimer(CopsSkill):
    """A sim-clock timer whose duration the plan sets when it is entered."""

    ABSTRACT = True
    OUTPUT_PORTS = {}  # reads the state only

    @abstractmethod
    def duration_s(self, st: CopsState) -> float:
        """The timer's duration, read from the plan when the timer is entered."""

    def initialise(self) -> None:
        self._until = self.ctx.clock.now_s + self.duration_s(self.state)

    def update(self) -> Status:
        return Status.SUCCESS if self.ctx.clock.now_s >= self._until - 1e-9 else Status.RUNNING


class ActionTimer(_PlanTimer):
    """Action Timer: RUNNING for ΔT (from the plan) when the step has a transition
    to make, so that robots stay in step; SUCCESS at once at the last step of a part.
    Reads ``cops``."""

    def duration_s(self, st: CopsState) -> float:
        plan = st.part_plan()
        return 0.0 if plan is None or st.step >= plan.horizon else st.delta_t_s


class ExplorationTimer(_PlanTimer):
    """Exploration Timer: RUNNING for the robot's exploration time (its task's steps
    times ΔT), then SUCCESS. Reads ``cops``."""

    def duration_s(self, st: CopsState) -> float:
        task = st.plan.exploration.get(self.ctx.name) if st.plan else None
        return task.steps * st.delta_t_s if task else 0.0


def _bearing(a: Any, b: Any) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def ordered_choices(topology: Topology, at: str, came_from: str | None, candidates: list[str]) -> list[str]:
    """Algorithm 1's choices in an order every robot agrees on without talking:
    clockwise from the direction the robot came from (from +x at a frontier)."""
    p = topology.locations[at]
    ref = _bearing(p, topology.locations[came_from]) if came_from else math.pi

    def turn(s: str) -> float:
        return (ref - _bearing(p, topology.locations[s])) % (2 * math.pi)
    return sorted(candidates, key=lambda s: (round(turn(s), 6), s))


class ExplorationAction(CopsSkill):
    """Exploration Action (Algorithm 1): communication-free split at forks.

    Starting at its frontier with frontier index i, the robot repeats: c = number of
    choices (at the frontier: its unexplored exits; further on: the tunnels other than
    the one it came by), choice = i mod c, i = i div c, move one location towards the
    choice. Robots sent to one frontier thus spread over its branches (Figure 5). A
    location the robot has arrived at is explored: on a voxel world it arrives near
    the location's position, which may lie in the cell above the floor the robot
    walks on, or the location may be one only its knowledge shows, and its own map
    would then never count the cell visited (a frontier's target for good). A choice
    the robot cannot reach (no route, blocked, or its own map takes it no nearer) is
    dropped and the robot chooses again among the others, with i as it was. At a
    dead end it waits. Runs until the Exploration Timer stops it.

    Reads/writes ``cops`` (the plan's exploration task; the knowledge's explored and
    unreachable locations); drives the robot. Logs ``exploration_choice`` and
    ``exploration_unreachable``. Returns RUNNING.
    """

    def initialise(self) -> None:
        st = self.state
        task = st.plan.exploration[self.ctx.name]
        self._i, self._at, self._prev = task.index, task.frontier, None
        self._moving: str | None = None
        self.reset_drive()
        self._i_before = self._i
        self._visited = {task.frontier}
        st.knowledge.freshness[self.ctx.name] = st.cycle

    def update(self) -> Status:
        st = self.state
        topo = st.knowledge.topology
        self._rename(topo)
        if self._moving is not None:
            moving = self.drive_to(self._moving, short_is_there=False)
            if moving == Status.RUNNING:
                return moving
            if moving == Status.FAILURE:
                self.event("exploration_unreachable", at=self._at, choice=self._moving)
                topo.unreachable.add(self._moving)
                self._i, self._moving = self._i_before, None
                return Status.RUNNING
            self._prev, self._at, self._moving = self._at, self._moving, None
            self._visited.add(self._at)
            topo.explored.add(self._at)
        if self._prev is None:
            explored = {topo.resolve(s) for s in st.plan.meta.get("explored", ())} | self._visited | topo.unreachable
            cands = [s for s in topo.neighbours(self._at) if s not in explored]
        else:
            cands = [s for s in topo.neighbours(self._at)
                     if s != self._prev and s not in self._visited and s not in topo.unreachable]
        choices = ordered_choices(topo, self._at, self._prev, cands)
        if not choices:
            self.feedback_message = f"dead end at {self._at}"
            return Status.RUNNING
        c = len(choices)
        choice, i = choices[self._i % c], self._i // c
        self.event("exploration_choice", at=self._at, choices=choices, index=self._i, choice=choice)
        self._i_before, self._i, self._moving = self._i, i, choice
        self.feedback_message = f"to {choice} (i={self._i})"
        return Status.RUNNING

    def _rename(self, topo: Topology) -> None:
        """Follow the renames of locations merged into regions since the last tick."""
        if topo.merged:
            self._at = topo.resolve(self._at)
            self._prev = topo.resolve(self._prev) if self._prev is not None else None
            self._moving = topo.resolve(self._moving) if self._moving is not None else None
            self._visited = {topo.resolve(s) for s in self._visited}

    def terminate(self, new_status: Status) -> None:
        self.stop_own_motion()


class TransitToReturnNode(CopsSkill):
    """Transit to return node: go back to the frontier the exploration started from,
    then continue with post-exploration (step 0).

    Reads/writes ``cops``; drives the robot. Returns RUNNING on the way, SUCCESS
    there, FAILURE without a route (its reason kept in ``cops``,
    ``transition_failed``).
    """

    def initialise(self) -> None:
        self.reset_drive()

    def update(self) -> Status:
        st = self.state
        moving = self.drive_to(st.plan.exploration[self.ctx.name].frontier, arrive=True)
        if moving == Status.FAILURE:
            st.transition_failed = self.feedback_message
        if moving is not None:
            return moving
        st.part, st.step = "post", 0
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()
