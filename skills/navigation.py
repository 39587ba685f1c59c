"""Path planning on the onboard map, shared by the skills of one robot.

The :class:`Navigator` keeps the navigation graph of the robot's onboard map and the
shortest-path tree from the robot, and rebuilds them when the map has changed and
they are older than ``rebuild_period_s`` (10 s) of sim time, so that several skills ticking
in one agent do not plan twice. The graph (legged or aerial) is updated from the voxels that
changed since the last build (the map's change log), not rebuilt over the whole map, and
so is the map's set of frontier voxels (:meth:`Navigator.frontier_voxels`).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..planners.frontier_incremental import FrontierUpdater
from ..planners.navgraph import NavGraph
from ..planners.navgraph_incremental import AerialGraphUpdater, LeggedGraphUpdater
from ..planners.occupancy import Grid
from .base import AgentContext
from .robot import ChangeLog, Robot


@dataclass(frozen=True)
class Plan:
    """The graph, the robot's node on it and the shortest-path tree from there."""

    graph: NavGraph
    source: int
    distances: np.ndarray
    predecessors: np.ndarray

    def path_to(self, node: int) -> np.ndarray:
        return self.graph.path(self.predecessors, node)


class Navigator:
    """Navigation graph and shortest paths from the robot, cached per map version."""

    snap_radii_m = (1.0, 2.0)

    def __init__(self, robot: Robot, ctx: AgentContext, rebuild_period_s: float = 10.0):
        self.robot = robot
        self.ctx = ctx
        self.rebuild_period_s = rebuild_period_s
        self._graph: NavGraph | None = None
        self._graph_key: tuple[int, float] | None = None
        self._plan: Plan | None = None
        self._plan_key: tuple[int, int] | None = None
        self.builds = 0
        #: Incremental results by name: (the map, its change log, the updater).
        self._updaters: dict[str, tuple[object, ChangeLog, Any]] = {}

    def grid(self) -> Grid:
        m = self.robot.onboard_map
        return Grid(m.occupancy, m.origin, m.voxel_size_m, m.free_voxels)


    def graph(self, force: bool = False) -> NavGraph:
        """The navigation graph of the current map (possibly ``rebuild_period_s`` old)."""
        version, now = self.robot.onboard_map.version, self.ctx.clock.now_s
        stale = self._graph_key is None or (
            version != self._graph_key[0] and now - self._graph_key[1] >= self.rebuild_period_s
        )
        if force or stale or self._graph is None:
            mob = self.robot.mobility
            if mob.aerial:
                self._graph = self.updated("aerial graph", lambda: AerialGraphUpdater(radius_m=mob.radius_m))
            else:
                self._graph = self._legged_graph()
            self._graph_key = (version, now)
            self.builds += 1
        return self._graph

    def _legged_graph(self) -> NavGraph:
        """The legged graph of the current map, updated from the voxels changed since the
        last build (built over the whole map the first time, or for a new map object)."""
        mob = self.robot.mobility
        return self.updated("legged graph", lambda: LeggedGraphUpdater(
            body_height_m=mob.body_height_m, radius_m=mob.radius_m, max_step_m=mob.max_step_m,
            max_inclination_deg=mob.max_inclination_deg))

    def frontier_voxels(self) -> np.ndarray:
        """The frontier voxels of the current map (:func:`delve.planners.frontier.frontier_voxels`
        of :meth:`grid`, in its order), updated from the voxels changed since the last call."""
        return self.updated("frontier voxels", FrontierUpdater)

    def updated(self, name: str, make: Callable[[], Any]) -> Any:
        """``update`` of the incremental result ``name`` of the current map: from the voxels
        in the map's change log since the last call, or, the first time or for a new map
        object, from the whole map (with ``make()`` a new updater)."""
        m = self.robot.onboard_map
        kept = self._updaters.get(name)
        if kept is None or kept[0] is not m:
            kept = self._updaters[name] = (m, m.change_log(), make())
            return kept[2].update(self.grid())
        return kept[2].update(self.grid(), kept[1].take())

    def map_changed(self) -> bool:
        """Whether the map has changed since the graph was built (a forced rebuild would differ)."""
        return self._graph_key is None or self._graph_key[0] != self.robot.onboard_map.version

    def node_near(self, graph: NavGraph, point: np.ndarray) -> int | None:
        """The graph node nearest to ``point`` within the snap radii, or None."""
        for r in self.snap_radii_m:
            node = graph.nearest(point, r)
            if node is not None:
                return node
        return None

    def from_robot(self, force: bool = False) -> Plan | None:
        """Shortest paths from the robot's position; None when it is off the graph
        (after rebuilding the graph once, in case the robot walked off an old one)."""
        graph = self.graph(force)
        source = self.node_near(graph, self.robot.position)
        if source is None and not force:
            graph = self.graph(force=True)
            source = self.node_near(graph, self.robot.position)

        if source is None:
            return None
        key = (id(graph), source)
        if self._plan is None or self._plan_key != key:
            dist, pred = graph.shortest_paths(source)
            self._plan, self._plan_key = Plan(graph, source, dist, pred), key
        return self._plan

    def path_to_point(self, point: np.ndarray, force: bool = False) -> tuple[np.ndarray | None, float]:
        """Path from the robot to the node nearest ``point`` and its length (inf if none).

        ``force`` rebuilds the graph from the current map first."""
        plan = self.from_robot(force=force)
        if plan is None:
            return None, float("inf")
        target = self.node_near(plan.graph, point)
        if target is None or not np.isfinite(plan.distances[target]):
            return None, float("inf")
        return plan.path_to(target), float(plan.distances[target])


def navigator(ctx: AgentContext, robot: Robot) -> Navigator:
    """The agent's shared :class:`Navigator`, created on first use."""
    nav = ctx.services.get("navigator")
    if nav is None:
        nav = ctx.services["navigator"] = Navigator(robot, ctx)
    return nav
