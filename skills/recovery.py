"""Recovery actions of the navigation-goals block: reset the local map, tell the
supervisor that a goal cannot be reached, pick a frontier to relocate to."""
from __future__ import annotations

from py_trees.common import Status
from py_trees.ports import PortInformation

from .base import Param, Skill
from .operator import GOAL_UNREACHABLE
from .safety import BASE


class ResetLocalMap(Skill):
    """Forget the onboard map around the robot so that the next scans map it again
    (after odometry drift made the start pose invalid). Returns SUCCESS."""

    PARAMS = {"radius_m": Param(float, 2.5, "radius of the map forgotten around the robot", exclusive_minimum=0)}

    def update(self) -> Status:
        self.robot.reset_local_map(self.p["radius_m"])
        self.event("local_map_reset", trigger=True, radius_m=self.p["radius_m"])
        return Status.SUCCESS


class NotifySupervisor(Skill):
    """Tell the supervisor that its goal cannot be reached.

    Reads ``goal`` and ``goto_failure``; sends a ``goal_unreachable`` message to the
    base station (it waits in the outbox while the link is down). Returns SUCCESS.
    """

    INPUT_PORTS = {
        "goal": PortInformation(list, required=False, description="the goal that cannot be reached [x, y, z] (m)"),
        "goto_failure": PortInformation(str, required=False, description="why (GoTo's failure code)"),
    }

    def update(self) -> Status:
        goal, reason = self.read("goal"), self.read("goto_failure")
        self.robot.radio.send(BASE, GOAL_UNREACHABLE, {"goal": goal, "reason": reason})
        self.event("supervisor_notified", trigger=True, goal=goal, reason=reason)
        return Status.SUCCESS
