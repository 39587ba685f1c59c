"""Nearest-frontier exploration, the baseline that GBPlanner2 is compared against.

Frontier voxels are known-free voxels next to unknown ones. They are clustered, each
cluster gets the navigation node nearest to it as its goal, and the cluster whose
goal is nearest along the navigation graph is chosen. Clusters whose goal failed
(unreachable, or still a frontier after a visit) are blacklisted by the caller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .navgraph import NavGraph, neighbour_values
from .occupancy import FREE, UNKNOWN, Grid

_FACES = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))


@dataclass(frozen=True)
class FrontierCluster:
    """A connected set of frontier voxels: their flat indices and world centroid."""

    voxels: np.ndarray
    centroid: np.ndarray

    @property
    def size(self) -> int:
        return len(self.voxels)


@dataclass(frozen=True)
class FrontierGoal:
    """The chosen cluster, the graph node to go to and the path length to it."""

    cluster: FrontierCluster
    node: int
    path_length_m: float


def frontier_voxels(grid: Grid, among: np.ndarray | None = None) -> np.ndarray:
    """Flat indices of FREE voxels with at least one UNKNOWN face neighbour inside the
    grid: all of them, or those of ``among`` (flat indices) that still are."""
    flat_occ = grid.occupancy.reshape(-1)
    free = np.flatnonzero(flat_occ == FREE) if among is None else among[flat_occ[among] == FREE]
    ijk = np.stack(np.unravel_index(free, grid.shape), axis=1)
    is_frontier = np.zeros(len(free), dtype=bool)
    for d in _FACES:
        is_frontier |= neighbour_values(flat_occ, free, ijk, d, grid.shape, FREE) == UNKNOWN
    return free[is_frontier]


def frontier_clusters(
    grid: Grid, voxels: np.ndarray, *, cluster_radius_m: float, min_cluster_voxels: int
) -> list[FrontierCluster]:
    """Group frontier voxels closer than ``cluster_radius_m``; drop clusters smaller than
    ``min_cluster_voxels``. Clusters are ordered by their smallest voxel index."""
    if len(voxels) == 0:
        return []
    pts = grid.to_world(np.stack(np.unravel_index(voxels, grid.shape), axis=1))
    pairs = cKDTree(pts).query_pairs(cluster_radius_m, output_type="ndarray")

    adj = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(pts), len(pts)))
    n, labels = connected_components(adj, directed=False)
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(n + 1))
    clusters = []
    for c in range(n):
        members = order[bounds[c] : bounds[c + 1]]
        if len(members) >= min_cluster_voxels:
            clusters.append(FrontierCluster(voxels=voxels[members], centroid=pts[members].mean(axis=0)))
    return clusters


def nearest_frontier(
    graph: NavGraph,
    distances: np.ndarray,
    clusters: list[FrontierCluster],
    grid: Grid,
    *,
    max_goal_offset_m: float,
) -> FrontierGoal | None:
    """The cluster whose goal node is nearest along the graph (``distances`` from the robot).

    A cluster's goal is the reachable node nearest to any of its voxels, within
    ``max_goal_offset_m``; clusters without one are unreachable and skipped.
    """
    reachable = np.flatnonzero(np.isfinite(distances))
    if len(reachable) == 0:
        return None
    tree = cKDTree(graph.positions[reachable])
    best: FrontierGoal | None = None
    for cluster in clusters:
        pts = grid.to_world(np.stack(np.unravel_index(cluster.voxels, grid.shape), axis=1))
        d, i = tree.query(pts, distance_upper_bound=max_goal_offset_m)
        ok = np.isfinite(d)
        if not ok.any():
            continue
        nodes = reachable[i[ok]]
        k = int(np.argmin(distances[nodes] + d[ok]))
        node = int(nodes[k])
        if best is None or distances[node] < best.path_length_m:
            best = FrontierGoal(cluster=cluster, node=node, path_length_m=float(distances[node]))
    return best
