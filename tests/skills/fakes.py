"""A small fake robot for skill tests: it walks paths in straight lines over a fixed
synthetic map (no world, no LiDAR), with a scripted radio, and the helpers that tick a
skill on it."""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import py_trees
import yaml
from delve.executive.tree_loader import build_tree
from delve.planners.occupancy import FREE, UNKNOWN, Grid
from delve.sim.voxel_map import ChangeLog
from delve.skills.base import AgentContext
from delve.skills.robot import PathStatus
from py_trees.common import Status


#: The shipped trees (and their subtrees).
TREES = Path(__file__).resolve().parents[2] / "trees"


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
    """An onboard map that changes only when a test (or ``reset_local_map``) writes to
    it; the first write copies the grid, so a grid shared between tests stays as it is."""

    def __init__(self, grid: Grid):
        self.occupancy, self.origin, self.voxel_size_m, self.version = grid.occupancy, grid.origin, grid.voxel_size_m, 1
        self._own = False
        self._changed: dict[int, int] = {}
        self._logs: list[ChangeLog] = []

    def free_voxels(self) -> np.ndarray:
        return np.flatnonzero(self.occupancy.reshape(-1) == FREE)

    def write(self, flat, values) -> None:
        """Set the voxels ``flat`` (flat indices or a boolean mask of the grid's shape)
        to ``values`` (one value or one each), as a scan would: the version goes up and
        ``take_changes`` reports them."""
        flat = np.asarray(flat)
        if flat.dtype == bool:
            flat = np.flatnonzero(flat.reshape(-1))
        values = np.broadcast_to(np.asarray(values, np.int8), flat.shape)
        if not self._own:
            self.occupancy, self._own = self.occupancy.copy(), True
        self.occupancy.reshape(-1)[flat] = values
        self._changed.update(zip(flat.tolist(), values.tolist()))
        for log in self._logs:
            log.record(flat)
        self.version += 1

    def change_log(self) -> ChangeLog:
        log = ChangeLog()
        self._logs.append(log)
        return log

    def take_changes(self) -> tuple[np.ndarray, np.ndarray]:
        flat = np.array(sorted(self._changed), np.int64)
        values = np.array([self._changed[i] for i in flat.tolist()], np.int8)
        self._changed = {}
        return flat, values


@dataclass(frozen=True)
class FakeMessage:
    sender: str
    recipient: str
    kind: str
    data: Any
    sent_s: float = 0.0


class FakeRadio:
    """A radio with a scripted link. ``link_up`` answers ``linked_to``, and ``ping``
    while ``ping_results`` (results to give, oldest first) is empty. ``send`` keeps
    every message in ``sent`` (and in ``outbox`` until :meth:`flush`, as a real radio
    keeps them while the link is down); ``deliver`` puts a message in the inbox."""

    def __init__(self, name: str = "r1", clock: Any = None):
        self.name = name
        self.clock = clock
        self.link_up = True
        self.ping_results: deque[bool] = deque()
        self.pings: list[tuple[float, str]] = []
        self.sent: list[FakeMessage] = []
        self.outbox: list[FakeMessage] = []
        self.inbox: list[FakeMessage] = []

    def _now(self) -> float:
        return self.clock.now_s if self.clock is not None else 0.0

    def send(self, recipient: str, kind: str, data: Any) -> None:
        msg = FakeMessage(self.name, recipient, kind, data, self._now())
        self.sent.append(msg)
        self.outbox.append(msg)

    def flush(self) -> list[FakeMessage]:
        """The messages that leave the outbox when the link carries them."""
        out, self.outbox = self.outbox, []
        return out

    def deliver(self, sender: str, kind: str, data: Any, sent_s: float = 0.0) -> None:
        self.inbox.append(FakeMessage(sender, self.name, kind, data, sent_s))

    def receive(self) -> list[FakeMessage]:
        out, self.inbox = self.inbox, []
        return out

    def linked_to(self, other: str) -> bool:
        return self.link_up

    @property
    def pending(self) -> int:
        return len(self.outbox)

    def ping(self, other: str) -> bool:
        self.pings.append((self._now(), other))
        return self.ping_results.popleft() if self.ping_results else self.link_up


@dataclass(frozen=True)
class FakeDrop:
    ok: bool
    name: str | None
    remaining: int
    error: str = ""


