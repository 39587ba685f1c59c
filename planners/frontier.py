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

from .navgraph import FACES, NavGraph, Voxels
from .occupancy import FREE, UNKNOWN, Grid



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
    """The chosen cluster, the graph node to go to, the path length to it and the
    straight distance from that node to the nearest sampled voxel of the cluster."""

    cluster: FrontierCluster
    node: int
    path_length_m: float
    offset_m: float


def frontier_voxels(grid: Grid, among: np.ndarray | None = None, depth: int = 3) -> np.ndarray:
    """Flat indices of FREE voxels that border unknown space: all of them, or those of
    ``among`` (flat indices) that still do.

    A voxel borders unknown space when, along one of the six face directions, the next
    ``depth`` voxels are all UNKNOWN (and inside the grid). Requiring more than one
    unknown voxel ignores the small holes that sparse far-range LiDAR rays leave in
    otherwise observed space.
    """
    flat_occ = grid.occupancy.reshape(-1)
    flat = grid.free_voxels() if among is None else among[flat_occ[among] == FREE]

    free = Voxels(flat, grid.shape)
    is_frontier = np.zeros(len(free), dtype=bool)
    for d in FACES:
        solid = free.at(flat_occ, d, FREE) == UNKNOWN
        for k in range(2, depth + 1):
            idx = np.flatnonzero(solid)
            solid[idx] = free.subset(idx).at(flat_occ, (d[0] * k, d[1] * k, d[2] * k), FREE) == UNKNOWN
        is_frontier |= solid
    return flat[is_frontier]


def frontier_clusters(grid: Grid, voxels: np.ndarray, *, cluster_radius_m: float, min_cluster_voxels: int,
                      max_extent_m: float) -> list[FrontierCluster]:
    """Group frontier voxels into clusters of at most ``max_extent_m`` across.

    Voxels are first pooled into blocks of 2×2×2; blocks whose centres are closer
    than ``cluster_radius_m`` join; groups wider than ``max_extent_m`` are split on a
    grid of that size. Clusters smaller than ``min_cluster_voxels`` are dropped.
    Deterministic order.
    """
    if len(voxels) == 0:
        return []
    voxels = np.sort(voxels)
    ijk = np.stack(np.unravel_index(voxels, grid.shape), axis=1)
    b = ijk // 2
    nb = np.array(grid.shape) // 2 + 1
    packed, block_of = np.unique((b[:, 0] * nb[1] + b[:, 1]) * nb[2] + b[:, 2], return_inverse=True)
    blocks = np.stack(np.unravel_index(packed, tuple(nb)), axis=1)
    centres = grid.origin + (blocks * 2 + 1.0) * grid.voxel_size_m
    pairs = cKDTree(centres).query_pairs(cluster_radius_m, output_type="ndarray")
    adj = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(blocks), len(blocks)))
    _, component = connected_components(adj, directed=False)
    cell = np.floor((centres - grid.origin) / max_extent_m).astype(np.int64)
    span = cell.max(axis=0) + 1
    key = ((component * span[0] + cell[:, 0]) * span[1] + cell[:, 1]) * span[2] + cell[:, 2]
    _, block_label = np.unique(key, return_inverse=True)
    labels = block_label[block_of.reshape(-1)]
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(labels.max() + 2))
    pts = grid.to_world(ijk)
    clusters = []
    for c in range(labels.max() + 1):
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
    offset_weight: float = 2.0,
    samples_per_cluster: int = 16,
) -> FrontierGoal | None:

    """The cluster whose goal node is nearest along the graph (``distances`` from the robot).

    A cluster's goal is the reachable node that minimises path length plus
    ``offset_weight`` times its straight distance to the cluster, within
    ``max_goal_offset_m`` of it (a far goal approaches a frontier the map cannot reach
    yet; a weight above 1 makes the node nearest the frontier win over the robot's
    own). Clusters without such a node are skipped; the cheapest cluster is chosen.
    """
    reachable = np.flatnonzero(np.isfinite(distances))
    if len(reachable) == 0 or not clusters:
        return None
    # Up to ``samples_per_cluster`` voxels of each cluster, evenly spread, stand for it.
    picks = [c.voxels[:: max(1, c.size // samples_per_cluster)] for c in clusters]
    voxels = np.concatenate(picks)
    owner = np.repeat(np.arange(len(clusters)), [len(p) for p in picks])
    pts = grid.to_world(np.stack(np.unravel_index(voxels, grid.shape), axis=1))
    d, i = cKDTree(graph.positions[reachable]).query(pts, distance_upper_bound=max_goal_offset_m)
    ok = np.isfinite(d)
    if not ok.any():
        return None
    nodes = reachable[i[ok]]
    cost = distances[nodes] + offset_weight * d[ok]
    k = int(np.argmin(cost))
    return FrontierGoal(cluster=clusters[owner[ok][k]], node=int(nodes[k]), path_length_m=float(distances[nodes[k]]),
                        offset_m=float(d[ok][k]))

