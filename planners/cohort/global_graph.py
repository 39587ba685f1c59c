"""COHORT's global graph G_C (Kulkarni et al. 2022, section IV-B, Figure 3).

Per submap, a subgraph: N_C vertices sampled at random in the submap's bounding box
(the extremities of its visited voxels) in free space, plus points along the robot's
trajectory in that submap, with collision-free edges within rho_C; each subgraph is
merged into G_C (its edges may join vertices of earlier submaps). Frontier clusters
are linked to the vertices near their centroids.

Choices where the paper is silent:

* Vertices are drawn among the submap's visited blocks of the common map that are
  still FREE there (every one of them lies in the box and in free space), so N_C
  draws give N_C vertices, without rejection sampling.
* Each new vertex gets edges to at most :data:`MAX_NEIGHBOURS` of its nearest vertices
  within rho_C, as delve's GBPlanner2 global planner does (all pairs within 4 m of a
  drift would give tens of thousands of edges per submap, for no shorter paths).
* An edge is collision-free when no point along it (every half fine voxel) lies in an
  OCCUPIED voxel of the fine base map (rock) or in a block of the common map that is
  still UNKNOWN (unseen space may be rock). Sparse holes of the fine map do not block:
  the block around them is FREE.

The graph is kept as arrays (positions, edge lists) with a cached scipy sparse
adjacency, so that Dijkstra from every robot and home is one
``scipy.sparse.csgraph.dijkstra`` call; :meth:`GlobalGraph.to_networkx` gives it as a
``networkx.Graph`` for anyone who wants one.
"""
from __future__ import annotations

import networkx as nx
import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.spatial import cKDTree

from ..frontier import FrontierCluster
from ..occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from .common_map import CommonMap

#: Edges per new vertex, at most (its nearest within rho_C), to bound G_C's size.
MAX_NEIGHBOURS = 12
#: Trajectory points are kept one per this share of rho_C along the path, so that
#: consecutive ones are always close enough to be joined.
TRAJECTORY_SPACING_SHARE = 0.5


