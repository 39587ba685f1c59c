"""A small fake robot for skill tests: it walks paths in straight lines over a fixed
synthetic map (no world, no LiDAR), and the helpers that tick a skill on it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from delve.planners.occupancy import FREE, Grid
from delve.skills.base import AgentContext
from delve.skills.robot import PathStatus
from py_trees.common import Status


class Clock:
    def __init__(self) -> None:
        self.now_s = 0.0


@dataclass
class FakeMobility:
    aerial: bool = False
    speed_mps: float = 1.0
    body_height_m: float = 0.5
    radius_m: float = 0.4
    max_inclination_deg: float = 35.0
    max_step_m: float = 0.3


class FakeMap:
    """A fixed onboard map."""

    def __init__(self, grid: Grid):
        self.occupancy, self.origin, self.voxel_size_m, self.version = grid.occupancy, grid.origin, grid.voxel_size_m, 1

    def free_voxels(self) -> np.ndarray:
        return np.flatnonzero(self.occupancy.reshape(-1) == FREE)

    def take_changes(self) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(0, np.int64), np.zeros(0, np.int8)


class FakeRobot:
    """Follows paths in straight lines at its speed when :meth:`step` is called, facing
    the way it walks; a path is BLOCKED where it first comes within ``block_radius_m``
    of ``block_at``. ``payload`` is what the robot carries (e.g. the simulator's
    pan-tilt-zoom camera: skills work out occlusion on the onboard map)."""

    def __init__(self, grid: Grid, position, home=None, platform: str = "legged", trail=None,
                 endurance_s=3000.0, payload=None):
        self.name = "r1"
        self.platform = platform
        self.mobility = FakeMobility(aerial=platform == "aerial")
        self.onboard_map = FakeMap(grid)
        self._pos = np.asarray(position, float)
        self.home = np.asarray(home if home is not None else position, float)
        self.yaw_rad = 0.0
        self.view_up_deg = 15.0
        self.endurance_remaining_s = endurance_s
        self.distance_m = 0.0
        self.trail = [np.asarray(p, float) for p in (trail if trail is not None else [position])]
        self.path: np.ndarray | None = None
        self.path_status = PathStatus.IDLE
        self.paths: list[np.ndarray] = []
        self.stops = 0
        self.block_at: np.ndarray | None = None
        self.block_radius_m = 0.3
        self.blocked_reason = ""
        self.payload = payload

    @property
    def position(self) -> np.ndarray:
        return self._pos.copy()

    @property
    def traversed_path(self) -> np.ndarray:
        return np.asarray(self.trail)

    @property
    def remaining_path(self) -> np.ndarray:
        if self.path_status != PathStatus.FOLLOWING or self.path is None:
            return np.zeros((0, 3))
        return self.path.copy()

    @property
    def command_id(self) -> int:
        return len(self.paths) + self.stops

    def follow_path(self, path) -> None:
        self.path = np.asarray(path, float).reshape(-1, 3)

        self.paths.append(self.path.copy())
        self.path_status = PathStatus.FOLLOWING

    def stop(self) -> None:
        self.stops += 1
        self.path = None
        if self.path_status == PathStatus.FOLLOWING:
            self.path_status = PathStatus.IDLE

    def step(self, dt_s: float = 1.0) -> None:
        if self.path_status != PathStatus.FOLLOWING or self.path is None:
            return
        budget = self.mobility.speed_mps * dt_s
        while budget > 1e-9 and len(self.path):
            target = self.path[0]
            d = float(np.linalg.norm(target - self._pos))
            if d > 1e-9:
                self.yaw_rad = float(np.arctan2(target[1] - self._pos[1], target[0] - self._pos[0]))
            move = min(budget, d)
            new = self._pos + (target - self._pos) * (move / d) if d > 1e-9 else target.copy()
            if self.block_at is not None and np.linalg.norm(new - self.block_at) < self.block_radius_m:
                self.path, self.path_status, self.blocked_reason = None, PathStatus.BLOCKED, "rock in the way"
                return
            self.distance_m += float(np.linalg.norm(new - self._pos))
            self._pos = new
            budget -= move
            if np.linalg.norm(self.trail[-1] - self._pos) >= 0.5:
                self.trail.append(self._pos.copy())
            if d - move < 1e-9:
                self.path = self.path[1:]
        if self.path is not None and len(self.path) == 0:
            self.path, self.path_status = None, PathStatus.ARRIVED


def make_ctx(robot, name: str = "r1") -> AgentContext:
    events: list[tuple[str, dict]] = []
    ctx = AgentContext(name=name, namespace=f"/{name}", clock=Clock(),
                       log=lambda event, **fields: events.append((event, fields)), robot=robot)
    ctx.events = events  # type: ignore[attr-defined]
    return ctx


def run(node, ctx, robot, ticks: int = 200, dt_s: float = 1.0) -> Status:
    """Tick ``node`` and step the robot until the node is done (or ``ticks`` ran out)."""
    for _ in range(ticks):
        node.tick_once()
        if node.status != Status.RUNNING:
            return node.status
        robot.step(dt_s)
        ctx.clock.now_s += dt_s
    return node.status


def events(ctx, kind: str) -> list[dict]:
    return [f for e, f in ctx.events if e == kind]
