"""Faults of a robot's body and power: stuck feet, a lost robot, a battery that drops."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ...skills.base import Param
from .base import REQUIRED, Fault

if TYPE_CHECKING:
    from ..runner import Mission


class Stuck(Fault):
    """The robot cannot move for ``duration_s`` of trying: it keeps its path but does
    not advance (the jam counts down while it follows a path)."""

    KIND = "stuck"
    DURATION = REQUIRED

    @property
    def end_s(self) -> float | None:
        """None: the robot counts its jam down itself (while it follows a path)."""
        return None

    def start(self, mission: "Mission") -> dict[str, Any]:
        mission.robots[self.robot].jam(self.duration_s)
        return {}


class Lost(Fault):
    """The robot dies where it stands: it stops, its radio falls silent for good and
    its tree stops; what it held and had not delivered is counted as undelivered."""

    KIND = "lost"

    def start(self, mission: "Mission") -> dict[str, Any]:
        mission.lose(self.robot, "lost (fault)")
        return {}


class BatteryDrop(Fault):
    """The battery loses ``drop_fraction`` of the endurance it has left at once (1:
    flat). At zero the robot stops, its radio falls silent, and a ``robot_lost`` event
    says "endurance exhausted"."""

    KIND = "battery_drop"
    PARAMS = {"drop_fraction": Param(float, 0.5, "share of the remaining endurance lost (1: flat)",
                                     exclusive_minimum=0.0, maximum=1.0)}

    def start(self, mission: "Mission") -> dict[str, Any]:
        robot = mission.robots[self.robot]
        robot.drain_battery(self.p["drop_fraction"])
        return {"endurance_left_s": round(robot.endurance_remaining_s, 1)}