def segments_free(fine: Grid, common: CommonMap, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether each segment ``a[i]``-``b[i]`` is collision-free: every point along it
    (every half fine voxel, ends included) inside the map, in no OCCUPIED fine voxel
    and in no UNKNOWN block of the common map."""
    a, b = np.atleast_2d(np.asarray(a, float)), np.atleast_2d(np.asarray(b, float))
    if len(a) == 0:
        return np.zeros(0, dtype=bool)
    step = 0.5 * fine.voxel_size_m
    n = np.maximum(np.ceil(np.linalg.norm(b - a, axis=1) / step).astype(np.int64), 1) + 1
    seg = np.repeat(np.arange(len(a)), n)
    t = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)) / (n[seg] - 1)
    pts = a[seg] + (b - a)[seg] * t[:, None]
    idx = fine.to_index(pts)
    inside = fine.in_bounds(idx)
    bad = ~inside
    i = idx[inside]
    bad[inside] = fine.occupancy[i[:, 0], i[:, 1], i[:, 2]] == OCCUPIED
    c = i // common.factor
    bad[inside] |= common.occupancy[c[:, 0], c[:, 1], c[:, 2]] == UNKNOWN
    blocked = np.zeros(len(a), dtype=bool)
    np.logical_or.at(blocked, seg, bad)
    return ~blocked


def thin_trajectory(trajectory: np.ndarray, spacing_m: float) -> np.ndarray:
    """The first point of ``trajectory`` ((k, 3), oldest first) in each ``spacing_m``
    of distance along it, and its last point."""
    traj = np.asarray(trajectory, float).reshape(-1, 3)
    if len(traj) <= 1:
        return traj
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(traj, axis=0), axis=1))])
    _, first = np.unique(np.floor(along / spacing_m), return_index=True)
    keep = np.union1d(first, [len(traj) - 1])
    return traj[keep]


def submap_rng(robot: str, index: int) -> np.random.Generator:
    """The generator of submap ``index`` of ``robot``: seeded by both, never by hash()."""
    return np.random.default_rng([index, *robot.encode()])


class GlobalGraph:
    """G_C: vertex ``positions`` (n, 3), the submap each came from (``vertex_submap``),
    whether it is a trajectory point (``vertex_on_trajectory``), and undirected weighted
    edges (``edge_u``, ``edge_v``, ``edge_w``: lengths in metres)."""

    def __init__(self) -> None:
        self.positions = np.zeros((0, 3))
        self.vertex_submap: list[tuple[str, int]] = []
        self.vertex_on_trajectory = np.zeros(0, dtype=bool)
        self.edge_u = np.zeros(0, dtype=np.int64)
        self.edge_v = np.zeros(0, dtype=np.int64)
        self.edge_w = np.zeros(0)
        self._adjacency: csr_matrix | None = None
        self._tree: cKDTree | None = None

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def num_edges(self) -> int:
        return len(self.edge_u)

    @property
    def kdtree(self) -> cKDTree:
        if self._tree is None:
            self._tree = cKDTree(self.positions)
        return self._tree

    def adjacency(self) -> csr_matrix:
        """Symmetric sparse adjacency (edge lengths), cached until the graph grows."""
        if self._adjacency is None:
            n = len(self)
            rows = np.concatenate([self.edge_u, self.edge_v])
            cols = np.concatenate([self.edge_v, self.edge_u])
            self._adjacency = coo_matrix((np.tile(self.edge_w, 2), (rows, cols)), shape=(n, n)).tocsr()
        return self._adjacency

    def to_networkx(self) -> nx.Graph:
        """G_C as a ``networkx.Graph``: nodes 0..n-1 with ``pos``, edges with ``weight``."""
        g = nx.Graph()
        g.add_nodes_from((i, {"pos": p}) for i, p in enumerate(self.positions))
        g.add_weighted_edges_from(zip(self.edge_u.tolist(), self.edge_v.tolist(), self.edge_w.tolist()))
        return g

    def add_submap(self, key: tuple[str, int], fine: Grid, common: CommonMap, visited: np.ndarray,
                   trajectory: np.ndarray, n_vertices: int, edge_radius_m: float,
                   rng: np.random.Generator) -> np.ndarray:
        """Add the subgraph of submap ``key`` and return its new vertex ids.

        ``visited``: the submap's visited blocks (flat indices of ``common``);
        ``trajectory``: (k, 3) robot positions in the submap, oldest first. Up to
        ``n_vertices`` vertices are drawn (with ``rng``) among the visited blocks still
        FREE in ``common``; trajectory points are kept every
        ``TRAJECTORY_SPACING_SHARE * edge_radius_m``. Edges: each new vertex to its
        nearest (at most :data:`MAX_NEIGHBOURS`) within ``edge_radius_m``, and
        consecutive trajectory points, when collision-free (:func:`segments_free`).
        """
        free = np.asarray(visited, np.int64)
        free = free[common.values(free) == FREE]
        drawn = np.sort(rng.choice(len(free), size=min(n_vertices, len(free)), replace=False))
        samples = common.centres(free[drawn]) if len(drawn) else np.zeros((0, 3))
        traj = thin_trajectory(trajectory, TRAJECTORY_SPACING_SHARE * edge_radius_m)
        new = np.concatenate([samples, traj])
        if len(new) == 0:
            return np.zeros(0, dtype=np.int64)
        first = len(self)
        ids = np.arange(first, first + len(new))
        self.positions = np.concatenate([self.positions, new])
        self.vertex_submap.extend([key] * len(new))
        self.vertex_on_trajectory = np.concatenate([self.vertex_on_trajectory,
                                                    np.arange(len(new)) >= len(samples)])
        self._tree = None
        k = min(MAX_NEIGHBOURS + 1, len(self))
        dist, near = self.kdtree.query(new, k=k, distance_upper_bound=edge_radius_m)
        dist, near = dist.reshape(len(new), k), near.reshape(len(new), k)
        u = np.repeat(ids, k)
        v = near.reshape(-1)
        ok = np.isfinite(dist.reshape(-1)) & (v != u)
        t_ids = ids[len(samples):]
        u = np.concatenate([u[ok], t_ids[:-1]])
        v = np.concatenate([v[ok], t_ids[1:]])
        pairs = np.unique(np.sort(np.stack([u, v], axis=1), axis=1), axis=0)
        if len(pairs):
            a, b = self.positions[pairs[:, 0]], self.positions[pairs[:, 1]]
            good = segments_free(fine, common, a, b)
            self.edge_u = np.concatenate([self.edge_u, pairs[good, 0]])
            self.edge_v = np.concatenate([self.edge_v, pairs[good, 1]])
            self.edge_w = np.concatenate([self.edge_w, np.linalg.norm(b - a, axis=1)[good]])
        self._adjacency = None
        return ids

    def attach(self, point: np.ndarray, fine: Grid, common: CommonMap, radius_m: float) -> int | None:
        """The vertex to enter G_C from ``point``: the nearest within ``radius_m`` with a
        collision-free segment to it, else the nearest of all; None for an empty graph."""
        if len(self) == 0:
            return None
        point = np.asarray(point, float)
        k = min(MAX_NEIGHBOURS, len(self))
        dist, near = self.kdtree.query(point, k=k, distance_upper_bound=radius_m)
        near = np.atleast_1d(near)[np.isfinite(np.atleast_1d(dist))]
        if len(near):
            free = segments_free(fine, common, np.repeat(point[None], len(near), axis=0), self.positions[near])
            if free.any():
                return int(near[np.argmax(free)])
        return int(self.kdtree.query(point)[1])

    def link_frontiers(self, clusters: list[FrontierCluster], common: CommonMap,
                       radius_m: float) -> list[np.ndarray]:
        """The vertices linked to each cluster (ascending ids): those within ``radius_m``
        of its centroid or of its point nearest the centroid (the centroid of a curved
        frontier may lie far from it); empty when none is that near."""
        if len(self) == 0:
            return [np.zeros(0, dtype=np.int64) for _ in clusters]
        links = []
        for c in clusters:
            pts = common.centres(c.voxels)
            anchor = pts[np.argmin(np.linalg.norm(pts - c.centroid, axis=1))]
            near = self.kdtree.query_ball_point(np.stack([c.centroid, anchor]), radius_m)
            links.append(np.unique(np.concatenate([np.asarray(n, dtype=np.int64) for n in near])))
        return links
