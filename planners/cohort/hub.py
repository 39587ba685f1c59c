"""The COHORT hub's state: the common map, every submap's frontier points, G_C, the
current frontier clusters and what it told each robot (Kulkarni et al. 2022, IV-B).

One :class:`CohortHub` lives on the base station (``skills/cohort/hub.py`` keeps it in
``ctx.services["cohort_hub"]``); its three steps are the hub behaviours': a submap
arrives (:meth:`CohortHub.add_submap`), the global frontiers are recomputed
(:meth:`CohortHub.update_frontiers`, only after a new submap), a robot asks where to
go (:meth:`CohortHub.reposition`). Pure: no radio, no clock; the fine base map is
passed in as a :class:`~delve.planners.occupancy.Grid` (its live arrays).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..frontier import FrontierCluster
from ..occupancy import FREE, Grid
from .common_map import CommonMap, align_submap
from .frontiers import GlobalFrontiers, cluster_frontiers, map_frontier, submap_frontier
from .global_graph import GlobalGraph, submap_rng
from .params import CohortParams
from .reposition import Reposition, choose_frontier

#: The entry of home among the Dijkstra sources.
HOME = "home"


@dataclass(frozen=True)
class SubmapInfo:
    """What the hub keeps of a submap: who sent it, when, its visited voxels' box at
    r_C (world corners), how many fine voxels it carried, its frontier points and
    G_C vertices at arrival."""

    robot: str
    index: int
    t_s: float
    bbox_min: np.ndarray
    bbox_max: np.ndarray
    voxels: int
    frontier_points: int
    vertices: int


@dataclass(frozen=True)
class AssignmentRecord:
    """One answer the hub gave: to whom, when, the target, box and cluster points."""

    robot: str
    t_s: float
    request_id: int
    result: Reposition
    points: np.ndarray


class CohortHub:
    """The hub's state.

    Attributes others read: ``params``; ``common`` (:class:`CommonMap`, r_C);
    ``frontiers`` (:class:`GlobalFrontiers`); ``graph`` (:class:`GlobalGraph`, G_C);
    ``clusters`` (the current :class:`FrontierCluster` list, largest first) and
    ``links`` (their G_C vertices); ``submaps`` ((robot, index) -> :class:`SubmapInfo`);
    ``robot_positions`` (last known, from submaps and requests) and ``last_heard_s``
    (when they were true); ``home``;
    ``assignments`` (every :class:`AssignmentRecord`, oldest first) and
    ``last_assignment`` (robot -> its latest); ``stale`` (a submap arrived since the
    frontiers were last computed).
    """

    def __init__(self, params: CohortParams, fine: Grid, home: np.ndarray | None = None) -> None:
        self.params = params
        self.common = CommonMap(fine.shape, fine.origin, fine.voxel_size_m, params.resolution_m)
        self.frontiers = GlobalFrontiers()
        self.graph = GlobalGraph()
        self.clusters: list[FrontierCluster] = []
        self.links: list[np.ndarray] = []
        self.submaps: dict[tuple[str, int], SubmapInfo] = {}
        self.robot_positions: dict[str, np.ndarray] = {}
        self.last_heard_s: dict[str, float] = {}
        self.home = None if home is None else np.asarray(home, float)
        self.assignments: list[AssignmentRecord] = []
        self.last_assignment: dict[str, AssignmentRecord] = {}
        self.stale = False

    @property
    def frontier_centroids(self) -> np.ndarray:
        """(n, 3) centroids of the current clusters (for the map)."""
        return np.array([c.centroid for c in self.clusters]).reshape(-1, 3)

    def add_submap(self, fine: Grid, robot: str, index: int, t_s: float, flat: np.ndarray, values: np.ndarray,
                   trajectory: np.ndarray) -> SubmapInfo:
        """Place a submap in the common map, find its frontier points, add its subgraph.

        ``fine``: the base map *after* the submap was merged into it (the common map
        takes the merged values of the submap's voxels); ``flat``, ``values``: the
        submap's fine voxels; ``trajectory``: (k, 3) robot positions in it.
        """
        flat, values = align_submap(np.asarray(flat, np.int64), np.asarray(values, np.int8))
        trajectory = np.asarray(trajectory, float).reshape(-1, 3)
        self.common.merge(flat, fine.occupancy.reshape(-1)[flat])
        blocks, pooled = self.common.pool(flat, values)
        points = submap_frontier(self.common, blocks, pooled, trajectory)
        key = (robot, int(index))
        self.frontiers.add(key, points)
        visited = blocks[pooled == FREE]
        ids = self.graph.add_submap(key, fine, self.common, visited, trajectory, self.params.n_vertices,
                                    self.params.edge_radius_m, submap_rng(robot, int(index)))
        if len(visited):
            corners = self.common.centres(visited)
            half = 0.5 * self.common.voxel_size_m
            lo, hi = corners.min(axis=0) - half, corners.max(axis=0) + half
        else:
            lo = hi = np.full(3, np.nan)
        info = SubmapInfo(robot, int(index), float(t_s), lo, hi, len(flat), len(points), len(ids))
        self.submaps[key] = info
        if len(trajectory):
            self.robot_positions[robot] = trajectory[-1].copy()
            self.last_heard_s[robot] = max(self.last_heard_s.get(robot, -np.inf), float(t_s))
            if self.home is None:
                self.home = trajectory[0].copy()
        self.stale = True
        return info

    def update_frontiers(self) -> int:
        """Re-check every frontier point against the common map, re-cluster, drop
        clusters under f_min and link the rest to G_C; returns the points deleted."""
        dropped = self.frontiers.recheck(self.common)
        self.clusters = cluster_frontiers(self.common, self.frontiers.all_points(), self.params.f_min)
        self.links = self.graph.link_frontiers(self.clusters, self.common, self.params.edge_radius_m)
        self.stale = False
        return dropped

    def reposition(self, fine: Grid, robot: str, position: np.ndarray, t_s: float,
                   request_id: int = 0) -> Reposition:
        """Answer ``robot``'s call from ``position``: :func:`choose_frontier` with every
        robot's last known position and home as Dijkstra sources, the clusters that
        share points with another robot's latest assignment while it holds (T_C + T_C^e
        after it was given: a robot that has not called again by then has gone home or
        lost its way back) as held by it, and the other robots holding none that the
        hub heard from (a submap made or a call) in that time as free, but for those
        it answered without a frontier less than T_C before (:meth:`told_none`).
        Recomputes the frontiers first when a submap arrived since. When the common
        map has no frontier point left at all (:attr:`explored`) the answer is reason
        ``explored``. The answer is recorded."""
        if self.stale:
            self.update_frontiers()
        self.robot_positions[robot] = np.asarray(position, float).copy()
        self.last_heard_s[robot] = float(t_s)
        result = Reposition(None, reason="explored") if self.explored else self._choose(fine, robot, t_s)
        points = self.clusters[result.cluster].voxels if result.ok else np.zeros(0, dtype=np.int64)
        record = AssignmentRecord(robot, float(t_s), int(request_id), result, points)
        self.assignments.append(record)
        self.last_assignment[robot] = record
        return result

    def _choose(self, fine: Grid, robot: str, t_s: float) -> Reposition:
        """:func:`choose_frontier` for ``robot`` with the sources, holders and free robots
        that :meth:`reposition` describes."""
        radius = self.params.edge_radius_m
        sources = dict(sorted(self.robot_positions.items()))
        if self.home is not None:
            sources[HOME] = self.home
        entries = {name: self.graph.attach(p, fine, self.common, radius) for name, p in sources.items()}
        holders = self.holders(robot, t_s)
        busy = set().union(*holders.values()) if holders else set()
        hold = self.params.period_s + self.params.extra_explore_s
        free = [n for n, heard in sorted(self.last_heard_s.items())
                if n not in (robot, HOME) and n not in busy and t_s - heard <= hold
                and not self.told_none(n, t_s)]
        lo, hi = self.common.bounds
        return choose_frontier(self.graph, self.clusters, self.links, entries, robot,
                               best_share_pct=self.params.best_share_pct, box_m=self.params.box_m,
                               world_min=lo, world_max=hi, holders=holders, free=free)

    @property
    def explored(self) -> bool:
        """Whether the common map is closed: submaps came, not one frontier point (of
        any cluster size) is left, and the whole map confirms it (:func:`map_frontier`:
        the submaps' search from the trajectory, and the re-check, may have dropped a
        point of an opening for good). Whatever a robot still out of reach finds joins
        the map through ground the team's submaps showed open, so a closed common map
        is the team's whole world. (Frontiers under f_min keep it open.)"""
        return (bool(self.submaps) and not len(self.frontiers.all_points())
                and not len(map_frontier(self.common)))

    def told_none(self, robot: str, t_s: float) -> bool:
        """Whether ``robot``'s latest answer, given less than T_C before ``t_s``, had no
        frontier: it explores on with its own GBPlanner2 and calls again only T_C after
        that answer, so it is not waiting for a cluster now. (Counted as free, two robots
        that call in turn could each be told none in favour of the other, as both
        robots' positions change with their calls, and the cluster would go to neither.)"""
        rec = self.last_assignment.get(robot)
        return rec is not None and not rec.result.ok and t_s - rec.t_s < self.params.period_s

    def holders(self, robot: str, t_s: float) -> dict[int, set[str]]:
        """Per current cluster (index), the robots other than ``robot`` whose latest
        assignment, given at most T_C + T_C^e before ``t_s``, shares points with it."""
        hold = self.params.period_s + self.params.extra_explore_s
        live = {other: rec.points for other, rec in sorted(self.last_assignment.items())
                if other != robot and t_s - rec.t_s <= hold and len(rec.points)}
        out: dict[int, set[str]] = {}
        for i, c in enumerate(self.clusters):
            names = {o for o, pts in live.items() if len(np.intersect1d(c.voxels, pts, assume_unique=True))}
            if names:
                out[i] = names
        return out
