"""Exploration skills."""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.frontier import (MAX_GOAL_OFFSET_M, FrontierCluster, FrontierGoal, frontier_clusters,
                                 frontier_voxels, nearest_frontier)
from ..planners.occupancy import Grid
from ..planners.geometry import xyz
from .base import Param, Skill
from .navigation import Plan, navigator
from .robot import PathStatus


class ExploreFrontiers(Skill):
    """Nearest-frontier exploration: go to the nearest reachable frontier cluster, repeat.

    Frontier voxels (known free next to unknown) of the onboard map are clustered; the
    cluster whose goal node is nearest along the navigation graph is chosen and the
    robot follows the path to it. Goals are chosen for the robot's LiDAR
    (:func:`~delve.planners.frontier.nearest_frontier`): from where the frontier lies
    within its view up (``view_up_deg``), so the unseen air under a roof is looked at
    from along the drift; a cluster it could see from no node it can reach now is no
    goal. A visit is judged on the voxels the goal sees (its targets): the voxels of a
    cluster whose targets are still a frontier after a visit, or whose path is blocked,
    are blacklisted: never goals again.

    Writes: ``frontier_goal`` (x, y, z of the current goal), ``frontiers_left`` (clusters).
    Returns: RUNNING while exploring; SUCCESS when no reachable frontier is left;
    FAILURE when the robot is not on its own navigation graph.
    """

    #: The YAML name says the planner; ``ExploreFrontiers`` is the name it had before.
    TYPE_NAME = "ExploreNearestFrontier"
    ALIASES: ClassVar[dict[str, dict[str, Any]]] = {"ExploreFrontiers": {}}
    PARAMS = {
        "cluster_radius_m": Param(float, 0.8, "frontier blocks (2×2×2 voxels) closer than this join", exclusive_minimum=0),
        "min_cluster_voxels": Param(int, 10, "smaller clusters are ignored", minimum=1),
        "max_cluster_extent_m": Param(float, 4.0, "larger clusters are split", exclusive_minimum=0),
        "max_goal_offset_m": Param(float, MAX_GOAL_OFFSET_M, "a goal node is at most this far from its cluster",
                                   exclusive_minimum=0),
        "observe_radius_m": Param(float, 3.0, "a frontier this near that stays one is unobservable",
                                  exclusive_minimum=0),
        "check_period_s": Param(
float, 2.0, "how often the target cluster is re-checked", exclusive_minimum=0),
        "dwell_s": Param(float, 1.0, "time to scan at a goal before judging it", minimum=0),
        "explored_fraction": Param(float, 0.8, "a cluster this much explored is left", exclusive_minimum=0, maximum=1),
    }
    OUTPUT_PORTS = {
        "frontier_goal": PortInformation(list, description="[x, y, z] of the current goal (m)"),
        "frontiers_left": PortInformation(int, description="frontier clusters found at the last plan"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.blacklist = np.zeros(0, dtype=np.int64)
        self.goal: FrontierGoal | None = None
        self.arrived_s: float | None = None
        self.checked_s = 0.0

    def initialise(self) -> None:
        self.goal, self.arrived_s = None, None

    def update(self) -> Status:
        if self.goal is not None and not self._goal_done():
            return Status.RUNNING
        return self._plan()

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.ctx.robot is not None:
            self.stop_own_motion()
        self.goal = None

    def _remaining(self) -> int:
        """How many of the goal's targets are frontier voxels still."""
        m = self.robot.onboard_map   # the occupancy alone: no list of free voxels brought up to date
        return len(frontier_voxels(Grid(m.occupancy, m.origin, m.voxel_size_m), among=self.goal.targets))

    def _goal_done(self) -> bool:
        """Whether to plan again: goal reached and scanned, blocked, or explored meanwhile."""
        now, status, goal = self.ctx.clock.now_s, self.robot.path_status, self.goal
        assert goal is not None
        if status == PathStatus.FOLLOWING:
            if now - self.checked_s < self.p["check_period_s"]:
                return False
            self.checked_s = now
            if self._remaining() <= (1 - self.p["explored_fraction"]) * len(goal.targets):
                self.stop_own_motion()
                return True
            return False
        if status == PathStatus.ARRIVED:
            if self.arrived_s is None:
                self.arrived_s = now
            if now - self.arrived_s < self.p["dwell_s"]:
                return False
            if self._remaining() > (1 - self.p["explored_fraction"]) * len(goal.targets):
                self._blacklist("still a frontier after a visit")
            return True
        if status == PathStatus.BLOCKED:
            self._blacklist(f"path blocked: {self.robot.blocked_reason}")
        return True

    def _blacklist(self, reason: str) -> None:
        assert self.goal is not None
        self.blacklist = np.union1d(self.blacklist, self.goal.cluster.voxels)
        self.event("frontier_blacklisted", at=xyz(self.goal.cluster.centroid), reason=reason)

    def _plan(self) -> Status:
        self.goal, self.arrived_s = None, None
        nav = navigator(self.ctx, self.robot)
        grid = nav.grid()
        candidates = nav.frontier_voxels()  # incremental, equal to frontier_voxels(grid)
        candidates = candidates[~_sorted_contains(self.blacklist, candidates)]
        # First on the cached navigation graph; if that ends at the robot, on a fresh one.
        for fresh in (False, True):
            plan = nav.from_robot(force=fresh)
            if plan is None:
                self.feedback_message = "robot is not on its navigation graph"
                self.event("explore_failed", reason=self.feedback_message)
                return Status.FAILURE
            clusters = self._clusters(grid, plan, candidates)
            self.write("frontiers_left", len(clusters))
            goal = self._choose(grid, plan, clusters)
            if goal is not None:
                break
        else:
            self.feedback_message = "no reachable frontier left"
            self.event("exploration_complete", blacklisted_voxels=len(self.blacklist))
            return Status.SUCCESS
        self.goal, self.checked_s = goal, self.ctx.clock.now_s
        self.follow(plan.path_to(goal.node))
        self.write("frontier_goal", xyz(plan.graph.positions[goal.node]))
        self.feedback_message = f"to frontier {goal.path_length_m:.1f} m away"
        self.event("frontier_goal", at=xyz(goal.cluster.centroid), path_length_m=round(goal.path_length_m, 2),
                   clusters=len(clusters))
        return Status.RUNNING

    def _clusters(self, grid: Grid, plan: Plan, candidates: np.ndarray) -> list[FrontierCluster]:
        """Clusters of the ``candidates`` (frontier voxels)."""
        return frontier_clusters(grid, candidates, cluster_radius_m=self.p["cluster_radius_m"],
                                 min_cluster_voxels=self.p["min_cluster_voxels"],
                                 max_extent_m=self.p["max_cluster_extent_m"])

    def _choose(self, grid: Grid, plan: Plan, clusters: list[FrontierCluster]) -> FrontierGoal | None:
        """The nearest frontier whose goal is not where the robot already stands, its
        goal chosen for the LiDAR's view (:func:`nearest_frontier`)."""

        def elsewhere(goal: FrontierGoal) -> bool:
            if goal.node != plan.source:
                return True
            if goal.offset_m <= self.p["observe_radius_m"]:
                # The robot stands next to the frontier and still sees it: it never will.
                self.goal = goal
                self._blacklist("unobservable from its goal")
            # Otherwise the graph does not reach any nearer: skip it on this graph.
            return False

        return nearest_frontier(plan.graph, plan.distances, clusters, grid,
                                max_goal_offset_m=self.p["max_goal_offset_m"], view_up_deg=self.robot.view_up_deg,
                                min_targets=self.p["min_cluster_voxels"], accept=elsewhere)


def _sorted_contains(sorted_values: np.ndarray, query: np.ndarray) -> np.ndarray:
    """Whether each of ``query`` is in ``sorted_values`` (ascending): ``np.isin`` by binary
    search, without sorting the frontier voxels again at every plan."""
    if len(sorted_values) == 0:
        return np.zeros(len(query), dtype=bool)
    at = np.minimum(np.searchsorted(sorted_values, query), len(sorted_values) - 1)
    return sorted_values[at] == query


__all__ = ["ExploreFrontiers"]
