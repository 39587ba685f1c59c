"""Navigation graphs kept up to date from the voxels that changed.

:func:`delve.planners.navgraph.legged_graph` and :func:`~delve.planners.navgraph.aerial_graph`
rebuild a graph over every free voxel of the map. Whether a voxel is a node, though,
depends only on the map a few voxels around it, and a node's edges on the nodes next to
it. :class:`LeggedGraphUpdater` and :class:`AerialGraphUpdater` keep, per voxel, what
each rule of the full build concluded (rock, ground, standable, node) and the edges by
voxel; an update follows a change through the rules, recomputing a rule only where one
of its inputs changed (a LiDAR sweep frees thousands of voxels of air, which change no
node), then numbers the nodes as the full build does (in the map's order of free
voxels), so the graph equals the full build's exactly.
"""
from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np
from scipy.sparse import csr_matrix

from .navgraph import (_NEIGHBOURS_8, NavGraph, Voxels, _ball, _Lookup, around, distinct, inclination_among,
                       inclination_reach)
from .occupancy import FREE, OCCUPIED, UNKNOWN, Grid


class _Updater(ABC):
    """What both updaters share: their per-voxel state made (``_setup``) for a grid, and
    the changed voxels followed into the rule that comes first, rock."""

    _shape: tuple[int, int, int] | None = None
    rock: np.ndarray

    @abstractmethod
    def _setup(self, grid: Grid) -> None:
        """The rules' offsets for this grid's voxel size, and the state of an unknown map."""

    def _changes(self, grid: Grid, changed: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(occupancy, the changed voxels, those of them that turned rock or not rock): all
        known voxels when ``changed`` is None or for a grid of another shape (state made anew)."""
        occ = grid.occupancy.reshape(-1)
        if changed is None or self._shape != grid.shape:
            self._setup(grid)
            changed = np.flatnonzero(occ != UNKNOWN)
        changed = np.asarray(changed, dtype=np.int64)
        return occ, changed, _store(self.rock, changed, occ[changed] == OCCUPIED)


class LeggedGraphUpdater(_Updater):
    """The legged navigation graph of one map, updated from its changed voxels.

    Takes the parameters of :func:`delve.planners.navgraph.legged_graph`. Memory: four
    bytes per voxel of the grid (zero-filled, so only the pages around the mapped space
    are backed) and the edges.
    """

    def __init__(self, *, body_height_m: float, radius_m: float, max_step_m: float, max_inclination_deg: float,
                 headroom_m: float | None = None, inclination_baseline_m: float = 0.6,
                 ground_inference_radius_m: float = 1.0):
        self.body_height_m, self.radius_m, self.max_step_m = body_height_m, radius_m, max_step_m
        self.max_inclination_deg, self.inclination_baseline_m = max_inclination_deg, inclination_baseline_m
        self.headroom_m = body_height_m + 0.2 if headroom_m is None else headroom_m
        self.ground_inference_radius_m = ground_inference_radius_m

    def _setup(self, grid: Grid) -> None:
        """The rules' offsets for this grid's voxel size, and empty per-voxel state (that
        of a map with every voxel unknown)."""
        vox, size = grid.voxel_size_m, int(np.prod(grid.shape))
        self._shape, self._vox = grid.shape, vox
        #: What the rules concluded per voxel: rock, free with rock below (ground),
        #: standable (ground below or beside, headroom above), node.
        self.rock, self.ground = np.zeros(size, np.uint8), np.zeros(size, np.uint8)
        self.standable, self.node = np.zeros(size, np.uint8), np.zeros(size, np.uint8)
        self._edges = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
        self.n_up = max(1, math.ceil(self.headroom_m / vox) - 1)
        radius = self.ground_inference_radius_m / vox
        span = range(-math.ceil(radius), math.ceil(radius) + 1)
        self._disc = [(a, b, 0) for a in span for b in span if math.hypot(a, b) <= radius + 1e-9]
        r = max(1, int(round(self.radius_m / vox)))
        layers = sorted({1, max(1, self.n_up // 2), self.n_up})
        self._body = [(di, dj, c) for di in range(-r, r + 1) for dj in range(-r, r + 1)
                      if (di, dj) != (0, 0) and di * di + dj * dj <= r * r for c in layers]
        self.max_dz = max(1, int(math.floor(self.max_step_m / vox + 1e-9)))
        steps = range(-self.max_dz, self.max_dz + 1)
        self._offsets = [(di, dj, dz) for di, dj in _NEIGHBOURS_8 if (di, dj) > (0, 0) for dz in steps]
        self._sides = [(di, dj, dz) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)) for dz in steps]
        b, search = inclination_reach(vox, self.max_inclination_deg, self.inclination_baseline_m)
        self._slope = [(di, dj, dz) for di, dj in ((b, 0), (-b, 0), (0, b), (0, -b)) for dz in range(-search, search + 1)]

    # -- the rules of legged_graph, per voxel ---------------------------------------------
    def _standable(self, occ: np.ndarray, q: Voxels) -> np.ndarray:
        """Which ``q`` voxels (free) stand on ground, or where the voxel below is unknown,
        beside ground at the same height, and have headroom (as legged_graph)."""
        below = q.at(occ, (0, 0, -1), UNKNOWN)
        stand = below == OCCUPIED
        unknown = np.flatnonzero(below == UNKNOWN)
        beside = np.zeros(len(unknown), dtype=bool)
        for d in self._disc:
            beside |= q.at(self.ground, d, 0, unknown) > 0
        stand[unknown[beside]] = True
        for c in range(1, self.n_up + 1):
            stand &= q.at(occ, (0, 0, c), OCCUPIED) != OCCUPIED
        return stand

    def _nodes(self, occ: np.ndarray, q: Voxels) -> np.ndarray:
        """Which ``q`` voxels (standable) are nodes: gentle ground, no rock by the body."""
        keep = inclination_among(q, self.standable, self._vox, self.max_inclination_deg,
                                 self.inclination_baseline_m) <= self.max_inclination_deg
        for d in self._body:
            keep &= q.at(occ, d, OCCUPIED) != OCCUPIED
        return keep

    def _edges_from(self, q: Voxels) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Edges (source flat, target flat, length) from the ``q`` voxels (nodes), as
        :func:`delve.planners.navgraph._graph` makes them with ``side_steps``."""
        sides: dict[tuple[int, int], np.ndarray] = {}

        def beside(di: int, dj: int) -> np.ndarray:
            if (di, dj) not in sides:
                sides[(di, dj)] = np.logical_or.reduce(
                    [q.at(self.node, (di, dj, dz), 0) > 0 for dz in range(-self.max_dz, self.max_dz + 1)])
            return sides[(di, dj)]

        src, dst, w = [], [], []
        ny, nz = self._shape[1], self._shape[2]
        for d in self._offsets:
            ok = q.at(self.node, d, 0) > 0
            if d[0] and d[1]:
                ok &= beside(d[0], 0) & beside(0, d[1])
            s = q.flat[ok]
            src.append(s)
            dst.append(s + (d[0] * ny + d[1]) * nz + d[2])
            w.append(np.full(len(s), self._vox * math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)))
        return np.concatenate(src), np.concatenate(dst), np.concatenate(w)

    # -- updates ------------------------------------------------------------------------------
    def update(self, grid: Grid, changed: np.ndarray | None = None) -> NavGraph:
        """The graph of ``grid`` after the voxels ``changed`` (flat indices) changed since
        the last update; from every known voxel when ``changed`` is None or on the first
        update (or for a grid of another shape)."""
        occ, changed, rock = self._changes(grid, changed)
        sh = self._shape
        ground = around(changed, sh, [(0, 0, 0), (0, 0, 1)])
        q = Voxels(ground, sh)
        ground = _store(self.ground, ground, (occ[ground] == FREE) & (q.at(occ, (0, 0, -1), UNKNOWN) == OCCUPIED))
        stand = distinct(sh, np.concatenate([around(changed, sh, [(0, 0, 0), (0, 0, 1)]), around(ground, sh, self._disc),
                                             around(rock, sh, [(0, 0, -c) for c in range(1, self.n_up + 1)])]))
        stand = _store(self.standable, stand, self._where_free(occ, stand, self._standable))
        node = distinct(sh, np.concatenate([around(stand, sh, [(0, 0, 0)] + _negated(self._slope)),
                                            around(rock, sh, _negated(self._body))]))
        node = _store(self.node, node, self._where_free(occ, node, self._nodes, among=self.standable))
        sources = around(node, sh, [(0, 0, 0)] + _negated(self._offsets + self._sides))
        self._edges = _renewed(self._edges, sources, self._edges_from(Voxels(sources[self.node[sources] > 0], sh)),
                               len(self.node))
        return _numbered(grid, self.node, self._edges, self.body_height_m - 0.5 * self._vox)

    def _where_free(self, occ: np.ndarray, flat: np.ndarray, rule, among: np.ndarray | None = None) -> np.ndarray:
        """A rule's conclusion for the voxels ``flat``: False where a voxel is not free (or
        not in ``among``), else the rule's."""
        out = occ[flat] == FREE
        if among is not None:
            out &= among[flat] > 0
        out[out] = rule(occ, Voxels(flat[out], self._shape))
        return out


