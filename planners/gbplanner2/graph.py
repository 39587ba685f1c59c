"""The random local graph G_L (Algorithm 2) and its Dijkstra shortest paths.

Algorithm 2 adds one random sample at a time: a sample in free space inside D_L is
(legged robots) projected onto the ground and marked *hanging* when there is no
mapped ground below it; it is connected to its nearest vertex if that edge is
admissible, and then to every vertex within delta whose edge is admissible, until
N_V,max vertices or N_E,max edges.

This implementation gives the same graph structure with batched numpy work instead
of one sample at a time:

1. samples are drawn uniformly in D_L in batches sized by the share of usable
   samples so far; the free ones are projected and collision-checked together (O(1)
   lookups in :class:`~.local_map.LocalMap`);
2. samples closer than ``edge_length_min_m`` to an earlier one are dropped;
3. candidate edges join each sample to its ``neighbours_max`` nearest samples within
   ``min(delta, edge_length_max_m)`` (a KD-tree query) and are all checked at once;
4. the samples the root reaches along admissible edges (a hanging vertex is an end,
   never a way through) form G_L; when more than N_V,max are reached, the N_V,max
   nearest to the robot along the graph (the sequential algorithm also grows its graph
   outwards from the robot); edges up to N_E,max in sampling order. Batches are sized
   so that about N_V,max samples are reached, which keeps G_L spread over all of D_L.

Where the sequential algorithm steers a far sample towards its nearest vertex, the
batches keep drawing until enough samples are connected; both give a graph of
collision-free vertices in D_L connected to the robot.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import breadth_first_order, dijkstra
from scipy.spatial import cKDTree

from .bounds import LocalBound
from .config import GBPlannerConfig
from .local_map import GROUND_BLOCKED, GROUND_NONE, LocalMap


@dataclass
class LocalGraph:
    """G_L: ``vertices`` (N, 3) with the root (the robot) at index 0, undirected
    ``edges`` (E, 2) with their ``lengths``, and which vertices are ``hanging``."""

    vertices: np.ndarray
    edges: np.ndarray
    lengths: np.ndarray
    hanging: np.ndarray
    bound: LocalBound | None = None
    num_samples: int = 0
    stats: dict = field(default_factory=dict)

    @property
    def num_vertices(self) -> int:
        return len(self.vertices)

    @property
    def num_edges(self) -> int:
        return len(self.edges)

    def directed_adjacency(self) -> csr_matrix:
        """Edge weights as a directed matrix in which no edge leaves a hanging vertex,
        so that shortest paths end at hanging vertices but never pass through them."""
        n = self.num_vertices
        if self.num_edges == 0:
            return csr_matrix((n, n))
        i, j = self.edges[:, 0], self.edges[:, 1]
        fwd = ~self.hanging[i]
        bwd = ~self.hanging[j]
        rows = np.concatenate([i[fwd], j[bwd]])
        cols = np.concatenate([j[fwd], i[bwd]])
        w = np.concatenate([self.lengths[fwd], self.lengths[bwd]])
        return coo_matrix((w, (rows, cols)), shape=(n, n)).tocsr()


@dataclass(frozen=True)
class ShortestPaths:
    """Dijkstra from the root: ``distance_m`` (inf when unreachable) and ``predecessor``
    (-9999 for the root and unreachable vertices, scipy's convention)."""

    distance_m: np.ndarray
    predecessor: np.ndarray

    @property
    def reachable(self) -> np.ndarray:
        return np.isfinite(self.distance_m)

    def path(self, target: int) -> list[int]:
        """Vertex indices from the root to ``target`` (empty when unreachable)."""
        if not np.isfinite(self.distance_m[target]):
            return []
        out = [int(target)]
        while self.predecessor[out[-1]] >= 0:
            out.append(int(self.predecessor[out[-1]]))
        return out[::-1]

    def leaves(self) -> np.ndarray:
        """Reachable vertices that precede no other vertex in the shortest-path tree."""
        n = len(self.distance_m)
        is_parent = np.zeros(n, bool)
        pred = self.predecessor
        is_parent[pred[pred >= 0]] = True
        out = self.reachable & ~is_parent
        out[0] = False if n > 1 else out[0]
        return np.flatnonzero(out)


def shortest_paths(graph: LocalGraph, source: int = 0) -> ShortestPaths:
    """GetDijkstraShortestPaths(G_L, xi_0)."""
    dist, pred = dijkstra(graph.directed_adjacency(), directed=True, indices=source, return_predecessors=True)
    return ShortestPaths(dist, pred)


def project_vertices(local_map: LocalMap, points: np.ndarray, config: GBPlannerConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ProjectPoint and GroundAttached for free samples of a legged robot.

    Returns the projected points (body height above the ground below them), whether
    each is hanging, and which samples are usable (free, box collision-free after the
    projection).
    """
    pts = np.atleast_2d(np.asarray(points, float))
    if len(pts) == 0:
        return pts.copy(), np.zeros(0, bool), np.zeros(0, bool)
    gz, status = local_map.project_to_ground(pts)
    out = pts.copy()
    usable = status != GROUND_BLOCKED  # blocked: the sample is not in free space
    out[:, 2] = np.where(usable, gz + config.body_height_m, pts[:, 2])
    hanging = status == GROUND_NONE
    usable &= local_map.is_box_free(out)
    return out, hanging, usable


def build_local_graph(
    local_map: LocalMap,
    root: np.ndarray,
    bound: LocalBound,
    config: GBPlannerConfig,
    rng: np.random.Generator,
    exploration_bounds: tuple[np.ndarray, np.ndarray] | None = None,
) -> LocalGraph:
    """BuildLocalGraph(xi_0) of Algorithm 2 inside ``bound`` (see the module docstring);
    with ``exploration_bounds`` (lo, hi), vertices must also lie inside that box."""
    cfg = config
    target = cfg.num_vertices_max - 1
    root = np.asarray(root, float)
    pool_pts = root[None].copy()
    pool_hang = np.zeros(1, bool)
    drawn = 0
    graph: LocalGraph | None = None
    # Draw about as many usable samples as vertices are wanted (a few more): the graph
    # then covers all of D_L. Too many would be cut to those nearest to the robot.
    want = target + target // 20 + 16
    usable_rate = 1.0  # usable samples per draw, re-estimated from each batch
    while drawn < cfg.num_samples_max:
        need = max(want - len(pool_pts), 1)
        n = int(min(max(64, math.ceil(1.05 * need / usable_rate)), cfg.num_samples_max - drawn))
        # SampleFree(D_L): uniform in the box, kept where free.
        raw = bound.sample(rng, n)
        drawn += n
        if cfg.is_legged:
            pts, hang, ok = project_vertices(local_map, raw, cfg)
        else:
            pts, hang = raw, np.zeros(n, bool)
            ok = local_map.is_box_free(raw)
        if exploration_bounds is not None:
            ok &= np.all((pts >= exploration_bounds[0]) & (pts <= exploration_bounds[1]), axis=1)
        pts, hang = pts[ok], hang[ok]
        keep = thin_samples(pts, cfg.edge_length_min_m, pool_pts)
        pool_pts = np.concatenate([pool_pts, pts[keep]])
        pool_hang = np.concatenate([pool_hang, hang[keep]])
        added = int(keep.sum())
        usable_rate = max(added / n, 0.02)
        # Free space packed with samples edge_length_min apart: more draws add nothing.
        saturated = added < max(4, n // 100)
        if len(pool_pts) < want and drawn < cfg.num_samples_max and not saturated:
            continue
        graph = _connect(local_map, pool_pts, pool_hang, cfg)
        if graph.num_vertices >= cfg.num_vertices_max or graph.stats.get("edge_limit_reached") or saturated:
            break
        # Not enough samples joined (part of D_L's free space is not connected to the
        # robot): draw as many more as the share that joined suggests.
        share = max(graph.stats.get("reached", 1), 1) / len(pool_pts)
        want = int(len(pool_pts) + 1.05 * (target + 1 - graph.num_vertices) / share) + 16
    if graph is None:
        graph = _connect(local_map, pool_pts, pool_hang, cfg)
    graph.bound = bound
    graph.num_samples = drawn
    return graph


def thin_samples(points: np.ndarray, radius_m: float, existing: np.ndarray | None = None) -> np.ndarray:
    """Which of ``points`` (in sampling order) to keep so that none lies within
    ``radius_m`` of an earlier kept point or of an ``existing`` one: the sequential
    rule, decided in rounds (a point is kept when all its earlier neighbours are
    dropped, dropped when one of them is kept)."""
    n = len(points)
    if n == 0 or radius_m <= 0:
        return np.ones(n, bool)
    status = np.zeros(n, np.int8)  # 0 undecided, 1 kept, -1 dropped
    if existing is not None and len(existing):
        d, _ = cKDTree(existing).query(points, k=1, distance_upper_bound=radius_m)
        status[np.isfinite(d)] = -1
    pairs = cKDTree(points).query_pairs(radius_m, output_type="ndarray")
    if len(pairs) == 0:
        status[status == 0] = 1
        return status == 1
    i, j = pairs.min(axis=1), pairs.max(axis=1)
    while True:
        undecided = status == 0
        if not undecided.any():
            break
        si = status[i]
        kept_before = np.bincount(j[si == 1], minlength=n) > 0
        open_before = np.bincount(j[si == 0], minlength=n) > 0
        drop = undecided & kept_before
        keep = undecided & ~kept_before & ~open_before
        status[drop] = -1
        status[keep] = 1
    return status == 1


def _reachable(n: int, ei: np.ndarray, ej: np.ndarray, hang: np.ndarray) -> np.ndarray:
    """Sorted indices of the vertices the root (0) reaches along the edges, never
    leaving a hanging vertex."""
    fwd = ~hang[ei]
    bwd = ~hang[ej]
    rows = np.concatenate([ei[fwd], ej[bwd]])
    cols = np.concatenate([ej[fwd], ei[bwd]])
    adj = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)).tocsr()
    order = breadth_first_order(adj, 0, directed=True, return_predecessors=False)
    return np.sort(order)


def _graph_distances(n: int, ei: np.ndarray, ej: np.ndarray, w: np.ndarray, hang: np.ndarray) -> np.ndarray:
    """Shortest distances from the root (0) along the edges, never leaving a hanging vertex."""
    fwd = ~hang[ei]
    bwd = ~hang[ej]
    rows = np.concatenate([ei[fwd], ej[bwd]])
    cols = np.concatenate([ej[fwd], ei[bwd]])
    ww = np.concatenate([w[fwd], w[bwd]])
    adj = coo_matrix((ww, (rows, cols)), shape=(n, n)).tocsr()
    return dijkstra(adj, directed=True, indices=0)


def _connect(local_map: LocalMap, pts: np.ndarray, hang: np.ndarray, cfg: GBPlannerConfig) -> LocalGraph:
    """Steps 3-4 of the module docstring on the pool of usable samples (root first)."""
    n = len(pts)
    if n < 2:
        return LocalGraph(pts[:1], np.zeros((0, 2), np.int64), np.zeros(0), hang[:1], stats={"pool": n})
    # 3. Candidate edges to the nearest samples within reach.
    reach = min(cfg.neighbour_radius_m, cfg.edge_length_max_m)
    k = min(cfg.neighbours_max + 1, n)
    dist, nbr = cKDTree(pts).query(pts, k=k, distance_upper_bound=reach)
    src = np.repeat(np.arange(n), k)
    nbr = nbr.reshape(-1)
    dist = dist.reshape(-1)
    keep = np.isfinite(dist) & (nbr != src) & (nbr < n)
    a, b = src[keep], nbr[keep]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    # The distinct pairs, by sorting: np.unique (hashing first) takes about twice as long.
    codes = np.sort(lo.astype(np.int64) * n + hi)
    first = np.ones(len(codes), bool)
    first[1:] = codes[1:] != codes[:-1]
    codes = codes[first]
    ei, ej = codes // n, codes % n
    # Edges between two hanging vertices can never be used.
    both_hanging = hang[ei] & hang[ej]
    ei, ej = ei[~both_hanging], ej[~both_hanging]
    check = local_map.check_edges(pts[ei], pts[ej], hanging_end=hang[ei] | hang[ej])
    ok = check.admissible & (check.length_m >= cfg.edge_length_min_m * 0.5)
    ei, ej, elen = ei[ok], ej[ok], check.length_m[ok]
    # 4. The graph: the samples the root reaches (never through a hanging vertex); when
    #    there are more than N_V,max, the N_V,max nearest to the robot along the graph
    #    (a prefix of the shortest-path tree, so still connected); their edges up to
    #    N_E,max in sampling order.
    dist = _graph_distances(n, ei, ej, elen, hang)
    joined = np.flatnonzero(np.isfinite(dist))
    n_reached = len(joined)
    if n_reached > cfg.num_vertices_max:
        joined = joined[np.argsort(dist[joined], kind="stable")[: cfg.num_vertices_max]]
    kept = np.sort(joined)
    keep_mask = np.zeros(n, bool)
    keep_mask[kept] = True
    e_in = keep_mask[ei] & keep_mask[ej]
    ei, ej, elen = ei[e_in], ej[e_in], elen[e_in]
    edge_limit = False
    if len(ei) > cfg.num_edges_max:
        edge_limit = True
        sel = np.argsort(ej, kind="stable")[: cfg.num_edges_max]
        sel.sort()
        ei, ej, elen = ei[sel], ej[sel], elen[sel]
        keep_mask &= np.arange(n) <= ej.max()
    if len(kept) > 0:
        # Truncation may strand a few samples: keep only what the root still reaches.
        sub = np.flatnonzero(keep_mask)
        local = -np.ones(n, np.int64)
        local[sub] = np.arange(len(sub))
        ok_e = keep_mask[ei] & keep_mask[ej]
        ei, ej, elen = ei[ok_e], ej[ok_e], elen[ok_e]
        reach = sub[_reachable(len(sub), local[ei], local[ej], hang[sub])]
        keep_mask[:] = False
        keep_mask[reach] = True
        ok_e = keep_mask[ei] & keep_mask[ej]
        ei, ej, elen = ei[ok_e], ej[ok_e], elen[ok_e]
        kept = np.flatnonzero(keep_mask)
    remap = -np.ones(n, np.int64)
    remap[kept] = np.arange(len(kept))
    edges = np.stack([remap[ei], remap[ej]], axis=1) if len(ei) else np.zeros((0, 2), np.int64)
    return LocalGraph(
        vertices=pts[kept],
        edges=edges,
        lengths=elen,
        hanging=hang[kept],
        stats={"pool": n, "reached": n_reached, "candidate_edges": len(check.admissible),
               "edge_limit_reached": edge_limit},
    )
