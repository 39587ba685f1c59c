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

from .occupancy import OCCUPIED, UNKNOWN, Grid

FACES = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))
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
    """A reusable flat-index -> node id + 1 array (0: no node), reset after each use
    (O(nodes), not O(grid)). It starts zero-filled, so the operating system backs only
    the pages that ever held a node: on a large world it costs memory where the map
    has free voxels, not 4 bytes for every voxel of the grid."""

    _buffers: dict[int, np.ndarray] = {}

    def __init__(self, size: int, flat: np.ndarray):
        buf = self._buffers.get(size)
        if buf is None:
            buf = self._buffers[size] = np.zeros(size, dtype=np.int32)
        self.buf, self.flat = buf, flat
        buf[flat] = np.arange(1, len(flat) + 1)

    def __enter__(self) -> np.ndarray:
        return self.buf

    def __exit__(self, *exc: object) -> None:
        self.buf[self.flat] = 0


class Voxels:
    """A sparse set of voxels of a grid (flat indices) with fast neighbour look-ups.

    Each voxel's distance to the grid's boundary is computed once, so a look-up at an
    offset checks bounds only for the few voxels nearer the boundary than the offset.
    """

    def __init__(self, flat: np.ndarray, shape: tuple[int, int, int], ijk: np.ndarray | None = None,
                 margin: np.ndarray | None = None):
        self.flat, self.shape = flat, shape
        self.ijk = np.stack(np.unravel_index(flat, shape), axis=1) if ijk is None else ijk
        if margin is None:
            i, j, k = self.ijk.T
            nx, ny, nz = shape
            margin = np.minimum.reduce([i, j, k, nx - 1 - i, ny - 1 - j, nz - 1 - k]) if len(flat) else i
        self.margin = margin
        self._near: dict[int, np.ndarray] = {}

    _last_free: tuple[np.ndarray, "Voxels"] | None = None

    @classmethod
    def free_of(cls, grid: Grid) -> "Voxels":
        """The grid's FREE voxels. A map that keeps its free voxels only appends to
        them between scans, so the last result is reused and extended by the new tail."""
        flat = grid.free_voxels()
        last = cls._last_free
        if last is not None and last[0] is flat:
            return last[1]
        n = len(last[0]) if last is not None else 0
        if last is not None and last[1].shape == grid.shape and 0 < n <= len(flat) and np.array_equal(last[0], flat[:n]):
            tail = Voxels(flat[n:], grid.shape)
            old = last[1]
            voxels = Voxels(flat, grid.shape, np.concatenate([old.ijk, tail.ijk]), np.concatenate([old.margin, tail.margin]))
        else:
            voxels = Voxels(flat, grid.shape)
        cls._last_free = (flat, voxels)
        return voxels

    def __len__(self) -> int:
        return len(self.flat)

    def subset(self, mask: np.ndarray) -> "Voxels":
        """The voxels selected by a boolean mask or index array."""
        return Voxels(self.flat[mask], self.shape, self.ijk[mask], self.margin[mask])

    def _near_boundary(self, r: int) -> np.ndarray:
        if r not in self._near:
            self._near[r] = np.flatnonzero(self.margin < r)
        return self._near[r]

    def at(self, values: np.ndarray, d: tuple[int, int, int], outside: int, idx: np.ndarray | None = None) -> np.ndarray:
        """``values`` (a flat array over the grid) at offset ``d`` from each voxel, or
        from the voxels ``idx`` (positions in this set); ``outside`` beyond the grid."""
        step = (d[0] * self.shape[1] + d[1]) * self.shape[2] + d[2]
        r = max(abs(d[0]), abs(d[1]), abs(d[2]))
        flat = self.flat if idx is None else self.flat[idx]
        near = self._near_boundary(r) if idx is None else np.flatnonzero(self.margin[idx] < r)
        if len(near) == 0:
            return values[flat + step]
        target = flat + step
        target[near] = 0
        out = values[target]
        t = (self.ijk if idx is None else self.ijk[idx])[near] + np.array(d)
        ok = np.all((t >= 0) & (t < np.array(self.shape)), axis=1)
        out[near] = outside
        out[near[ok]] = values[flat[near[ok]] + step]
        return out


