"""Nearest-frontier exploration, the baseline that GBPlanner2 is compared against.

Frontier voxels are known-free voxels next to unknown ones. They are clustered, each
cluster gets as its goal the navigation node nearest to it from which the robot's
sensor observes it (issue 16 item 7: a LiDAR with a narrow vertical view sees the
unseen air under a drift's roof only from afar), and the cluster whose goal is nearest
along the navigation graph is chosen. Clusters whose goal failed (unreachable, or
still a frontier after a visit) are blacklisted by the caller.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .navgraph import FACES, NavGraph, Voxels, _Lookup
from .occupancy import FREE, OCCUPIED, UNKNOWN, Grid


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
    """The chosen cluster, the graph node to go to, the path length to it, the
    straight distance from that node to the cluster's centroid, and ``targets``: the
    cluster's voxels (flat indices) the sensor can observe from that node, on which a
    visit is judged."""

    cluster: FrontierCluster
    node: int
    path_length_m: float
    offset_m: float
    targets: np.ndarray


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
    return free.flat[_unknown_faces(flat_occ, free, depth).any(axis=1)]


def _unknown_faces(flat_occ: np.ndarray, voxels: Voxels, depth: int) -> np.ndarray:
    """(N, 6) whether the next ``depth`` voxels along each of :data:`FACES` are UNKNOWN."""
    out = np.zeros((len(voxels), len(FACES)), dtype=bool)
    for j, d in enumerate(FACES):
        solid = voxels.at(flat_occ, d, FREE) == UNKNOWN
        for k in range(2, depth + 1):
            idx = np.flatnonzero(solid)
            solid[idx] = voxels.at(flat_occ, (d[0] * k, d[1] * k, d[2] * k), FREE, idx) == UNKNOWN
        out[:, j] = solid
    return out


#: Viewpoints that may observe a frontier, and goal candidates, are one node per cell
#: of this size (m).
VIEWPOINT_SPACING_M = 1.2
#: A goal node, and a viewpoint that counts, is at most this far from its frontier (m).
MAX_GOAL_OFFSET_M = 12.0


#: Cells (of the bounding box of the nodes) up to which viewpoint_nodes finds each one's
#: first node with a table rather than by sorting.
_MAX_CELL_TABLE = 1 << 26


def viewpoint_nodes(graph: NavGraph, distances: np.ndarray,
                    spacing_m: float = VIEWPOINT_SPACING_M) -> np.ndarray:
    """The nodes reachable from the robot (finite ``distances``), thinned to the first of
    each ``spacing_m`` cell (ascending, deterministic)."""
    reachable = np.flatnonzero(np.isfinite(distances))
    if len(reachable) == 0:
        return reachable
    key = np.zeros(len(reachable), dtype=np.int64)
    for a in range(3):   # one contiguous coordinate at a time
        cell = np.floor(graph.positions[reachable, a] / spacing_m).astype(np.int64)
        cell -= cell.min()
        key = key * (int(cell.max()) + 1) + cell
    if key.max() >= _MAX_CELL_TABLE:
        _, first = np.unique(key, return_index=True)
        return reachable[np.sort(first)]
    # The first node of each cell: written last in a reversed scatter (as navgraph.distinct).
    first = np.empty(int(key.max()) + 1, dtype=np.int32)
    at = np.arange(len(key), dtype=np.int32)
    first[key[::-1]] = at[::-1]
    return reachable[first[key] == at]


def in_view(sensor: np.ndarray, points: np.ndarray, view_up_deg: float, slack_m: float) -> np.ndarray:
    """Whether each point is at most ``view_up_deg`` above the horizontal seen from its
    ``sensor`` (rows pair up), give or take ``slack_m`` of height."""
    diff = points - sensor
    level = np.hypot(diff[:, 0], diff[:, 1])
    return diff[:, 2] <= level * np.tan(np.radians(min(view_up_deg, 89.9))) + slack_m


#: A LiDAR ray that meets a wall of unknown space at more than this angle from its
#: normal glances off it: a frontier on the side of a drift is seen from in front.
MAX_INCIDENCE_DEG = 60.0


def view_targets(grid: Grid, voxels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What a sensor must see to observe each frontier voxel (flat indices): (N, 3)
    points and (N, 3) unit normals. Where the unknown run lies above the voxel (the
    unseen air under a roof, which a LiDAR with a narrow vertical view sees only from
    afar), the point one voxel higher and no normal (zero); else the voxel's centre and
    the horizontal face direction it borders unknown space on (zero if only below)."""
    faces = _unknown_faces(grid.occupancy.reshape(-1), Voxels(voxels, grid.shape), FRONTIER_DEPTH)
    up, side = faces[:, FACES.index((0, 0, 1))], faces[:, :4]
    pts = grid.to_world(np.stack(np.unravel_index(voxels, grid.shape), axis=1))
    pts[up, 2] += grid.voxel_size_m
    side_face = np.array(FACES[:4], float)[np.argmax(side, axis=1)]
    normal = np.where((~up & side.any(axis=1))[:, None], side_face, 0.0)
    return pts, normal


