"""COPS on voxel worlds: a robot's view of the mobility-communication network.

:class:`VoxelNetworkView` implements the robot interface's ``NetworkView`` for any
robot with an onboard voxel map. The network is extracted from what the robot has
mapped (:func:`delve.planners.cops.extraction.extract_topology`): locations are the
cells of a fixed world lattice, so every robot names a place the same way.

The robot's navigation graph (:mod:`delve.skills.navigation`) says where it can go:
a legged robot stands on the voxels that are nodes of its legged graph (and, when
it steps higher than a voxel, on the risers of its steps); a flying robot flies
through the known-free voxels around the nodes of its aerial graph. Routes to a
location are shortest paths on the same graph. The cells the robot has passed
through (its traversed path) count as explored.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..planners.cops.extraction import (
    DEFAULT_CELL_M,
    DEFAULT_COMM_RANGE_M,
    DEFAULT_MIN_FREE_VOXELS,
    cell_name,
    extract_topology,
    lattice_cells,
)
from ..planners.cops.topology import Topology
from ..planners.navgraph import NavGraph
from ..planners.occupancy import FREE, Grid
from .base import AgentContext
from .navigation import Navigator
from .robot import Robot

#: Flying robots' standable voxels: the free voxels within this many voxels of a node
#: of the aerial graph (whose nodes lie on a lattice of every second voxel).
AERIAL_NODE_REACH_VOXELS = 1
#: Rounding allowance when counting how many voxels a legged robot's step spans (as
#: ``legged_graph`` counts it).
_STEP_TOLERANCE_VOXELS = 1e-9


class _MapClock:
    """A clock that never advances: a navigator on it rebuilds on every map change."""

    now_s = 0.0


class VoxelNetworkView:
    """The COPS network a robot's onboard map reveals (the ``NetworkView`` protocol).

    ``topology()`` is extracted again whenever the map, the navigation graph or the
    robot's traversed path has changed since the last call. Pass the agent's shared ``navigator``
    (:func:`delve.skills.navigation.navigator`) to plan on one graph per agent; by
    default the view keeps its own, rebuilt on every map change.
    """

    def __init__(self, robot: Robot, *, cell_m: float = DEFAULT_CELL_M,
                 comm_range_m: float = DEFAULT_COMM_RANGE_M, min_free_voxels: int = DEFAULT_MIN_FREE_VOXELS,
                 navigator: Navigator | None = None):
        if not (isinstance(cell_m, (int, float)) and math.isfinite(cell_m) and cell_m > 0):
            raise ValueError(f"cell_m must be a positive finite number, got {cell_m!r}")
        self.robot = robot
        self.cell_m = float(cell_m)
        self.comm_range_m = float(comm_range_m)
        self.min_free_voxels = min_free_voxels
        self.navigator = navigator if navigator is not None else Navigator(
            robot, _own_context(robot), rebuild_period_s=0.0)
        self._key: tuple[int, NavGraph, int] | None = None
        self._topology = Topology()
        self.extractions = 0

    # -- the NetworkView protocol ---------------------------------------------------------
    def topology(self) -> dict[str, Any]:
        """The plain-dict :class:`Topology` of the robot's map (a fresh dict each call)."""
        return self.current().to_dict()

    def location(self) -> str | None:
        """The location whose cell holds the robot's ground point, or None."""
        name = cell_name(lattice_cells(self.ground_point()[None], self.cell_m)[0])
        return name if name in self.current().locations else None

    def route(self, location: str) -> np.ndarray | None:
        """Waypoints (N, 3) along the navigation graph from the robot to the node nearest
        the location's position; None for an unknown location or when none is reachable."""
        pos = self.current().locations.get(location)
        if pos is None:
            return None
        path, _ = self.navigator.path_to_point(np.asarray(pos) + [0.0, 0.0, self.sight_height_m()])
        return path

    # -- helpers ----------------------------------------------------------------------------
    def current(self) -> Topology:
        """The cached :class:`Topology`, extracted again if the map, the navigation
        graph or the robot's traversed path changed."""
        graph = self.navigator.graph()
        trail = np.asarray(self.robot.traversed_path, dtype=float).reshape(-1, 3)
        version, visits = self.robot.onboard_map.version, len(trail)
        if self._key is None or self._key[1] is not graph or (self._key[0], self._key[2]) != (version, visits):
            grid = self.navigator.grid()
            self._topology = extract_topology(
                grid.occupancy, grid.origin, grid.voxel_size_m, standable=self.standable(grid, graph),
                free=grid.free, cell_m=self.cell_m, comm_range_m=self.comm_range_m,
                min_free_voxels=self.min_free_voxels, sight_height_m=self.sight_height_m(),
                visited=self.ground_points(trail))
            self._key = (version, graph, visits)
            self.extractions += 1
        return self._topology

    def standable(self, grid: Grid, graph: NavGraph) -> np.ndarray:
        """Bool mask of the voxels the robot stands on (legged) or flies through (aerial)."""
        mob = self.robot.mobility
        vox = grid.voxel_size_m
        mask = np.zeros(grid.shape, dtype=bool)
        if mob.aerial:
            nodes = grid.to_index(graph.positions)
            reach = range(-AERIAL_NODE_REACH_VOXELS, AERIAL_NODE_REACH_VOXELS + 1)
            offsets = [(a, b, c) for a in reach for b in reach for c in reach]
        else:
            nodes = grid.to_index(graph.positions - [0.0, 0.0, mob.body_height_m - 0.5 * vox])
            rise = max(1, math.floor(mob.max_step_m / vox + _STEP_TOLERANCE_VOXELS))
            offsets = [(0, 0, c) for c in range(rise)]
        for d in offsets:
            idx = nodes + d
            idx = idx[grid.in_bounds(idx)]
            mask[idx[:, 0], idx[:, 1], idx[:, 2]] = True
        return mask & (grid.occupancy == FREE)

    def sight_height_m(self) -> float:
        """How far above a location's position the robot's body (and radio) is."""
        mob = self.robot.mobility
        return 0.0 if mob.aerial else max(0.0, mob.body_height_m - 0.5 * self.robot.onboard_map.voxel_size_m)

    def ground_point(self) -> np.ndarray:
        """The centre of the voxel the robot stands in (legged) or flies in (aerial)."""
        return self.ground_points(np.asarray(self.robot.position, dtype=float)[None])[0]

    def ground_points(self, body: np.ndarray) -> np.ndarray:
        """Body positions (N, 3) -> the centres of the voxels the robot stands in there."""
        return body - [0.0, 0.0, self.sight_height_m()]


def _own_context(robot: Robot) -> AgentContext:
    """A minimal agent context for a navigator that only this view uses."""
    return AgentContext(name=robot.name, namespace=f"/{robot.name}", clock=_MapClock(),
                        log=lambda *args, **kwargs: None, robot=robot)