class FakeRobot:
    """Follows paths in straight lines at its speed when :meth:`step` is called, facing
    the way it walks; a path is BLOCKED where it first comes within ``block_radius_m``
    of ``block_at``. While ``jammed_s`` > 0 (see :meth:`jam`) it follows its path
    without moving, as the simulator's jam fault does. ``payload`` is what the robot
    carries (e.g. the simulator's pan-tilt-zoom camera: skills work out occlusion on
    the onboard map). ``radio`` is a :class:`FakeRadio`; the robot carries
    ``breadcrumbs`` and has ground under it to drop them on while ``has_ground``."""

    def __init__(self, grid: Grid, position, home=None, platform: str = "legged", trail=None,
                 endurance_s=3000.0, payload=None, breadcrumbs: int = 0):
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
        self.radio = FakeRadio(self.name)
        self.jammed_s = 0.0
        self.breadcrumbs = breadcrumbs
        self.has_ground = True
        self.drops: list[np.ndarray] = []
        self.map_resets: list[float] = []
        #: Artifact readings the next take_* call returns (tests fill them).
        self.camera_detections: list = []
        self.signal_readings: list = []
        #: Range-sensor sweeps the next take_lidar_scans call returns (tests fill them).
        self.lidar_scans: list = []

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

    def take_camera_detections(self) -> list:
        out, self.camera_detections = self.camera_detections, []
        return out

    def take_signal_readings(self) -> list:
        out, self.signal_readings = self.signal_readings, []
        return out

    def take_lidar_scans(self) -> list:
        out, self.lidar_scans = self.lidar_scans, []
        return out

    def follow_path(self, path) -> None:
        self.path = np.asarray(path, float).reshape(-1, 3)

        self.paths.append(self.path.copy())
        self.path_status = PathStatus.FOLLOWING

    def stop(self) -> None:
        self.stops += 1
        self.path = None
        if self.path_status == PathStatus.FOLLOWING:
            self.path_status = PathStatus.IDLE

    def jam(self, duration_s: float) -> None:
        """The feet are stuck for ``duration_s`` of :meth:`step` time."""
        self.jammed_s = max(self.jammed_s, duration_s)

    def deploy_breadcrumb(self) -> FakeDrop:
        if self.breadcrumbs <= 0:
            return FakeDrop(False, None, 0, f"{self.name} has no breadcrumbs left")
        if not self.has_ground:
            return FakeDrop(False, None, self.breadcrumbs,
                            f"{self.name} has no ground below to drop a breadcrumb on")
        self.breadcrumbs -= 1
        self.drops.append(self.position)
        return FakeDrop(True, f"{self.name}_crumb{len(self.drops)}", self.breadcrumbs)

    def reset_local_map(self, radius_m: float) -> None:
        """Forget the map within ``radius_m`` of the robot (set it UNKNOWN)."""
        self.map_resets.append(radius_m)
        m = self.onboard_map
        idx = np.indices(m.occupancy.shape).reshape(3, -1).T
        centres = m.origin + (idx + 0.5) * m.voxel_size_m
        m.write(np.linalg.norm(centres - self._pos, axis=1) <= radius_m, UNKNOWN)

    def step(self, dt_s: float = 1.0) -> None:
        if self.path_status != PathStatus.FOLLOWING or self.path is None:
            return
        if self.jammed_s > 0:
            self.jammed_s = max(0.0, self.jammed_s - dt_s)
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
    radio = getattr(robot, "radio", None)
    if isinstance(radio, FakeRadio) and radio.clock is None:
        radio.clock = ctx.clock  # messages carry the sim time they were sent at
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


def build(text: str, ctx, within: Path = TREES):
    """Build the tree node written in YAML ``text`` for the agent ``ctx``, as a tree
    file in ``within`` names it (so ``include: subtrees/x.yaml`` finds shipped subtrees)."""
    return build_tree(yaml.safe_load(text), ctx, file=within / "inline.yaml")


def bb(key: str, agent: str = "r1", default: Any = None) -> Any:
    """An agent's blackboard entry, ``default`` when it was never written."""
    return py_trees.blackboard.Blackboard.storage.get(f"/{agent}/{key}", default)


def body(p, dx: float = 0.0, dy: float = 0.0) -> np.ndarray:
    """The body centre of a legged robot standing ``dx`` along and ``dy`` across from the
    floor point ``p`` of a synthetic tunnel (floor at ``p``'s z, body 0.5 m above)."""
    return np.asarray(p, float) + np.array([dx, dy, 0.5])