def observes(sensor: np.ndarray, points: np.ndarray, normals: np.ndarray, view_up_deg: float, reach_m: float,
             slack_m: float) -> np.ndarray:
    """Whether a sensor at ``sensor`` sees each view target (:func:`view_targets`;
    rows pair up, or broadcast): within ``reach_m``, at most ``view_up_deg`` above its
    horizontal (:func:`in_view`, give or take ``slack_m``) and, where the target has a
    normal, at most :data:`MAX_INCIDENCE_DEG` from it. Lines of sight are not checked."""
    diff = points - sensor
    level = np.hypot(diff[..., 0], diff[..., 1])
    dist = np.hypot(level, diff[..., 2])
    has_normal = np.abs(normals).sum(axis=-1)
    cos_max = np.cos(np.radians(MAX_INCIDENCE_DEG))
    facing = np.einsum("...i,...i->...", diff, normals) >= cos_max * dist * has_normal
    below_top = diff[..., 2] <= level * np.tan(np.radians(min(view_up_deg, 89.9))) + slack_m
    return (dist <= reach_m) & facing & below_top


def observes_samples(sensors: np.ndarray, points: np.ndarray, normals: np.ndarray, sample: np.ndarray,
                     view_up_deg: float, reach_m: float, slack_m: float) -> np.ndarray:
    """``observes(sensors[:, None], points[sample], normals[sample], ...)`` (C, S) for
    sensors (C, 3) and view targets (:func:`view_targets`, whose normals are face
    directions or zero) picked by ``sample`` (C, S), the same values: per coordinate
    on contiguous arrays, and the dot product with a face direction as the one
    coordinate it picks (exact), so no (C, S, 3) arrays are gathered."""
    px, py, pz = (np.ascontiguousarray(points[:, a])[sample] for a in range(3))
    dx, dy, dz = px - sensors[:, 0, None], py - sensors[:, 1, None], pz - sensors[:, 2, None]
    level = np.hypot(dx, dy)
    dist = np.hypot(level, dz)
    nx, ny, nz = (np.ascontiguousarray(normals[:, a])[sample] for a in range(3))
    dot = dx * nx + dy * ny + dz * nz   # one term at most is nonzero: exact
    cos_max = np.cos(np.radians(MAX_INCIDENCE_DEG))
    facing = (dot >= cos_max * dist) | ((nx == 0) & (ny == 0) & (nz == 0))
    below_top = dz <= level * np.tan(np.radians(min(view_up_deg, 89.9))) + slack_m
    return (dist <= reach_m) & facing & below_top