def around(flat: np.ndarray, shape: tuple[int, int, int], offsets: list[tuple[int, int, int]]) -> np.ndarray:
    """The distinct voxels (flat indices, inside the grid of ``shape``) at ``offsets``
    from the voxels ``flat``: where a change to those voxels can be seen from."""
    v = Voxels(flat, shape)
    step = np.array([shape[1] * shape[2], shape[2], 1])
    parts = []
    for d in offsets:
        target = v.flat + int(np.dot(d, step))
        near = np.flatnonzero(v.margin < max(abs(d[0]), abs(d[1]), abs(d[2])))
        if len(near):
            t = v.ijk[near] + np.array(d)
            target = np.delete(target, near[~np.all((t >= 0) & (t < np.array(shape)), axis=1)])
        parts.append(target)
    return distinct(shape, np.concatenate(parts)) if parts else flat


def distinct(shape: tuple[int, int, int], flat: np.ndarray) -> np.ndarray:
    """The distinct values of ``flat`` (flat indices of a grid of ``shape``), each once,
    unsorted: a scatter and a gather on the shared lookup, several times faster than
    ``np.unique``'s sorting or hashing on tens of thousands of indices."""
    with _Lookup(int(np.prod(shape)), flat) as at:
        return flat[at[flat] == np.arange(1, len(flat) + 1)]


