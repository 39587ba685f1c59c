"""Navigation graphs over an occupancy grid, for path planning on the onboard map.

Legged robots walk on *standable* voxels (known free, rock below, headroom above,
no rock within the body radius, ground inclination within the limit); aerial robots
fly through blocks of known free voxels with a margin. Graphs are scipy sparse
matrices so that shortest paths use ``scipy.sparse.csgraph.dijkstra``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from .occupancy import FREE, OCCUPIED, UNKNOWN, Grid

_NEIGHBOURS_8 = [(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0)]


@dataclass
class NavGraph:
    """Nodes (positions of the robot's body centre) and a weighted sparse adjacency."""

    positions: np.ndarray
    adjacency: csr_matrix
    _tree: cKDTree | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def kdtree(self) -> cKDTree:
        if self._tree is None:
            self._tree = cKDTree(self.positions if len(self.positions) else np.zeros((0, 3)))
        return self._tree

    def nearest(self, point: np.ndarray, max_distance_m: float) -> int | None:
        """Index of the node nearest to ``point`` within ``max_distance_m``, or None."""
        if len(self) == 0:
            return None
        d, i = self.kdtree.query(np.asarray(point, float), distance_upper_bound=max_distance_m)
        return None if not np.isfinite(d) else int(i)

    def shortest_paths(self, source: int) -> tuple[np.ndarray, np.ndarray]:
        """Distances (m) and predecessors of every node from ``source``."""
        dist, pred = dijkstra(self.adjacency, directed=False, indices=source, return_predecessors=True)
        return dist, pred

    def path(self, pred: np.ndarray, target: int) -> np.ndarray:
        """(N, 3) positions from the source of ``pred`` to ``target``."""
        nodes = [target]
        while pred[nodes[-1]] >= 0:
            nodes.append(int(pred[nodes[-1]]))
        return self.positions[nodes[::-1]]


class _Lookup:
    """A reusable flat-index -> node-id array, reset after each use (O(nodes), not O(grid))."""

    _buffers: dict[int, np.ndarray] = {}

    def __init__(self, size: int, flat: np.ndarray):
        buf = self._buffers.get(size)
        if buf is None:
            buf = self._buffers[size] = np.full(size, -1, dtype=np.int64)
        self.buf, self.flat = buf, flat
        buf[flat] = np.arange(len(flat))

    def __enter__(self) -> np.ndarray:
        return self.buf

    def __exit__(self, *exc: object) -> None:
        self.buf[self.flat] = -1


def _offset_ok(ijk: np.ndarray, d: tuple[int, int, int], shape: tuple[int, int, int]) -> np.ndarray:
    t = ijk + np.array(d)
    return np.all((t >= 0) & (t < np.array(shape)), axis=1)


def neighbour_values(
    flat_occ: np.ndarray,
    flat: np.ndarray,
    ijk: np.ndarray,
    d: tuple[int, int, int],
    shape: tuple[int, int, int],
    outside: int,
) -> np.ndarray:
    """Occupancy of the voxel at offset ``d`` from each voxel; ``outside`` beyond the grid."""
    ok = _offset_ok(ijk, d, shape)
    out = np.full(len(flat), outside, dtype=np.int8)
    step = (d[0] * shape[1] + d[1]) * shape[2] + d[2]
    out[ok] = flat_occ[flat[ok] + step]
    return out


def legged_graph(
    grid: Grid,
    *,
    body_height_m: float,
    radius_m: float,
    max_step_m: float,
    max_inclination_deg: float,
    headroom_m: float | None = None,
    inclination_baseline_m: float = 0.6,
) -> NavGraph:
    """Graph of standable voxels, 8-connected horizontally with steps up to ``max_step_m``.

    A voxel is standable when it is known FREE, has rock directly below, no rock in
    the ``headroom_m`` above it (default: body height + 0.2 m) and none within
    ``radius_m`` horizontally at body height. The ground inclination is estimated by
    central differences of standable heights ``inclination_baseline_m`` apart.
    """
    occ, shape, vox = grid.occupancy, grid.shape, grid.voxel_size_m
    flat_occ = occ.reshape(-1)
    free = np.flatnonzero(flat_occ == FREE)
    ijk = np.stack(np.unravel_index(free, shape), axis=1)
    below = neighbour_values(flat_occ, free, ijk, (0, 0, -1), shape, UNKNOWN)
    cand, cijk = free[below == OCCUPIED], ijk[below == OCCUPIED]
    headroom = body_height_m + 0.2 if headroom_m is None else headroom_m
    n_up = max(1, math.ceil(headroom / vox) - 1)
    ok = np.ones(len(cand), dtype=bool)
    for c in range(1, n_up + 1):
        ok &= neighbour_values(flat_occ, cand, cijk, (0, 0, c), shape, OCCUPIED) != OCCUPIED
    cand, cijk = cand[ok], cijk[ok]
    incline = _inclination_deg(cand, cijk, shape, vox, max_inclination_deg, inclination_baseline_m)
    keep = incline <= max_inclination_deg
    r = max(1, int(round(radius_m / vox)))
    layers = sorted({1, max(1, n_up // 2), n_up})
    for di in range(-r, r + 1):
        for dj in range(-r, r + 1):
            if (di, dj) == (0, 0) or di * di + dj * dj > r * r:
                continue
            for c in layers:
                keep &= neighbour_values(flat_occ, cand, cijk, (di, dj, c), shape, OCCUPIED) != OCCUPIED
    nodes, nijk = cand[keep], cijk[keep]
    positions = grid.to_world(nijk)
    positions[:, 2] += body_height_m - 0.5 * vox
    max_dz = max(1, int(math.floor(max_step_m / vox + 1e-9)))
    rows, cols, w = [], [], []
    with _Lookup(flat_occ.size, nodes) as ids:
        for di, dj in _NEIGHBOURS_8:
            if (di, dj) < (0, 0):
                continue  # each undirected edge once
            for dz in range(-max_dz, max_dz + 1):
                ok = _offset_ok(nijk, (di, dj, dz), shape)
                src = np.flatnonzero(ok)
                tgt = ids[nodes[src] + (di * shape[1] + dj) * shape[2] + dz]
                hit = tgt >= 0
                rows.append(src[hit])
                cols.append(tgt[hit])
                w.append(np.full(hit.sum(), vox * math.sqrt(di * di + dj * dj + dz * dz)))
    return _graph(positions, rows, cols, w)


def _inclination_deg(
    cand: np.ndarray,
    cijk: np.ndarray,
    shape: tuple[int, int, int],
    vox: float,
    limit_deg: float,
    baseline_m: float,
) -> np.ndarray:
    """Ground inclination at each standable voxel from neighbours ``baseline_m`` away."""
    b = max(1, int(round(baseline_m / vox)))
    search = max(2, math.ceil(b * math.tan(math.radians(min(limit_deg + 15, 80)))))
    heights = {}
    with _Lookup(int(np.prod(shape)), cand) as ids:
        for di, dj in ((b, 0), (-b, 0), (0, b), (0, -b)):
            h = np.full(len(cand), np.nan)
            for dz in sorted(range(-search, search + 1), key=abs):
                ok = _offset_ok(cijk, (di, dj, dz), shape) & np.isnan(h)
                src = np.flatnonzero(ok)
                hit = ids[cand[src] + (di * shape[1] + dj) * shape[2] + dz] >= 0
                h[src[hit]] = dz
            heights[(di, dj)] = h
    grads = []
    for plus, minus in (((b, 0), (-b, 0)), ((0, b), (0, -b))):
        hp, hm = heights[plus], heights[minus]
        g = np.where(np.isnan(hp) | np.isnan(hm), np.nan, (hp - hm) / (2 * b))
        g = np.where(np.isnan(g) & ~np.isnan(hp), hp / b, g)
        g = np.where(np.isnan(g) & ~np.isnan(hm), -hm / b, g)
        grads.append(np.nan_to_num(g))
    return np.degrees(np.arctan(np.hypot(grads[0], grads[1])))


def aerial_graph(grid: Grid, *, block: int = 2) -> NavGraph:
    """Graph of ``block``³ blocks of known free voxels, 26-connected, with a one-block
    margin to any rock, so a flying robot keeps clear of walls."""
    occ = grid.occupancy
    nb = tuple(s // block for s in occ.shape)
    cropped = occ[: nb[0] * block, : nb[1] * block, : nb[2] * block]
    blocks = cropped.reshape(nb[0], block, nb[1], block, nb[2], block)
    all_free = (blocks == FREE).all(axis=(1, 3, 5))
    any_rock = (blocks == OCCUPIED).any(axis=(1, 3, 5))
    flat_free = np.flatnonzero(all_free)
    ijk = np.stack(np.unravel_index(flat_free, nb), axis=1)
    rock = any_rock.reshape(-1).astype(np.int8)
    keep = np.ones(len(flat_free), dtype=bool)
    for d in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)):
        keep &= neighbour_values(rock, flat_free, ijk, d, nb, 1) == 0
    nodes, nijk = flat_free[keep], ijk[keep]
    positions = grid.origin + (nijk + 0.5) * block * grid.voxel_size_m
    rows, cols, w = [], [], []
    offsets = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) > (0, 0, 0)]
    with _Lookup(int(np.prod(nb)), nodes) as ids:
        for d in offsets:
            ok = _offset_ok(nijk, d, nb)
            src = np.flatnonzero(ok)
            tgt = ids[nodes[src] + (d[0] * nb[1] + d[1]) * nb[2] + d[2]]
            hit = tgt >= 0
            rows.append(src[hit])
            cols.append(tgt[hit])
            w.append(np.full(hit.sum(), block * grid.voxel_size_m * math.sqrt(sum(x * x for x in d))))
    return _graph(positions, rows, cols, w)


def _graph(positions: np.ndarray, rows: list, cols: list, w: list) -> NavGraph:
    n = len(positions)
    r = np.concatenate(rows) if rows else np.zeros(0, int)
    c = np.concatenate(cols) if cols else np.zeros(0, int)
    v = np.concatenate(w) if w else np.zeros(0)
    adj = csr_matrix((v, (r, c)), shape=(n, n))
    return NavGraph(positions=positions, adjacency=adj)
