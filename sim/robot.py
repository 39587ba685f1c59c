"""Kinematic robots: they follow paths, scan with their LiDAR and never pass through rock.

``SimRobot`` implements the robot interface that skills own (``delve.skills.robot``).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .artifact_sensors import CameraDetection, SignalReading
from .body import RobotBody
from .lidar import LidarScan
from .payload import PanTiltZoomCamera
from .platforms import Platform
from .radio import BREADCRUMB_ANTENNA_HEIGHT_M, BreadcrumbDrop
from .voxel_map import OCCUPIED, UNKNOWN, VoxelMap


if TYPE_CHECKING:
    from .radio import RadioEndpoint
    from .world import World

IDLE, FOLLOWING, ARRIVED, BLOCKED = "idle", "following", "arrived", "blocked"
#: Range-sensor sweeps a robot keeps for ``take_lidar_scans`` (the oldest go first).
LIDAR_SCANS_KEPT = 20
_GOLDEN = (math.sqrt(5) - 1) / 2


class SimRobot(RobotBody):
    """A legged or aerial robot in a :class:`World`.

    Legged robots keep their body ``body_height_m`` above the ground, refuse steps
    above ``max_step_m`` and ground inclinations above ``max_inclination_deg``
    (measured over ``inclination_window_m`` of travel). Aerial robots fly in 3D.
    Endurance counts down with sim time; at zero the robot stops for good and its
    radio falls silent.

    Faults (injected by the executive's fault kinds): ``jam``, ``kill``,
    ``inject_map_artifact``, ``drain_battery``, ``degrade_lidar`` /
    ``restore_lidar`` and ``drift`` / ``relocalise``. With a localisation drift the
    robot believes it stands at ``position`` = ``true_position`` + the drift: it
    follows paths and integrates its scans in that believed frame.
    """

    inclination_window_m = 1.0
    trail_spacing_m = 0.5

    def __init__(
        self,
        name: str,
        platform: Platform,
        world: "World",
        start: np.ndarray,
        radio: "RadioEndpoint",
        endurance_s: float | None = None,
    ):
        self._name = name
        self._platform = platform
        self.world = world
        self._radio = radio
        self._map = VoxelMap(world.free.shape, world.origin, world.voxel_size_m)
        start = np.asarray(start, dtype=float)
        if platform.aerial:
            self._ground = math.nan
            self._pos = start + np.array([0.0, 0.0, platform.body_height_m])
        else:
            self._ground = float(start[2])
            self._pos = start + np.array([0.0, 0.0, platform.body_height_m])
        self._home = self._pos.copy()
        self._yaw = 0.0
        self._endurance = float(endurance_s if endurance_s is not None else platform.endurance_s)
        self._distance = 0.0
        self._trail = [self._pos.copy()]
        self._trail_since = 0.0
        self._slope_hist: list[tuple[float, float]] = [(0.0, self._ground)]
        self._path: np.ndarray | None = None
        self._wp = 0
        self._status = IDLE
        self.blocked_reason = ""
        self._scans = 0
        #: Sim time the robot spent moving (the paper's "operational" time, Table 3).
        self.moving_s = 0.0
        self._detections: list[CameraDetection] = []
        self._signals: list[SignalReading] = []
        self._commands = 0

        self._stuck_s = 0.0
        self._parked = False
        self._down = False
        #: Localisation drift: believed minus true position, and how fast it grows (m/s of motion).
        self._drift = np.zeros(3)
        self._drift_mps = np.zeros(3)

        self._payload: PanTiltZoomCamera | None = None

        #: Sweeps not yet taken (None until a tree first asks: nothing is kept for trees that never do).
        self._lidar_scans: deque[LidarScan] | None = None

        self._all_sensors = [(spec, spec.beam_directions(0.0))
                             for spec in (platform.lidar, platform.terrain) if spec]
        self._sensors = list(self._all_sensors)

    # ---- the robot interface (the rest in RobotBody) ----------------------------
    @property
    def position(self) -> np.ndarray:
        """Where the robot believes it is: its true position plus its localisation drift."""
        return self._pos + self._drift

    @property
    def yaw_rad(self) -> float:
        return self._yaw

    @property
    def onboard_map(self) -> VoxelMap:
        return self._map

    @property
    def traversed_path(self) -> np.ndarray:
        return np.array(self._trail)

    @property
    def radio(self) -> "RadioEndpoint":
        return self._radio

    @property
    def breadcrumbs(self) -> int:
        """Breadcrumbs (mesh relay nodes) the robot still carries."""
        return self._radio.breadcrumbs

    def deploy_breadcrumb(self) -> BreadcrumbDrop:
        """Drop a breadcrumb on the ground under the robot, its antenna
        ``BREADCRUMB_ANTENNA_HEIGHT_M`` up. A refusal (none left, no ground) is a
        result with ``ok=False`` and an ``error``, never an exception."""
        if self._platform.aerial:
            drop = float(self._pos[2] - self.world.origin[2])
            ground = float(self.world.ground_height(self._pos[None], drop)[0])
        else:
            ground = self._ground
        if math.isnan(ground):
            return BreadcrumbDrop(False, self._name, None, self.breadcrumbs,
                                  f"{self._name} has no ground below to drop a breadcrumb on")
        spot = np.array([self._pos[0], self._pos[1], ground + BREADCRUMB_ANTENNA_HEIGHT_M])
        return self._radio.deploy_breadcrumb(spot)

    @property
    def remaining_path(self) -> np.ndarray:
        """(M, 3) waypoints of the path being followed not reached yet, the next one
        first; (0, 3) when the robot follows none."""
        if self._status != FOLLOWING or self._path is None:
            return np.zeros((0, 3))
        return self._path[self._wp:].copy()

    @property
    def payload(self) -> PanTiltZoomCamera | None:
        """The pan-tilt-zoom inspection camera (the paper's values), created on first
        use. Legged robots carry it, as the ANYmal Explorers did; aerial robots do not."""
        if self._payload is None and not self._platform.aerial:
            self._payload = PanTiltZoomCamera(self.world)
        return self._payload

    # ---- artifact sensors (their readings come from the mission's ArtifactSensors) ----
    def receive_artifact_readings(self, readings: list) -> None:
        """Keep the artifact sensors' new readings for the fusion behaviours."""
        for r in readings:
            (self._detections if isinstance(r, CameraDetection) else self._signals).append(r)

    def take_camera_detections(self) -> list[CameraDetection]:
        out, self._detections = self._detections, []
        return out

    def take_lidar_scans(self) -> list[LidarScan]:
        """The range sensors' sweeps since the last call, oldest first (at most
        :data:`LIDAR_SCANS_KEPT`); the first call starts keeping them."""
        if self._lidar_scans is None:
            self._lidar_scans = deque(maxlen=LIDAR_SCANS_KEPT)
        out = list(self._lidar_scans)
        self._lidar_scans.clear()
        return out

    def take_signal_readings(self) -> list[SignalReading]:
        out, self._signals = self._signals, []
        return out

    @property
    def alive(self) -> bool:
        return not self._down and self._endurance > 0

    def jam(self, duration_s: float) -> None:
        """A fault: the feet (or rotors) are stuck for ``duration_s``; a path being
        followed stays FOLLOWING but the robot does not move."""
        self._stuck_s = max(self._stuck_s, duration_s)

    def kill(self) -> None:
        """A fault: the robot dies where it stands; it stops and its radio falls silent."""
        self.stop()
        self._endurance = 0.0
        self._down = True
        self._radio.silent = True

    def inject_map_artifact(self, radius_m: float = 1.5) -> None:
        """A fault: the state estimator jumps, the robot halts, and rock appears in its
        onboard map all around it, as odometry drift leaves in a real map, so planners
        find its start pose invalid."""
        self.stop()
        self._map.set_sphere(self.position, radius_m, OCCUPIED)

    def degrade_lidar(self, range_m: float | None = None, ray_fraction: float = 1.0) -> None:
        """A fault: every range sensor (the LiDAR, a legged robot's terrain cameras)
        reaches at most ``range_m`` and keeps ``ray_fraction`` of its beams (0: a
        dropout, the sensors return nothing); :meth:`restore_lidar` ends it."""
        self._sensors = []
        for spec, beams in self._all_sensors:
            if range_m is not None and range_m < spec.range_m:
                spec = replace(spec, range_m=float(range_m))
            keep = (np.arange(len(beams)) * _GOLDEN) % 1.0 < ray_fraction
            if keep.any():
                self._sensors.append((spec, beams[keep]))

    def restore_lidar(self) -> None:
        """The range sensors work again as the platform has them."""
        self._sensors = list(self._all_sensors)

    def drift(self, velocity_mps: np.ndarray) -> None:
        """A fault: from now on the believed position drifts from the true one by
        ``velocity_mps`` (3,) per second of motion; zero stops the drift (what has
        drifted stays until :meth:`relocalise`)."""
        self._drift_mps = np.asarray(velocity_mps, dtype=float).reshape(3).copy()

    def relocalise(self) -> None:
        """The state estimator finds its true pose again: the drift is gone (the map
        keeps what it integrated while drifting)."""
        self._drift_mps = np.zeros(3)
        self._drift = np.zeros(3)

    @property
    def drift_m(self) -> float:
        """How far the believed position is from the true one now."""
        return float(np.linalg.norm(self._drift))


    def reset_local_map(self, radius_m: float) -> None:
        """Forget the onboard map within ``radius_m`` of the robot (the next scans
        map it again), as the paper's behaviour tree resets the elevation map."""
        self._map.set_sphere(self.position, radius_m, UNKNOWN)

    def park(self) -> None:
        """Stop and power down: endurance no longer counts down (the mission is over)."""
        self.stop()
        self._parked = True

    def follow_path(self, path: np.ndarray) -> None:
        self._commands += 1
        path = np.asarray(path, dtype=float).reshape(-1, 3)
        if len(path) == 0 or not np.all(np.isfinite(path)):
            self._status, self.blocked_reason = BLOCKED, "empty or non-finite path"
            return
        self._path, self._wp, self._status, self.blocked_reason = path, 0, FOLLOWING, ""

    def stop(self) -> None:
        self._commands += 1
        self._path = None
        if self._status == FOLLOWING:
            self._status = IDLE

    # ---- simulation ------------------------------------------------------------
    def step(self, dt_s: float) -> None:
        """Advance endurance and motion by one sim step. When the endurance runs out
        the robot stops for good (path BLOCKED, "endurance exhausted") and its radio
        falls silent."""
        if self._down or self._parked:
            return
        self._endurance = max(0.0, self._endurance - dt_s)
        if self._endurance == 0.0:
            self._path = None
            self._status = BLOCKED
            self.blocked_reason = "endurance exhausted"
            self._down = True
            self._radio.silent = True
            return
        if self._status != FOLLOWING or self._path is None:
            return
        if self._stuck_s > 0:
            self._stuck_s = max(0.0, self._stuck_s - dt_s)
            return
        if self._drift_mps.any():
            self._drift = self._drift + self._drift_mps * dt_s
        before = self._distance
        self._advance(self._platform.speed_mps * dt_s)
        if self._distance > before:
            self.moving_s += dt_s

    def _advance(self, budget: float) -> None:
        """Walk (or fly) up to ``budget`` metres along the path being followed."""
        while budget > 1e-9 and self._status == FOLLOWING:
            target = self._path[self._wp] - self._drift
            delta = target - self._pos
            if not self._platform.aerial:
                delta[2] = 0.0
            dist = float(np.linalg.norm(delta))
            if dist < 1e-6:
                self._wp += 1
                if self._wp >= len(self._path):
                    self._status, self._path = ARRIVED, None
                continue
            move = min(budget, dist)
            if not self._move(self._pos + delta * (move / dist)):
                return
            budget -= move
            self._yaw = math.atan2(delta[1], delta[0])

    def _move(self, new: np.ndarray) -> bool:
        """Move to ``new`` if the platform can stand or fly there; else stop BLOCKED."""
        p = self._platform
        if p.aerial:
            if not self.world.is_free(new[None])[0]:
                return self._block("rock in the way")
        else:
            ground = self._ground_below(new[0], new[1])
            if math.isnan(ground) or abs(ground - self._ground) > p.max_step_m + 1e-6:
                return self._block("no ground or step too high")
            new = np.array([new[0], new[1], ground + p.body_height_m])
            if not self.world.is_free_at(float(new[0]), float(new[1]), float(new[2])):
                return self._block("rock in the way")
            travelled = self._slope_hist[-1][0] + float(np.hypot(*(new[:2] - self._pos[:2])))
            hist = self._slope_hist + [(travelled, ground)]
            while len(hist) > 2 and travelled - hist[1][0] >= self.inclination_window_m:
                hist.pop(0)
            run = travelled - hist[0][0]
            if run >= self.inclination_window_m:
                incline = math.degrees(math.atan2(abs(ground - hist[0][1]), run))
                if incline > p.max_inclination_deg:
                    return self._block(f"inclination {incline:.0f}° above {p.max_inclination_deg:.0f}°")
            self._slope_hist = hist
            self._ground = ground
        step = float(np.linalg.norm(new - self._pos))
        self._distance += step
        self._trail_since += step
        self._pos = new
        if self._trail_since >= self.trail_spacing_m:
            self._trail.append(new + self._drift)
            self._trail_since = 0.0
        return True

    def _ground_below(self, x: float, y: float) -> float:
        """Height of the rock surface under (x, y) near the current ground, by a ray cast
        down onto the world mesh (continuous, unlike the voxel grid); NaN if none."""
        reach = self._platform.max_step_m + 0.3
        x, y, z = float(x), float(y), float(self._ground + reach)
        if not self.world.is_free_at(x, y, z):
            return math.nan
        d = self.world.distance_down(x, y, z, 2 * reach)
        return self._ground + reach - d if math.isfinite(d) else math.nan

    def _block(self, reason: str) -> bool:
        self._status, self.blocked_reason, self._path = BLOCKED, reason, None
        return False

    def scan(self) -> None:
        """One sweep of each range sensor (LiDAR, terrain cameras) into the onboard map."""
        # Rotate each fan a little every sweep, as an unsynchronised spinning LiDAR
        # does, so that successive sweeps sample different voxels.
        turn = (self._scans * _GOLDEN) % 1.0
        for spec, beams in self._sensors:
            sensor = self._pos + np.array([0.0, 0.0, spec.mount_height_m])
            yaw = (self._yaw if spec.horizontal_fov_deg < 360 else 0.0) + turn * math.radians(
                spec.horizontal_resolution_deg)
            c, s = math.cos(yaw), math.sin(yaw)
            dirs = np.stack([c * beams[:, 0] - s * beams[:, 1], s * beams[:, 0] + c * beams[:, 1], beams[:, 2]], axis=1)
            ranges = self.world.cast_rays(np.broadcast_to(sensor, dirs.shape), dirs, spec.range_m)
            self._map.integrate_scan(sensor + self._drift, dirs, ranges, spec.range_m)
            if self._lidar_scans is not None:
                hit = ranges <= spec.range_m
                at = sensor + self._drift
                self._lidar_scans.append(LidarScan(at, at + dirs[hit] * ranges[hit, None]))
        self._scans += 1
