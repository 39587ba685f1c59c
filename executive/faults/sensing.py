"""Faults of a robot's perception and state estimation (voxel worlds): rock that is
not there in its map, range sensors that degrade or drop out, a drifting pose."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ...skills.base import Param
from .base import OPTIONAL, Fault

if TYPE_CHECKING:
    from ..runner import Mission


class MapArtifact(Fault):
    """The state estimator jumps: the robot halts and rock appears in its onboard map
    within ``radius_m`` around it, as odometry drift leaves in a real map."""

    KIND = "map_artifact"
    PARAMS = {"radius_m": Param(float, 1.5, "radius of the phantom rock around the robot",
                                exclusive_minimum=0.0, maximum=100.0)}
    WORLDS = ("voxel",)

    def start(self, mission: "Mission") -> dict[str, Any]:
        mission.robots[self.robot].inject_map_artifact(self.p["radius_m"])
        return {}


class LidarDegraded(Fault):
    """The range sensors (LiDAR, a legged robot's terrain cameras) reach at most
    ``range_m`` and keep ``ray_fraction`` of their beams, until ``duration_s`` has
    passed (for good without it)."""

    KIND = "lidar_degraded"
    DURATION = OPTIONAL
    PARAMS = {
        "range_m": Param(float, None, "the sensors' range while degraded (null: unchanged)",
                         exclusive_minimum=0.0, maximum=1e3, nullable=True),
        "ray_fraction": Param(float, 1.0, "share of the beams that still return (0: a dropout)", minimum=0.0,
                              maximum=1.0),
    }
    WORLDS = ("voxel",)

    def degradation(self) -> tuple[float | None, float]:
        """The range and the share of beams this fault leaves."""
        return self.p["range_m"], self.p["ray_fraction"]

    def _apply(self, mission: "Mission") -> None:
        """Degrade the sensors as the active faults on the robot add up (the shortest
        range, the smallest share), or restore them when none is left."""
        robot = mission.robots[self.robot]
        held = [f.degradation() for f in mission.faults.holding(LidarDegraded, self.robot)]
        if not held:
            robot.restore_lidar()
            return
        ranges = [r for r, _ in held if r is not None]
        robot.degrade_lidar(min(ranges) if ranges else None, min(share for _, share in held))

    def start(self, mission: "Mission") -> dict[str, Any]:
        self._apply(mission)
        return {}

    def end(self, mission: "Mission") -> dict[str, Any]:
        self._apply(mission)
        return {}


class LidarDropout(LidarDegraded):
    """The range sensors return nothing until ``duration_s`` has passed (for good
    without it): the onboard map stops growing, the robot moves on what it mapped."""

    KIND = "lidar_dropout"
    PARAMS = {}

    def degradation(self) -> tuple[float | None, float]:
        return None, 0.0


class LocalisationDrift(Fault):
    """The robot's believed pose drifts from the true one by ``rate_mps`` per second
    of motion, towards ``heading_deg`` (0: +x, 90: +y): it follows paths and
    integrates scans at the drifted pose, so its map smears and its paths may run
    into rock. At ``duration_s`` it relocalises (the drift goes; the map keeps what it
    integrated); without it the drift grows to the end of the run. Overlapping drifts
    add up."""

    KIND = "localisation_drift"
    DURATION = OPTIONAL
    PARAMS = {
        "rate_mps": Param(float, 0.05, "drift per second of motion (m/s)", exclusive_minimum=0.0,
                          maximum=10.0),
        "heading_deg": Param(float, 90.0, "direction of the drift in the horizontal plane (0: +x, 90: +y)",
                             minimum=-360.0, maximum=360.0),
    }
    WORLDS = ("voxel",)

    def velocity(self) -> np.ndarray:
        """The drift's velocity (m per second of motion)."""
        a = math.radians(self.p["heading_deg"])
        return self.p["rate_mps"] * np.array([math.cos(a), math.sin(a), 0.0])

    def _apply(self, mission: "Mission") -> None:
        held = mission.faults.holding(LocalisationDrift, self.robot)
        mission.robots[self.robot].drift(sum((f.velocity() for f in held), np.zeros(3)))

    def start(self, mission: "Mission") -> dict[str, Any]:
        self._apply(mission)
        return {}

    def end(self, mission: "Mission") -> dict[str, Any]:
        robot = mission.robots[self.robot]
        drift = robot.drift_m
        robot.relocalise()
        self._apply(mission)
        return {"drift_m": round(drift, 2)}
