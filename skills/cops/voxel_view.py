"""COPS on voxel worlds: a robot's view of the mobility-communication network.

:class:`VoxelNetworkView` implements the robot interface's ``NetworkView`` for any
robot with an onboard voxel map. The network is extracted from what the robot has
mapped (:func:`delve.planners.cops.extraction.extract_topology`, kept up to date
from the voxels the map changed by an
:class:`~delve.planners.cops.extraction_incremental.ExtractionUpdater`): locations are
the cells of a fixed world lattice, so every robot names a place the same way.

The robot's navigation graph (:mod:`delve.skills.navigation`) says where it can
stand: a legged robot on the voxels that are nodes of its legged graph (and, when it
steps higher than a voxel, on the risers of its steps), a flying robot in the
known-free voxels around the nodes of its aerial graph. Connectivity, though, is
that of the known free space: a LiDAR sees a tunnel's floor in rings, so the
standable voxels of one scan are rings with gaps between them that the free space
above spans. Routes to a location are shortest paths on the navigation graph; where
the graph does not reach a location yet, the route leads to the reachable node
nearest it, and the robot asks again there, with more of the floor mapped. The cells
the robot has passed through (its traversed path) count as explored.

Cells side by side in an open area are merged into one location
(:mod:`delve.planners.cops.regions`); the view keeps the merges it has made (a
region only grows) and never merges the lattice's cell (0, 0, 0), the base's (the
backend centres it on the team's start), so the base location keeps its name. A
name the robot's map knows as a member of a region stands for that region
(:meth:`VoxelNetworkView.resolve`).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...planners.cops.extraction import (
    DEFAULT_CELL_M,
    DEFAULT_COMM_RANGE_M,
    DEFAULT_MIN_FREE_VOXELS,
    cell_name,
    lattice_cells,
    line_of_sight,
)
from ...planners.cops.extraction_incremental import ExtractionUpdater
from ...planners.cops.regions import DEFAULT_MAX_REGION_M, DEFAULT_OPEN_RADIUS_M, cell_of_name
from ...planners.cops.topology import Topology
from ...planners.navgraph import NavGraph
from ...planners.occupancy import FREE, Grid
from ..base import AgentContext
from ..navigation import Navigator, Plan
from ..robot import ChangeLog, Robot

#: Flying robots' standable voxels: the free voxels within this many voxels of a node
#: of the aerial graph (whose nodes lie on a lattice of every second voxel).
AERIAL_NODE_REACH_VOXELS = 1
#: A robot this near a location's position (m) has arrived there: a route ends at
#: the graph node nearest the position, within the navigator's snap radii.
ARRIVAL_RADIUS_M = 2.5
#: A partial route (towards a location the graph does not reach yet) must end at
#: least this much nearer the location than the robot is, metres.
MIN_PROGRESS_M = 1.0
#: Rounding allowance when counting how many voxels a legged robot's step spans (as
#: ``legged_graph`` counts it).
_STEP_TOLERANCE_VOXELS = 1e-9


class _MapClock:
    """A clock that never advances: a navigator on it rebuilds on every map change."""

    now_s = 0.0


class VoxelNetworkView:
    """The COPS network a robot's onboard map reveals (the ``NetworkView`` protocol).

    ``topology()`` is extracted again whenever the navigation graph has been rebuilt
    (the navigator rebuilds it when the map has changed) since the last call, from the
    voxels the map changed since the last extraction (the map's change log); the
    cells of the traversed path are marked explored on every call. Pass the agent's shared ``navigator``
    (:func:`delve.skills.navigation.navigator`) to plan on one graph per agent; by
    default the view keeps its own, rebuilt on every map change. Robots of one team
    share ``lattice_origin`` (see :func:`extract_topology`).
    """

    def __init__(self, robot: Robot, *, cell_m: float = DEFAULT_CELL_M,
                 comm_range_m: float = DEFAULT_COMM_RANGE_M, min_free_voxels: int = DEFAULT_MIN_FREE_VOXELS,
                 navigator: Navigator | None = None, lattice_origin: np.ndarray | None = None,
                 open_radius_m: float | None = DEFAULT_OPEN_RADIUS_M, max_region_m: float = DEFAULT_MAX_REGION_M):
        if not (isinstance(cell_m, (int, float)) and math.isfinite(cell_m) and cell_m > 0):
            raise ValueError(f"cell_m must be a positive finite number, got {cell_m!r}")
        self.robot = robot
        self.lattice_origin = np.zeros(3) if lattice_origin is None else np.asarray(lattice_origin, float)
        self.cell_m = float(cell_m)
        #: The base's cell, never merged into a region.
        self.base_cell = cell_name((0, 0, 0))
        self.navigator = navigator if navigator is not None else Navigator(
            robot, _own_context(robot), rebuild_period_s=0.0)
        self._graph: NavGraph | None = None
        self._topology = Topology()
        self._visited: set[str] = set()
        self._trail_seen = 0
        self.extractions = 0
        self._extractor = ExtractionUpdater(
            cell_m=self.cell_m, comm_range_m=float(comm_range_m), min_free_voxels=min_free_voxels,
            sight_height_m=self.sight_height_m(), lattice_origin=self.lattice_origin,
            open_radius_m=open_radius_m, max_region_m=max_region_m)
        #: The map the extractor follows and its change log.
        self._log: tuple[object, ChangeLog] | None = None
        #: The home's ground point and cell (fixed: a robot's home does not move).
        self._home = self.ground_points(np.asarray(robot.home, dtype=float)[None])[0]
        self._home_cell = self.cell_of(self._home[None])[0]

    # -- the NetworkView protocol ---------------------------------------------------------
    def topology(self) -> dict[str, Any]:
        """The plain-dict :class:`Topology` of the robot's map (a fresh dict each call)."""
        return self.current().to_dict()

    def location(self) -> str | None:
        """The location the robot has arrived at (the nearest whose :meth:`target` is
        within ``ARRIVAL_RADIUS_M``), else the one whose cell holds its ground point,
        else None. Arrival comes first because the body stands on the true ground and
        positions lie on map voxels: at a location's position on a slope, the ground
        point can fall into the cell below when a floor crosses a cell's boundary."""
        locations = self.current().locations
        ground = self.ground_point()
        if locations:
            names = list(locations)
            home = self.resolve(self._home_cell)
            targets = np.array([self._home if n == home else locations[n] for n in names], dtype=float)
            gaps = np.linalg.norm(targets - ground, axis=1)
            i = int(np.argmin(gaps))
            if gaps[i] <= ARRIVAL_RADIUS_M:
                return names[i]
        return self.resolve(self.cell_of(ground[None])[0])

    def resolve(self, name: str) -> str | None:
        """The location of the robot's map a name stands for: the name itself, or the
        region it was merged into; None when the map knows no such location."""
        topo = self.current()
        name = topo.resolve(name)
        return name if name in topo.locations else None

    def near(self, ground: np.ndarray) -> bool:
        """Whether the robot's ground point is within ``ARRIVAL_RADIUS_M`` of a point."""
        return float(np.linalg.norm(self.ground_point() - np.asarray(ground, dtype=float))) <= ARRIVAL_RADIUS_M

    def arrived(self, location: str) -> bool:
        """Whether the robot's ground point is within ``ARRIVAL_RADIUS_M`` of where it
        goes for the location (:meth:`target`)."""
        pos = self.target(location)
        return pos is not None and self.near(pos)

    def route(self, location: str) -> np.ndarray | None:
        """Waypoints (N, 3) along the navigation graph from the robot to the node nearest
        the location's position or, when the graph does not reach it yet, to the
        reachable node nearest it (if that is ``MIN_PROGRESS_M`` nearer than the robot),
        else, from outside the location, straight to it if the straight line crosses
        only known free space; None for an unknown location or when none of these is
        possible (inside the location: the robot is as near as it gets)."""
        pos = self.target(location)
        if pos is None:
            return None
        return self.route_towards(pos, straight=self.location() != self.resolve(location))

    def route_towards(self, ground: np.ndarray, straight: bool = True) -> np.ndarray | None:
        """As :meth:`route`, to a ground point (a location the team knows and this
        robot's map does not show yet: another robot explored it); ``straight``
        allows the straight route."""
        goal = np.asarray(ground, dtype=float) + [0.0, 0.0, self.sight_height_m()]
        plan, target = self._plan_towards(goal, force=False)
        if target is None and self.navigator.map_changed():
            plan, target = self._plan_towards(goal, force=True)
        if plan is None:
            return self._straight(goal) if straight else None
        if target is None:
            reachable = np.flatnonzero(np.isfinite(plan.distances))
            gap = np.linalg.norm(plan.graph.positions[reachable] - goal, axis=1)
            target = int(reachable[np.argmin(gap)])
            if gap.min() > np.linalg.norm(np.asarray(self.robot.position) - goal) - MIN_PROGRESS_M:
                return self._straight(goal) if straight else None
        return plan.path_to(target)

    def _straight(self, goal: np.ndarray) -> np.ndarray | None:
        """A straight route to ``goal`` (body height) where the straight line from the
        robot crosses only known-free voxels, else None: across an open yard the LiDAR
        sees the floor in rings far apart, and the graph may reach no nearer node."""
        start = np.asarray(self.robot.position, dtype=float)
        if not line_of_sight(self.navigator.grid(), start[None], goal[None])[0]:
            return None
        return np.stack([start, goal])

    def _plan_towards(self, goal: np.ndarray, force: bool) -> tuple[Plan | None, int | None]:
        """Shortest paths from the robot (on a graph rebuilt first if ``force``) and the
        node nearest ``goal`` if it is reachable."""
        plan = self.navigator.from_robot(force=force)
        if plan is None:
            return None, None
        target = self.navigator.node_near(plan.graph, goal)
        return plan, target if target is not None and np.isfinite(plan.distances[target]) else None

    def target(self, location: str) -> np.ndarray | None:
        """The ground point the robot goes to for a location (or a name merged into
        it): the location's position or, in the location of the robot's home, its
        home (so each robot of a team comes back to its own start pose); None for an
        unknown location."""
        name = self.resolve(location)
        if name is None:
            return None
        if name == self.resolve(self._home_cell):
            return self._home.copy()
        return np.asarray(self.current().locations[name], dtype=float)

    def cell_of(self, points: np.ndarray) -> list[str]:
        """The names of the lattice cells of ground points (N, 3)."""
        return [cell_name(c) for c in lattice_cells(points, self.cell_m, self.lattice_origin)]

    @property
    def revision(self) -> tuple[int, int]:
        """Changes whenever the topology may have: (extractions, visited cells)."""
        self.current()
        return self.extractions, len(self._visited)

    # -- helpers ----------------------------------------------------------------------------
    def current(self) -> Topology:
        """The cached :class:`Topology`, extracted again if the navigation graph was
        rebuilt, with the cells of the traversed path marked explored (the
        extraction merges only explored cells into regions)."""
        trail = self.robot.traversed_path
        if len(trail) > self._trail_seen:
            new = np.asarray(trail[self._trail_seen:], dtype=float).reshape(-1, 3)
            self._visited.update(self.cell_of(self.ground_points(new)))
            self._trail_seen = len(trail)
        graph = self.navigator.graph()
        if graph is not self._graph:
            grid = self.navigator.grid()
            self._topology = self._extractor.update(
                grid, self._changes(), standable=self.standable(grid, graph),
                visited=self._cell_centres(self._visited), prior=self._topology.merged,
                keep=(self.base_cell,))
            self._graph = graph
            self.extractions += 1
        visited = {self._topology.resolve(c) for c in self._visited}
        self._topology.explored |= visited & self._topology.locations.keys()
        return self._topology

    def _changes(self) -> np.ndarray | None:
        """The voxels the map changed since the last call; None the first time or for a
        new map object (the extractor then reads the whole map)."""
        m = self.robot.onboard_map
        if self._log is None or self._log[0] is not m:
            self._log = (m, m.change_log())
            return None
        return self._log[1].take()

    def _cell_centres(self, cells: set[str]) -> np.ndarray:
        """(N, 3) centres of lattice cells given by name."""
        idx = np.array([cell_of_name(c) for c in sorted(cells)], dtype=float).reshape(-1, 3)
        return self.lattice_origin + (idx + 0.5) * self.cell_m

    def standable(self, grid: Grid, graph: NavGraph) -> np.ndarray:
        """Flat indices (ascending) of the free voxels the robot stands on (legged) or
        flies through (aerial)."""
        mob = self.robot.mobility
        vox = grid.voxel_size_m
        if mob.aerial:
            nodes = grid.to_index(graph.positions)
            reach = range(-AERIAL_NODE_REACH_VOXELS, AERIAL_NODE_REACH_VOXELS + 1)
            offsets = [(a, b, c) for a in reach for b in reach for c in reach]
        else:
            nodes = grid.to_index(graph.positions - [0.0, 0.0, mob.body_height_m - 0.5 * vox])
            rise = max(1, math.floor(mob.max_step_m / vox + _STEP_TOLERANCE_VOXELS))
            offsets = [(0, 0, c) for c in range(rise)]
        idx = np.concatenate([nodes + d for d in offsets])
        flat = np.unique(np.ravel_multi_index(tuple(idx[grid.in_bounds(idx)].T), grid.shape))
        return flat[grid.occupancy.reshape(-1)[flat] == FREE]

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