def clear_sight(grid: Grid, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether each segment ``a[i]``-``b[i]`` crosses no OCCUPIED voxel of the map and
    stays inside it (sampled every half voxel up to its end). Unknown voxels do not
    block: the space between a viewpoint and a frontier is often unseen air."""
    step = 0.5 * grid.voxel_size_m
    length = np.linalg.norm(b - a, axis=1)
    n = np.maximum(np.ceil(length / step).astype(np.int64), 1)
    seg = np.repeat(np.arange(len(a)), n)
    t = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)) / n[seg]
    pts = a[seg] + (b - a)[seg] * t[:, None]
    idx = grid.to_index(pts)
    nx, ny, nz = grid.shape
    i, j, k = idx[:, 0], idx[:, 1], idx[:, 2]
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny) & (k >= 0) & (k < nz)
    flat = np.where(inside, (i * ny + j) * nz + k, 0)
    rock = ~inside | (grid.occupancy.reshape(-1)[flat] == OCCUPIED)
    return np.bincount(seg[rock], minlength=len(a)) == 0


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
    src, dst = _close_blocks(packed, tuple(int(n) for n in nb), centres, cluster_radius_m, 2 * grid.voxel_size_m)
    adj = coo_matrix((np.ones(len(src)), (src, dst)), shape=(len(blocks), len(blocks)))
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
    for c in np.flatnonzero(np.diff(bounds) >= min_cluster_voxels):
        members = order[bounds[c] : bounds[c + 1]]
        # np.mean's own sum and division, without its wrapper's cost (same values)
        centroid = np.add.reduce(pts[members], axis=0) / len(members)
        clusters.append(FrontierCluster(voxels=voxels[members], centroid=centroid))
    return clusters


def _close_blocks(packed: np.ndarray, shape: tuple[int, int, int], centres: np.ndarray, radius_m: float,
                  spacing_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Each pair (i, j) of blocks whose centres are at most ``radius_m`` apart, once: the
    pairs ``cKDTree.query_pairs`` finds (squared distance summed axis by axis, compared
    with the squared radius), found by looking up the few lattice offsets within reach
    (blocks: ascending flat indices ``packed`` on a lattice of ``shape``, ``spacing_m``
    apart, centres (N, 3))."""
    src, dst = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    q = Voxels(packed, shape)
    r2 = radius_m * radius_m
    with _Lookup(int(np.prod(shape)), packed) as ids:
        for d in _lattice_offsets(radius_m, spacing_m):
            j = q.at(ids, d, 0).astype(np.int64) - 1
            i = np.flatnonzero(j >= 0)
            j = j[i]
            diff = centres[i] - centres[j]
            near = (diff[:, 0] * diff[:, 0] + diff[:, 1] * diff[:, 1]) + diff[:, 2] * diff[:, 2] <= r2
            src.append(i[near])
            dst.append(j[near])
    return np.concatenate(src), np.concatenate(dst)


@functools.lru_cache(maxsize=16)
def _lattice_offsets(radius_m: float, spacing_m: float) -> list[tuple[int, int, int]]:
    """The offsets (one of each opposite pair) of a lattice ``spacing_m`` apart that may be
    within ``radius_m`` (with a margin for rounding: the caller tests the distance)."""
    reach = int(radius_m / spacing_m) + 1
    span = range(-reach, reach + 1)
    return [d for d in itertools.product(span, span, span)
            if d > (0, 0, 0) and math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2) * spacing_m <= radius_m * (1 + 1e-6)]


#: Voxels of each cluster whose view is checked from every goal candidate (bounds the work).
VIEW_SAMPLES = 16
#: A goal must let the sensor observe at least this share of what the cluster's best
#: goal candidate lets it observe.
VIEW_SHARE = 0.8
#: Goal candidates, cheapest first, whose line of sight to the cluster is checked.
SIGHT_CANDIDATES = 8


