"""A robot on a graph world: it drives tunnel by tunnel and explores the locations
it reaches. It implements the robot interface's motion and radio parts and its
``NetworkView`` (``topology``, ``location``, ``route``); there is no voxel map (its
onboard map is empty), no payload and no breadcrumb."""
from __future__ import annotations

from typing import Any

import networkx as nx
import numpy as np

from .body import RobotBody
from .graph_radio import GraphRadioEndpoint
from .graph_world import GraphWorld, Known
from .platforms import Platform
from .radio import BreadcrumbDrop
from .voxel_map import VoxelMap

IDLE, FOLLOWING, ARRIVED, BLOCKED = "idle", "following", "arrived", "blocked"


class GraphRobot(RobotBody):
    """A robot on a :class:`GraphWorld`: drives tunnel by tunnel, explores locations.

    ``follow_path`` takes waypoints that must be locations, each joined to the one
    before (or to the robot's location) by a tunnel; otherwise the path is blocked.
    """

    def __init__(self, name: str, platform: Platform, world: GraphWorld, start: np.ndarray,
                 radio: GraphRadioEndpoint, endurance_s: float | None = None):
        self._name = name
        self._platform = platform
        self.world = world
        self._radio = radio
        start_at = world.location_at(np.asarray(start, dtype=float))
        self._pos = world.pos(start_at).copy() if start_at is not None else np.asarray(start, float).reshape(3).copy()
        self._home = self._pos.copy()
        self._endurance = float(platform.endurance_s if endurance_s is None else endurance_s)
        self._distance = 0.0
        self._trail = [self._pos.copy()]
        self._path: list[np.ndarray] = []
        self._status = IDLE
        self._commands = 0
        self._alive = True
        self._parked = False
        self.blocked_reason = ""
        self._last_location: str | None = None
        self._stuck_s = 0.0
        self.transitions = 0
        self._known = Known()
        self._map = VoxelMap((0, 0, 0), self._home, 1.0)
        self._arrive()

    # ---- the robot interface (motion, radio; the rest in RobotBody) ---------------
    @property
    def traversed_path(self) -> np.ndarray:
        return np.array(self._trail + [self._pos])

    @property
    def radio(self) -> GraphRadioEndpoint:
        return self._radio

    @property
    def remaining_path(self) -> np.ndarray:
        return np.array(self._path).reshape(-1, 3)

    @property
    def alive(self) -> bool:
        return self._alive and self._endurance > 0

    def follow_path(self, path: np.ndarray) -> None:
        self._commands += 1
        pts = np.asarray(path, dtype=float).reshape(-1, 3)
        here = self.world.location_at(self._pos) or self._last_location
        stops = []
        for p in pts:
            loc = self.world.location_at(p)
            if loc is None or (loc != here and not self.world.graph.has_edge(here, loc)):
                self._path, self._status = [], BLOCKED
                self.blocked_reason = f"no tunnel from {here} to {np.round(p, 1).tolist()}"
                return
            stops.append(self.world.pos(loc).copy())
            here = loc
        self._path, self._status, self.blocked_reason = stops, FOLLOWING if stops else ARRIVED, ""

    def stop(self) -> None:
        self._commands += 1
        self._path = []
        if self._status == FOLLOWING:
            self._status = IDLE

    def park(self) -> None:
        self.stop()
        self._parked = True

    @property
    def explored(self) -> list[str]:
        """Locations this robot explored, in order."""
        return self._known.explored

    def jam(self, duration_s: float) -> None:
        """A fault: the robot cannot move for ``duration_s``."""
        self._stuck_s = max(self._stuck_s, duration_s)

    def kill(self) -> None:
        """The robot dies where it stands: it stops and its radio falls silent."""
        self._alive = False
        self._path = []
        self._status = BLOCKED
        self.blocked_reason = "robot lost"
        self._radio.silent = True

    # ---- the rest of the robot interface: what a graph robot does without -----------
    @property
    def yaw_rad(self) -> float:
        """A graph robot keeps no heading: 0."""
        return 0.0

    @property
    def onboard_map(self) -> VoxelMap:
        """Empty: a graph robot senses locations, not voxels (its map is ``topology``)."""
        return self._map

    def reset_local_map(self, radius_m: float) -> None:
        """Nothing to forget: the onboard map is empty."""

    @property
    def breadcrumbs(self) -> int:
        return 0

    def deploy_breadcrumb(self) -> BreadcrumbDrop:
        return BreadcrumbDrop(False, self._name, None, 0, f"{self._name} carries no breadcrumbs on a graph world")

    @property
    def payload(self) -> None:
        return None

    def take_camera_detections(self) -> list:
        """No artifact sensors on a graph world."""
        return []

    def take_signal_readings(self) -> list:
        return []

    def take_lidar_scans(self) -> list:
        """No range sensor on a graph world."""
        return []

    # ---- NetworkView --------------------------------------------------------------
    def topology(self) -> dict[str, Any]:
        """What this robot explored so far, as a plain topology dict."""
        return self._known.as_dict()

    def location(self) -> str | None:
        """The location the robot has reached (and explored); None on the way."""
        loc = self._last_location
        return loc if loc is not None and np.allclose(self._pos, self.world.pos(loc)) else None

    def arrived(self, location: str) -> bool:
        """At a location is at its position."""
        return self.location() == location

    def route(self, location: str) -> np.ndarray | None:
        """Waypoints along known tunnels to ``location`` (shortest by length)."""
        here = self.location() or self._last_location
        k = self._known
        if location not in k.locations or here is None:
            return None
        g = nx.Graph()
        g.add_weighted_edges_from((u, v, length) for (u, v), length in k.mobility.items())
        if here == location:
            return np.array([self.world.pos(location)])
        try:
            names = nx.shortest_path(g, here, location, weight="weight")
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            return None
        return np.array([self.world.pos(s) for s in names[1:]])

    # ---- simulation ------------------------------------------------------------
    def step(self, dt_s: float) -> None:
        if not self._alive or self._parked:
            return
        self._endurance = max(0.0, self._endurance - dt_s)
        if self._endurance == 0.0:
            # The battery is flat: the robot stops for good and its radio falls silent.
            self._path, self._status, self.blocked_reason = [], BLOCKED, "endurance exhausted"
            self._alive = False
            self._radio.silent = True
            return
        if self._stuck_s > 0:
            self._stuck_s = max(0.0, self._stuck_s - dt_s)
            return
        budget = self._platform.speed_mps * dt_s
        while budget > 1e-9 and self._path:
            delta = self._path[0] - self._pos
            dist = float(np.linalg.norm(delta))
            move = min(budget, dist)
            if dist > 1e-9:
                self._pos = self._pos + delta * (move / dist)
            self._distance += move
            budget -= move
            if move >= dist - 1e-9:
                self._pos = self._path.pop(0).copy()
                self._trail.append(self._pos.copy())
                self._arrive()
        if not self._path and self._status == FOLLOWING:
            self._status = ARRIVED

    def _arrive(self) -> None:
        """Count the transition and explore the location the robot reached."""
        loc = self.world.location_at(self._pos)
        if loc is None:
            return
        if self._last_location is not None and loc != self._last_location:
            self.transitions += 1
        self._last_location = loc
        self.world.reveal(self._known, loc)