class AerialGraphUpdater(_Updater):
    """The aerial navigation graph of one map (:func:`delve.planners.navgraph.aerial_graph`
    with its parameters), updated from its changed voxels. A node is a free voxel of the
    lattice with no rock within the robot's radius: only voxels that turned free or not
    free, and the lattice voxels within the radius of voxels that turned rock or not rock,
    are tested again. Memory: two bytes per voxel of the grid (zero-filled) and the edges."""

    def __init__(self, *, radius_m: float, stride: int = 2):
        self.radius_m, self.stride = radius_m, stride

    def _setup(self, grid: Grid) -> None:
        """The rules' offsets for this grid's voxel size, and the state of an unknown map."""
        size, s = int(np.prod(grid.shape)), self.stride
        self._shape, self._vox = grid.shape, grid.voxel_size_m
        self.rock, self.node = np.zeros(size, np.uint8), np.zeros(size, np.uint8)
        self._edges = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
        self._ball = _ball(max(1, math.ceil(self.radius_m / grid.voxel_size_m)))
        self._offsets = [(a * s, b * s, c * s) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
                         if (a, b, c) > (0, 0, 0)]

    def update(self, grid: Grid, changed: np.ndarray | None = None) -> NavGraph:
        """The graph of ``grid`` after the voxels ``changed`` (flat indices) changed since
        the last update; from every known voxel when ``changed`` is None or on the first
        update (or for a grid of another shape)."""
        occ, changed, rock = self._changes(grid, changed)
        sh = self._shape
        test = distinct(sh, np.concatenate([self._on_lattice(changed), self._lattice_around(rock)]))
        node = _store(self.node, test, self._is_node(occ, test))
        sources = around(node, sh, [(0, 0, 0)] + _negated(self._offsets))
        self._edges = _renewed(self._edges, sources, self._edges_from(Voxels(sources[self.node[sources] > 0], sh)),
                               len(self.node))
        return _numbered(grid, self.node, self._edges)

    def _on_lattice(self, flat: np.ndarray) -> np.ndarray:
        ijk = np.unravel_index(flat, self._shape)
        return flat[(ijk[0] % self.stride == 0) & (ijk[1] % self.stride == 0) & (ijk[2] % self.stride == 0)]

    def _lattice_around(self, flat: np.ndarray) -> np.ndarray:
        """The lattice voxels within the radius of the voxels ``flat``: per class of a voxel's
        position on the lattice, only the offsets of the ball that land on it (an eighth of
        them for a stride of 2)."""
        s = self.stride
        ijk = np.stack(np.unravel_index(flat, self._shape), axis=1) % s
        parts = []
        for cls in np.unique(ijk, axis=0):
            offsets = [d for d in self._ball if all((c + o) % s == 0 for c, o in zip(cls, d))]
            if offsets:
                parts.append(around(flat[np.all(ijk == cls, axis=1)], self._shape, offsets))
        return np.concatenate(parts) if parts else np.zeros(0, np.int64)

    def _is_node(self, occ: np.ndarray, flat: np.ndarray) -> np.ndarray:
        """Which lattice voxels ``flat`` are nodes: free, with no rock (nor the grid's edge)
        within the radius."""
        out = occ[flat] == FREE
        q = Voxels(flat[out], self._shape)
        keep = np.ones(len(q), dtype=bool)
        for d in self._ball:
            keep &= q.at(occ, d, OCCUPIED) != OCCUPIED
        out[out] = keep
        return out

    def _edges_from(self, q: Voxels) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Edges (source flat, target flat, length) from the ``q`` voxels (nodes) to the
        nodes at the lattice offsets, as :func:`delve.planners.navgraph._graph` makes them."""
        src, dst, w = [], [], []
        ny, nz = self._shape[1], self._shape[2]
        for d in self._offsets:
            s = q.flat[q.at(self.node, d, 0) > 0]
            src.append(s)
            dst.append(s + (d[0] * ny + d[1]) * nz + d[2])
            w.append(np.full(len(s), self._vox * math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)))
        return np.concatenate(src), np.concatenate(dst), np.concatenate(w)


Edges = tuple[np.ndarray, np.ndarray, np.ndarray]


def _renewed(edges: Edges, sources: np.ndarray, new: Edges, size: int) -> Edges:
    """The edges (source flat, target flat, length, over a grid of ``size`` voxels) without
    those from ``sources``, and the ``new`` ones made from them."""
    src, dst, w = edges
    with _Lookup(size, sources) as redo:
        keep = redo[src] == 0
    return np.concatenate([src[keep], new[0]]), np.concatenate([dst[keep], new[1]]), np.concatenate([w[keep], new[2]])


def _numbered(grid: Grid, node: np.ndarray, edges: Edges, lift_m: float = 0.0) -> NavGraph:
    """The graph of the ``node`` voxels, numbered in the map's order of free voxels as the
    whole-map build numbers them, at their centres raised ``lift_m``, with the ``edges``."""
    free = grid.free_voxels()   # only the nodes' positions are needed, not Voxels of all free ones
    nodes = free[node[free] > 0]
    positions = grid.to_world(np.stack(np.unravel_index(nodes, grid.shape), axis=1))
    if lift_m:
        positions[:, 2] += lift_m
    n = len(nodes)
    with _Lookup(len(node), nodes) as ids:
        rows, cols = ids[edges[0]].astype(np.int64) - 1, ids[edges[1]].astype(np.int64) - 1
    return NavGraph(positions=positions, adjacency=csr_matrix((edges[2], (rows, cols)), shape=(n, n)))


def _store(state: np.ndarray, flat: np.ndarray, value: np.ndarray) -> np.ndarray:
    """Store a rule's conclusions for the voxels ``flat``; the voxels where they changed."""
    value = value.astype(np.uint8)
    changed = flat[state[flat] != value]
    state[flat] = value
    return changed


def _negated(offsets: list[tuple[int, int, int]]) -> list[tuple[int, int, int]]:
    """The voxels that look at a voxel through ``offsets`` lie at the negated offsets."""
    return [(-a, -b, -c) for a, b, c in offsets]