def nearest_frontier(
    graph: NavGraph,
    distances: np.ndarray,
    clusters: list[FrontierCluster],
    grid: Grid,
    *,
    max_goal_offset_m: float,
    view_up_deg: float = 90.0,
    sensor_height_m: float = 0.0,
    offset_weight: float = 2.0,
    node_spacing_m: float = VIEWPOINT_SPACING_M,
    min_targets: int = 1,
    accept: Callable[[FrontierGoal], bool] = lambda goal: True,
) -> FrontierGoal | None:
    """The cluster whose goal node is cheapest: path length from the robot
    (``distances``) plus ``offset_weight`` times the straight distance to the cluster's
    centroid; ``None`` when no cluster has a goal.

    A goal node lies within ``max_goal_offset_m`` of the centroid and is chosen for the
    sensor (``sensor_height_m`` above the node), which sees at most ``view_up_deg``
    above the horizontal: a frontier voxel is observable from a node when what must be
    seen of it (:func:`view_targets`: the air above a voxel under an unseen roof) is
    within that band and ``max_goal_offset_m`` and, for a wall of unknown space, met
    from in front (:func:`observes`). Of :data:`VIEW_SAMPLES` voxels of each
    cluster, a goal must observe at least :data:`VIEW_SHARE` of the most that any
    candidate observes, so the unseen air under a 3 m roof is approached from 8 m along
    the drift, not from below, where a LiDAR with a 30° view never sees it. A cluster
    of which no candidate observes ``min_targets`` voxels (estimated from the samples)
    is no goal for this sensor, from where the robot can walk now. The cheapest
    candidates (up to :data:`SIGHT_CANDIDATES`) are checked for a line of sight
    (:func:`clear_sight`) to the voxels they observe; the goal's ``targets`` are those
    with a clear line. Goals that ``accept`` refuses are passed over with their cluster
    (the caller's, say a goal where the robot stands already). A far goal approaches a
    frontier the map cannot reach yet; a weight above 1 makes the node nearest the
    frontier win over the robot's own. Candidate nodes are thinned to one per
    ``node_spacing_m`` cell.
    """
    nodes = viewpoint_nodes(graph, distances, node_spacing_m)
    if len(nodes) == 0 or not clusters:
        return None
    centroids = np.array([c.centroid for c in clusters])
    near = cKDTree(graph.positions[nodes]).query_ball_point(centroids, max_goal_offset_m)
    owner = np.repeat(np.arange(len(clusters)), [len(n) for n in near])
    if len(owner) == 0:
        return None
    cand = nodes[np.concatenate([np.asarray(n, dtype=np.int64) for n in near])]
    offset = np.linalg.norm(centroids[owner] - graph.positions[cand], axis=1)
    sensor = graph.positions[cand] + np.array([0.0, 0.0, sensor_height_m])
    picks = [c.voxels[_view_samples(c.size)] for c in clusters]
    sizes = np.array([len(p) for p in picks])
    first = np.cumsum(sizes) - sizes
    points, normals = view_targets(grid, np.concatenate(picks))
    # Each candidate against its cluster's samples: a row per candidate, padded to the most samples.
    col = np.arange(sizes.max())
    sample = np.minimum(first[owner][:, None] + col, len(points) - 1)
    slack = 0.5 * grid.voxel_size_m
    seen = observes_samples(sensor, points, normals, sample, view_up_deg, max_goal_offset_m, slack)
    share = (seen & (col < sizes[owner][:, None])).sum(axis=1) / sizes[owner]
    best = np.zeros(len(clusters))
    np.maximum.at(best, owner, share)
    worth = best * np.array([c.size for c in clusters]) >= min_targets
    usable = worth[owner] & (share >= VIEW_SHARE * best[owner])
    cost = np.where(usable, distances[cand] + offset_weight * offset, np.inf)
    finite = np.flatnonzero(np.isfinite(cost))
    by_cluster = finite[np.lexsort((cost[finite], owner[finite]))]
    rank = np.arange(len(by_cluster)) - np.searchsorted(owner[by_cluster], owner[by_cluster])
    tries = by_cluster[rank < SIGHT_CANDIDATES]   # each cluster's cheapest candidates ...
    tries = tries[np.argsort(cost[tries], kind="stable")]   # ... cheapest first
    tries_left = np.bincount(owner[tries], minlength=len(clusters))
    cheapest = np.full(len(clusters), -1)
    for k in tries:
        c = owner[k]
        if tries_left[c] == 0:
            continue
        cheapest[c] = k if cheapest[c] < 0 else cheapest[c]
        tries_left[c] -= 1
        mine = slice(first[c], first[c] + sizes[c])
        visible = observes(sensor[k], points[mine], normals[mine], view_up_deg, max_goal_offset_m, slack)
        clear = clear_sight(grid, np.broadcast_to(sensor[k], (int(visible.sum()), 3)), points[mine][visible])
        if clear.sum() >= VIEW_SHARE * share[k] * sizes[c]:
            targets = _observed(grid, clusters[c].voxels, sensor[k], view_up_deg, max_goal_offset_m)
        elif tries_left[c] > 0:
            continue
        else:  # no clear line from its cheapest candidates: the cheapest, judged on the whole cluster
            k, targets = cheapest[c], clusters[c].voxels
        tries_left[c] = 0
        goal = FrontierGoal(cluster=clusters[c], node=int(cand[k]), path_length_m=float(distances[cand[k]]),
                            offset_m=float(offset[k]), targets=targets)
        if accept(goal):
            return goal
    return None


@functools.lru_cache(maxsize=4096)
def _view_samples(size: int) -> np.ndarray:
    """Positions of the :data:`VIEW_SAMPLES` voxels (or all) spread over a cluster of ``size``."""
    out = np.linspace(0, size - 1, min(size, VIEW_SAMPLES)).astype(np.int64)
    out.flags.writeable = False
    return out


def _observed(grid: Grid, voxels: np.ndarray, sensor: np.ndarray, view_up_deg: float,
              reach_m: float) -> np.ndarray:
    """The ``voxels`` (flat indices) that ``sensor`` observes (:func:`observes`) with a
    clear line to them (:func:`clear_sight`)."""
    pts, normals = view_targets(grid, voxels)
    ok = observes(sensor, pts, normals, view_up_deg, reach_m, 0.5 * grid.voxel_size_m)
    ok[ok] = clear_sight(grid, np.broadcast_to(sensor, (int(ok.sum()), 3)), pts[ok])
    return voxels[ok]