def legged_graph(
    grid: Grid,
    *,
    body_height_m: float,
    radius_m: float,
    max_step_m: float,
    max_inclination_deg: float,
    headroom_m: float | None = None,
    inclination_baseline_m: float = 0.6,
    ground_inference_radius_m: float = 1.0,
) -> NavGraph:
    """Graph of standable voxels, 8-connected horizontally with steps up to ``max_step_m``.

    A voxel is standable when it is known FREE, stands on ground, has no rock in the
    ``headroom_m`` above it (default: body height + 0.2 m) and none within
    ``radius_m`` horizontally at body height. Ground is rock seen directly below, or,
    where the voxel below was never hit (a spinning LiDAR sees the floor only on rings
    of its lower beams), ground seen at the same height within
    ``ground_inference_radius_m``. The ground inclination is estimated by central
    differences of standable heights ``inclination_baseline_m`` apart.
    """
    vox = grid.voxel_size_m
    flat_occ = grid.occupancy.reshape(-1)
    free = Voxels.free_of(grid)

    below = free.at(flat_occ, (0, 0, -1), UNKNOWN)
    on_rock = below == OCCUPIED
    stand = on_rock
    if ground_inference_radius_m > 0 and on_rock.any():
        unknown = np.flatnonzero(below == UNKNOWN)
        near = _same_height_near(free.ijk[on_rock], free.ijk[unknown], ground_inference_radius_m / vox)
        stand = on_rock.copy()
        stand[unknown[near]] = True
    cand = free.subset(stand)
    headroom = body_height_m + 0.2 if headroom_m is None else headroom_m
    n_up = max(1, math.ceil(headroom / vox) - 1)
    ok = np.ones(len(cand), dtype=bool)
    for c in range(1, n_up + 1):
        ok &= cand.at(flat_occ, (0, 0, c), OCCUPIED) != OCCUPIED
    cand = cand.subset(ok)
    keep = _inclination_deg(cand, vox, max_inclination_deg, inclination_baseline_m) <= max_inclination_deg
    r = max(1, int(round(radius_m / vox)))
    layers = sorted({1, max(1, n_up // 2), n_up})
    for di in range(-r, r + 1):
        for dj in range(-r, r + 1):
            if (di, dj) == (0, 0) or di * di + dj * dj > r * r:
                continue
            for c in layers:
                keep &= cand.at(flat_occ, (di, dj, c), OCCUPIED) != OCCUPIED
    nodes = cand.subset(keep)
    positions = grid.to_world(nodes.ijk)
    positions[:, 2] += body_height_m - 0.5 * vox
    max_dz = max(1, int(math.floor(max_step_m / vox + 1e-9)))
    offsets = [(di, dj, dz) for di, dj in _NEIGHBOURS_8 if (di, dj) > (0, 0) for dz in range(-max_dz, max_dz + 1)]
    return _graph(nodes, positions, offsets, vox, side_steps=max_dz)


def _same_height_near(ground: np.ndarray, query: np.ndarray, radius_cells: float) -> np.ndarray:
    """Which ``query`` voxels have a ``ground`` voxel at the same height within
    ``radius_cells`` horizontally (heights are scaled apart so they never match)."""
    if len(query) == 0:
        return np.zeros(0, dtype=bool)
    scale = np.array([1.0, 1.0, 10.0 * (radius_cells + 1)])
    d, _ = cKDTree(ground * scale).query(query * scale, distance_upper_bound=radius_cells + 1e-9)
    return np.isfinite(d)


def _inclination_deg(cand: Voxels, vox: float, limit_deg: float, baseline_m: float) -> np.ndarray:
    """Ground inclination at each standable voxel from neighbours ``baseline_m`` away."""
    with _Lookup(int(np.prod(cand.shape)), cand.flat) as ids:
        return inclination_among(cand, ids, vox, limit_deg, baseline_m)


def inclination_reach(vox: float, limit_deg: float, baseline_m: float) -> tuple[int, int]:
    """How far (voxels: horizontally, vertically) :func:`inclination_among` looks."""
    b = max(1, int(round(baseline_m / vox)))
    return b, max(2, math.ceil(b * math.tan(math.radians(min(limit_deg + 15, 80)))))


def inclination_among(query: Voxels, standable: np.ndarray, vox: float, limit_deg: float,
                      baseline_m: float) -> np.ndarray:
    """Ground inclination at each ``query`` voxel from the standable voxels (nonzero in
    ``standable``, a flat array over the grid) ``baseline_m`` away."""
    b, search = inclination_reach(vox, limit_deg, baseline_m)
    heights = {}
    for di, dj in ((b, 0), (-b, 0), (0, b), (0, -b)):
        h = np.full(len(query), np.nan)
        for dz in sorted(range(-search, search + 1), key=abs):
            hit = (query.at(standable, (di, dj, dz), 0) > 0) & np.isnan(h)
            h[hit] = dz
        heights[(di, dj)] = h
    grads = []
    for plus, minus in (((b, 0), (-b, 0)), ((0, b), (0, -b))):
        hp, hm = heights[plus], heights[minus]
        g = np.where(np.isnan(hp) | np.isnan(hm), np.nan, (hp - hm) / (2 * b))
        g = np.where(np.isnan(g) & ~np.isnan(hp), hp / b, g)
        g = np.where(np.isnan(g) & ~np.isnan(hm), -hm / b, g)
        grads.append(np.nan_to_num(g))
    return np.degrees(np.arctan(np.hypot(grads[0], grads[1])))


def aerial_graph(grid: Grid, *, radius_m: float, stride: int = 2) -> NavGraph:
    """Graph of known-free voxels on a lattice of every ``stride``-th voxel, 26-connected,
    keeping only those with no rock within ``radius_m`` (the robot's body), so a flying
    robot passes squeezes just wider than itself."""
    flat_occ = grid.occupancy.reshape(-1)
    free = Voxels.free_of(grid)
    on_lattice = np.all(free.ijk % stride == 0, axis=1)
    nodes = free.subset(on_lattice)
    r = max(1, math.ceil(radius_m / grid.voxel_size_m))
    keep = np.ones(len(nodes), dtype=bool)
    for d in _ball(r):
        keep &= nodes.at(flat_occ, d, OCCUPIED) != OCCUPIED
    nodes = nodes.subset(keep)
    positions = grid.to_world(nodes.ijk)
    offsets = [(a * stride, b * stride, c * stride) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
               if (a, b, c) > (0, 0, 0)]
    return _graph(nodes, positions, offsets, grid.voxel_size_m)


def _ball(r: int) -> list[tuple[int, int, int]]:
    """Offsets within ``r`` voxels of the origin, the origin excluded."""
    span = range(-r, r + 1)
    return [(a, b, c) for a in span for b in span for c in span if 0 < a * a + b * b + c * c <= r * r]


def _graph(nodes: Voxels, positions: np.ndarray, offsets: list[tuple[int, int, int]], cell_m: float,
           side_steps: int | None = None) -> NavGraph:
    """Connect nodes to the nodes at ``offsets`` (each undirected edge once).

    With ``side_steps``, a horizontal diagonal edge also needs a node beside it on
    both sides (within ``side_steps`` voxels of height), so that no edge cuts the
    corner of a wall or a ledge.
    """
    rows, cols, w = [], [], []
    with _Lookup(int(np.prod(nodes.shape)), nodes.flat) as ids:
        sides: dict[tuple[int, int], np.ndarray] = {}

        def beside(di: int, dj: int) -> np.ndarray:
            if (di, dj) not in sides:
                sides[(di, dj)] = np.logical_or.reduce(
                    [nodes.at(ids, (di, dj, dz), 0) > 0 for dz in range(-side_steps, side_steps + 1)])
            return sides[(di, dj)]

        for d in offsets:
            tgt = nodes.at(ids, d, 0).astype(np.int64) - 1
            ok = tgt >= 0
            if side_steps is not None and d[0] and d[1]:
                ok &= beside(d[0], 0) & beside(0, d[1])
            src = np.flatnonzero(ok)

            rows.append(src)
            cols.append(tgt[src])
            w.append(np.full(len(src), cell_m * math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)))

    n = len(positions)
    adj = csr_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    return NavGraph(positions=positions, adjacency=adj)
