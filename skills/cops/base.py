"""The base of the COPS behaviours: the agent's COPS state on the blackboard, its
radio, and driving to a location through the robot's NetworkView."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status

from ...planners.cops.topology import Topology
from ..base import AgentContext, Param, ParamNamedPort, Skill
from ..robot import NetworkView, PathStatus
from .state import KIND, CopsState, collect_own_map

#: A route towards where the knowledge puts a location that ends nearer the robot
#: than this (m) takes it no nearer: it is there as far as its own map can tell.
HINT_PROGRESS_M = 1.0
STATE_KEY = Param(str, "cops", "blackboard key of the agent's COPS state", key=True)
#: The agent's COPS state as the behaviours read it (a fresh one while none is stored)...
STATE_IN = ParamNamedPort(CopsState, required=False, description="the agent's COPS state (a fresh one while none "
                          "is stored)", key_param="state")
#: ... and as those write it that make it when none is stored and change it in place.
STATE_OUT = ParamNamedPort(CopsState, description="the agent's COPS state, made when none is stored, changed in "
                           "place", key_param="state")


def network_view(ctx: AgentContext) -> NetworkView | None:
    """The robot's NetworkView (service ``network_view``, which the world backend
    makes for each robot of a COPS team); None at the base station."""
    return ctx.services.get("network_view")


class CopsSkill(Skill):
    """Base of the COPS behaviours: the agent's state and radio.

    Each reads and writes the state (port ``cops``, its key named by the parameter
    ``state``); one that only reads it declares no output port."""

    ABSTRACT = True
    AGENT = None   # the leader's steps run on the base station, the others' on robots
    PARAMS = {"state": STATE_KEY}
    INPUT_PORTS = {"cops": STATE_IN}
    OUTPUT_PORTS = {"cops": STATE_OUT}
    #: The location :meth:`drive_to` last sent the robot to, and the last one where
    #: it found the robot as near the position as it can get.
    _driving: str | None = None
    _settled: str | None = None

    def reset_drive(self) -> None:
        """Forget earlier drives (when the behaviour starts afresh)."""
        self._driving = self._settled = None

    def stored_state(self) -> CopsState | None:
        """The agent's COPS state; None until a behaviour has made it."""
        return self.read("cops")

    @property
    def state(self) -> CopsState:
        """The agent's COPS state; while none is stored, a fresh one, which a behaviour
        that writes the state stores (one that only reads it does not)."""
        st = self.read("cops")
        if st is None:
            st = CopsState()
            if "cops" in self.OUTPUT_PORTS:
                self.write("cops", st)
        return st

    @property
    def radio(self) -> Any:
        return self.ctx.robot.radio if self.ctx.robot is not None else self.ctx.services["radio"]

    def greet_home(self, st: "CopsState") -> None:
        """Greet the leader from the base, with everything the agent holds (what it
        mapped on its way home included)."""
        collect_own_map(self.ctx, st.knowledge)
        self.radio.send(self.p["leader"], KIND, {"type": "hello", "home": True, "payload": st.knowledge.payload()})

    def drive_to(self, there: str, arrive: bool = False, short_is_there: bool = True) -> Status | None:
        """Drive towards location ``there`` through the NetworkView: None once there
        (in its region; with ``arrive``, at the end of its route to the position, or as
        near the position as the robot can get inside the region), RUNNING on the way,
        FAILURE when it cannot get there (no route, or blocked; logged
        ``cops_transition_failed`` with the robot, ``from`` (its location), ``to`` and
        the ``reason``). A route that ends short of ``there`` (a voxel map's graph
        reaches further as the robot walks) is asked for again where it ends. A name
        the view knows under another (a lattice cell merged into a region, see
        :func:`view_name`) is driven to under the view's name; one it does not know
        yet, to the position the agent's knowledge gives (:meth:`_hint`). Where the
        robot's own map takes it no nearer that position, it is there as far as it
        can tell (a plan's move goes on) or, without ``short_is_there``, it has no
        route (exploration: the location is out of its reach, not explored)."""
        view, robot = network_view(self.ctx), self.robot
        there = view_name(view, there, self.state.knowledge.topology)
        hint = self._hint(view, there)
        at_hint = hint is not None and view.near(hint)
        inside = view.location() == there or at_hint
        on_own_route = self._driving == there and getattr(self, "_command_id", None) == robot.command_id
        if inside and (not arrive or not (on_own_route and robot.path_status == PathStatus.FOLLOWING)
                       and (self._settled == there or at_hint or view.arrived(there))):
            self._driving = None
            return None
        if not on_own_route or robot.path_status in (PathStatus.ARRIVED, PathStatus.IDLE):
            route = view.route(there) if hint is None else view.route_towards(hint)
            if hint is not None and route is not None and \
                    np.linalg.norm(np.asarray(route)[-1] - robot.position) < HINT_PROGRESS_M:
                route, inside = None, inside or short_is_there  # its own map takes it no nearer
            if route is None and inside:  # as near as it gets
                self._driving, self._settled = None, there
                return None
            if route is None:
                return self._failed(view, there, f"no route to {there}")
            self.follow(route)
            self._driving = there
        if robot.path_status == PathStatus.BLOCKED:
            reason = f"blocked on the way to {there}"
            return self._failed(view, there, f"{reason}: {robot.blocked_reason}" if robot.blocked_reason else reason)
        return Status.RUNNING

    def _hint(self, view: NetworkView, there: str) -> np.ndarray | None:
        """Where the agent's knowledge puts a location that the robot's own map does
        not show yet (another robot explored it), for a view that can route towards a
        point (``resolve``, ``route_towards``, ``near``); else None."""
        known = self.state.knowledge.topology.locations.get(there)
        if known is None or not hasattr(view, "route_towards") or view.resolve(there) is not None:
            return None
        return np.asarray(known, dtype=float)

    def _failed(self, view: NetworkView, there: str, reason: str) -> Status:
        """FAILURE of a drive, with its reason as feedback and as an event."""
        st = self.state
        self.feedback_message = reason
        self.event("cops_transition_failed", robot=self.ctx.name, cycle=st.cycle, part=st.part, step=st.step,
                   reason=reason, **{"from": view.location(), "to": there})
        return Status.FAILURE


def view_name(view: NetworkView, name: str, topology: Topology) -> str:
    """The name under which ``view`` knows the location ``name`` of an agent's
    ``topology``: a view that merges cells into regions (``resolve``) may know it
    under its region's name or, when the topology merged more than the view's map,
    under the name of another member; else ``name`` itself."""
    resolve = getattr(view, "resolve", None)
    if resolve is None:
        return name
    found = resolve(name)
    for member in topology.members(name) if found is None else ():
        found = resolve(member)
        if found is not None:
            break
    return found if found is not None else name
