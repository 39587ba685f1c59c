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
    straight distance from that node to the cluster's centroid."""

    cluster: FrontierCluster
    node: int
    path_length_m: float
    offset_m: float


#: Unknown voxels in a row beyond a free voxel that make it a frontier.
FRONTIER_DEPTH = 3


def frontier_voxels(grid: Grid, among: np.ndarray | None = None, depth: int = FRONTIER_DEPTH) -> np.ndarray:
    """Flat indices of FREE voxels that border unknown space: all of them, or those of
    ``among`` (flat indices) that still do.

    A voxel borders unknown space when, along one of the six face directions, the next
    ``depth`` voxels are all UNKNOWN (and inside the grid). Requiring more than one
    unknown voxel ignores the small holes that sparse far-range LiDAR rays leave in
    otherwise observed space.
    """
    flat_occ = grid.occupancy.reshape(-1)
    free = Voxels.free_of(grid) if among is None else Voxels(among[flat_occ[among] == FREE], grid.shape)
    is_frontier = np.zeros(len(free), dtype=bool)
    for d in FACES:
        solid = free.at(flat_occ, d, FREE) == UNKNOWN
        for k in range(2, depth + 1):
            idx = np.flatnonzero(solid)
            solid[idx] = free.at(flat_occ, (d[0] * k, d[1] * k, d[2] * k), FREE, idx) == UNKNOWN
        is_frontier |= solid
    return free.flat[is_frontier]


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
    *,
    max_goal_offset_m: float,
    view_up_deg: float = 90.0,
    sensor_height_m: float = 0.0,
    offset_weight: float = 2.0,
    node_spacing_m: float = 0.6,
) -> FrontierGoal | None:
    """The cluster whose goal node is cheapest: path length from the robot
    (``distances``) plus ``offset_weight`` times the straight distance to the cluster.

    A goal node must lie within ``max_goal_offset_m`` of the cluster's centroid and
    see it: the centroid may be at most ``view_up_deg`` above the sensor
    (``sensor_height_m`` above the node), so a ceiling frontier is approached from
    where a LiDAR with a narrow vertical field of view can see it, not from below. A
    far goal approaches a frontier the map cannot reach yet; a weight above 1 makes
    the node nearest the frontier win over the robot's own. Candidate nodes are
    thinned to one per ``node_spacing_m`` cell. None when no cluster has a goal.
    """
    reachable = np.flatnonzero(np.isfinite(distances))
    if len(reachable) == 0 or not clusters:
        return None
    cell = np.floor(graph.positions[reachable] / node_spacing_m).astype(np.int64)
    cell -= cell.min(axis=0)
    span = cell.max(axis=0) + 1
    _, first = np.unique((cell[:, 0] * span[1] + cell[:, 1]) * span[2] + cell[:, 2], return_index=True)
    nodes = reachable[np.sort(first)]
    centroids = np.array([c.centroid for c in clusters])
    near = cKDTree(graph.positions[nodes]).query_ball_point(centroids, max_goal_offset_m)
    owner = np.repeat(np.arange(len(clusters)), [len(n) for n in near])
    if len(owner) == 0:
        return None
    cand = nodes[np.concatenate([np.asarray(n, dtype=np.int64) for n in near])]
    diff = centroids[owner] - graph.positions[cand]
    offset = np.linalg.norm(diff, axis=1)
    level = np.hypot(diff[:, 0], diff[:, 1])
    seen = diff[:, 2] - sensor_height_m <= level * np.tan(np.radians(min(view_up_deg, 89.9))) + 0.5 * node_spacing_m
    cost = np.where(seen, distances[cand] + offset_weight * offset, np.inf)
    k = int(np.argmin(cost))
    if not np.isfinite(cost[k]):
        return None
    node = int(cand[k])
    return FrontierGoal(cluster=clusters[owner[k]], node=node, path_length_m=float(distances[node]),
                        offset_m=float(offset[k]))

