"""The COPS topology of a voxel map kept up to date from the voxels that changed.

:func:`delve.planners.cops.extraction.extract_topology` labels the components of every
lattice cell, finds where components of neighbouring cells touch, tests every layer
for open space and picks every location's position, over the whole known map, each
time. All of it but the last, small steps is local:

* A cell's components, its location and the location's position depend only on which
  of the cell's voxels are free and standable. :class:`ExtractionUpdater` labels again
  only the cells where that changed (each on its own: a component lies within one
  cell) and keeps the other cells' labels; components are numbered across the map.
* Components touch only across cell boundaries, so only the boundary voxels of the
  cells labelled again are looked at for touching pairs; the other pairs are kept.
* A voxel is open only within ``open_radius_m`` of a *centre* of open space: a free
  voxel whose disc of that radius in its layer is all free
  (:func:`delve.planners.cops.regions.open_space`). A centre has free voxels at eight
  points of its disc, the *probes*; the voxels that pass the probes are kept up to
  date from the changed voxels (a voxel's result changes only when it or one of its
  probes changes), and ``open_space`` runs only on their box widened by the disc
  (beyond it no voxel is open), again only when a voxel in that box has changed. In
  a mine of tunnels narrower than the disc no voxel passes and nothing runs.
* The frontier voxels come from a
  :class:`~delve.planners.frontier_incremental.FrontierUpdater`.
* The rest (locations in the lattice's order, edges through fragments that are no
  location, regions, lines of sight) is the full extraction's own code, on as few
  rows as there are locations and touching components.

The result equals ``extract_topology``'s exactly (names, positions, explored flags,
edges and lengths, regions) given the same standable voxels and all known-free voxels
as passable (as :class:`delve.skills.cops.voxel_view.VoxelNetworkView` calls it). Two
things are taken from the whole map as the full extraction takes them, so that the
floating-point numbers are the same: the box of the known-free voxels (the full
extraction's world coordinates are counted from its corner) and the lattice index of
each layer of voxels; where a layer's index would differ from the one computed from
the map's own corner (a voxel centre on a cell boundary, to the last bit), the update
is the full extraction and the next one starts afresh.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..frontier_incremental import FrontierUpdater
from ..navgraph import Voxels, around, distinct
from ..occupancy import FREE, OCCUPIED, Grid
from .extraction import (
    _CONNECTIVITY_26,
    _HALF_NEIGHBOURS_26,
    DEFAULT_CELL_M,
    DEFAULT_COMM_RANGE_M,
    DEFAULT_MIN_FREE_VOXELS,
    _check_parameters,
    _checked_point,
    _crop,
    _mobility_pairs,
    _network,
    _pack,
    _partition,
    _position_voxels,
    _unpack,
    _visited_cells,
    extract_topology,
)
from .regions import DEFAULT_MAX_REGION_M, DEFAULT_OPEN_RADIUS_M, open_faces, open_space
from .topology import Topology

#: The 26 neighbours of a voxel.
_NEIGHBOURS_26 = _HALF_NEIGHBOURS_26 + [(-a, -b, -c) for a, b, c in _HALF_NEIGHBOURS_26]


@dataclass
class _Cell:
    """A lattice cell's part of the map: the box of its free voxels (global voxel
    indices), its components' numbers, its main component's if that is a location
    (else -1) and the voxel of the location's position."""

    box: tuple[slice, slice, slice]
    ids: np.ndarray
    main: int
    spot: np.ndarray | None


class ExtractionUpdater:
    """The COPS topology of one map (:func:`~delve.planners.cops.extraction.extract_topology`),
    updated from its changed voxels.

    Takes the parameters of ``extract_topology`` that stay fixed over a mission. Memory:
    per voxel of the grid, four bytes of component labels and three one-byte flags
    (standable, probes passed, frontier), zero-filled, so only the pages around the
    mapped space are backed.
    """

    def __init__(self, *, cell_m: float = DEFAULT_CELL_M, comm_range_m: float = DEFAULT_COMM_RANGE_M,
                 min_free_voxels: int = DEFAULT_MIN_FREE_VOXELS, sight_height_m: float = 0.0,
                 lattice_origin: np.ndarray | None = None,
                 open_radius_m: float | None = DEFAULT_OPEN_RADIUS_M,
                 max_region_m: float = DEFAULT_MAX_REGION_M):
        _check_parameters(cell_m, comm_range_m, min_free_voxels, sight_height_m, open_radius_m, max_region_m)
        self.cell_m, self.comm_range_m, self.min_free_voxels = cell_m, comm_range_m, min_free_voxels
        self.sight_height_m, self.corner = sight_height_m, _checked_point(lattice_origin, "lattice_origin")
        self.open_radius_m, self.max_region_m = open_radius_m, max_region_m
        self._key: tuple | None = None

    def _setup(self, grid: Grid) -> None:
        """Empty state (that of a map with no free voxel) for this grid's geometry."""
        size = int(np.prod(grid.shape))
        self._key = (grid.shape, tuple(grid.origin.tolist()), grid.voxel_size_m)
        self._partition = _partition(grid, self.cell_m, self.corner)
        #: Per voxel: its component's number + 1 (0: not free), standable, passes the probes.
        self._labels = np.zeros(size, np.int32)
        self._standable, self._probed = np.zeros(size, np.uint8), np.zeros(size, np.uint8)
        self._standable_flat = self._probed_flat = np.zeros(0, np.int64)
        self._frontier = FrontierUpdater()
        self._cells: dict[tuple[int, int, int], _Cell] = {}
        self._count = 0
        self._touching = np.zeros((0, 2), np.int64)
        self._open_box: tuple[slice, ...] | None = None
        self._open_mask = self._open_pairs = None
        if self.open_radius_m is not None:
            self._probes = _probes(self.open_radius_m / grid.voxel_size_m)
            self._probed_by = [(0, 0, 0)] + [(-a, -b, -c) for a, b, c in self._probes]

    # -- updates ------------------------------------------------------------------------------
    def update(self, grid: Grid, changed: np.ndarray | None = None, *, standable: np.ndarray | None = None,
               visited: np.ndarray | None = None, prior: dict[str, str] | None = None,
               keep: tuple[str, ...] | list[str] = ()) -> Topology:
        """The topology of ``grid`` after the voxels ``changed`` (flat indices) changed
        since the last update; from the whole map when ``changed`` is None, on the first
        update, or for a grid of another shape or placement.

        ``standable`` are the flat indices (distinct) of the free voxels a robot stands on
        (None: every free voxel); ``visited``, ``prior`` and ``keep`` as for
        ``extract_topology``, which this equals with ``standable`` as a mask and
        ``passable`` every known-free voxel."""
        visited_cells = _visited_cells(visited, self.cell_m, self.corner)
        key = (grid.shape, tuple(np.asarray(grid.origin, float).tolist()), grid.voxel_size_m)
        first = changed is None or key != self._key
        if first:
            self._setup(grid)
            changed = grid.free_voxels()
        changed = np.asarray(changed, dtype=np.int64)
        occ = grid.occupancy.reshape(-1)
        flipped = changed[(occ[changed] == FREE) != (self._labels[changed] > 0)]
        stand = grid.free_voxels() if standable is None else np.asarray(standable, dtype=np.int64)
        dirty = self._cells_of(np.concatenate([flipped, self._set_standable(stand)]))
        frontiers = self._frontier.update(grid, None if first else changed)
        if self.open_radius_m is not None:
            self._update_probes(grid, flipped, first)
        boxes = {c: self._free_box(grid, c) for c in dirty}
        dropped = [self._cells.pop(c) for c in dirty if c in self._cells]
        for c in dropped:
            self._labels.reshape(grid.shape)[c.box] = 0
        kept = [c.box for c in self._cells.values()]
        found = [b for b in boxes.values() if b is not None]
        if not kept and not found:
            self._touching = np.zeros((0, 2), np.int64)
            return Topology()
        lo = np.min([[s.start for s in b] for b in kept + found], axis=0)
        hi = np.max([[s.stop - 1 for s in b] for b in kept + found], axis=0)
        crop, box = _crop(grid, lo.tolist(), hi.tolist())
        if any(not np.array_equal(a, p[b]) for a, p, b in
               zip(_partition(crop, self.cell_m, self.corner), self._partition, box)):
            self._key = None
            return self._full(grid, stand, visited, prior, keep)
        for cell, b in boxes.items():
            if b is not None:
                self._cells[cell] = self._label(grid, crop, box, cell, b)
        gone = np.concatenate([c.ids for c in dropped]) if dropped else np.zeros(0, np.int64)
        self._touching = self._touching_pairs(grid, gone, [c for c in boxes if boxes[c] is not None])
        return self._topology(grid, crop, box, frontiers, visited_cells, flipped, bool(dirty), prior, keep)

    def _full(self, grid: Grid, stand: np.ndarray, visited: np.ndarray | None, prior: dict[str, str] | None,
              keep: tuple[str, ...] | list[str]) -> Topology:
        """``extract_topology`` of the whole map, with this updater's parameters."""
        mask = np.zeros(grid.shape, dtype=bool)
        mask.reshape(-1)[stand] = True
        return extract_topology(grid.occupancy, grid.origin, grid.voxel_size_m, standable=mask,
                                passable=grid.occupancy == FREE, free=grid.free_voxels(), cell_m=self.cell_m,
                                comm_range_m=self.comm_range_m, min_free_voxels=self.min_free_voxels,
                                sight_height_m=self.sight_height_m, visited=visited,
                                lattice_origin=self.corner, open_radius_m=self.open_radius_m,
                                max_region_m=self.max_region_m, prior=prior, keep=keep)

    def _set_standable(self, flat: np.ndarray) -> np.ndarray:
        """Store the standable voxels ``flat`` (distinct); the voxels that became or
        stopped being standable."""
        mark, old = self._standable, self._standable_flat
        added = flat[mark[flat] == 0]
        mark[flat] = 2
        removed = old[mark[old] == 1]
        mark[removed] = 0
        mark[flat] = 1
        self._standable_flat = flat
        return np.concatenate([added, removed])

    def _cells_of(self, flat: np.ndarray) -> list[tuple[int, int, int]]:
        """The distinct lattice cells (in lattice order) of the voxels ``flat``."""
        ijk = np.unravel_index(flat, self._key[0])
        cells = np.stack([p[i] for p, i in zip(self._partition, ijk)], axis=1)
        keys = np.unique(_pack(cells, self._partition))
        return [tuple(c) for c in _unpack(keys, self._partition).tolist()]

    def _cell_box(self, cell: tuple[int, int, int]) -> tuple[slice, ...]:
        """The box of a lattice cell's voxels in the grid."""
        return tuple(slice(int(np.searchsorted(p, c, "left")), int(np.searchsorted(p, c, "right")))
                     for p, c in zip(self._partition, cell))

    def _free_box(self, grid: Grid, cell: tuple[int, int, int]) -> tuple[slice, ...] | None:
        """The box of a cell's free voxels (None when it has none)."""
        box = self._cell_box(cell)
        free = grid.occupancy[box] == FREE
        if not free.any():
            return None
        out = []
        for axis, s in enumerate(box):
            on = np.flatnonzero(free.any(axis=tuple(a for a in range(3) if a != axis)))
            out.append(slice(s.start + int(on[0]), s.start + int(on[-1]) + 1))
        return tuple(out)

    # -- a cell's components and location -----------------------------------------------------
    def _label(self, grid: Grid, crop: Grid, box: tuple[slice, ...], cell: tuple[int, int, int],
               free_box: tuple[slice, ...]) -> _Cell:
        """Label the cell's free voxels (in ``free_box``) as components, store their
        numbers, and find its location: its main component (the most standable voxels,
        equal counts to the first in the grid's order, as ``extract_topology`` labels)
        if that has ``min_free_voxels`` of them, and the position's voxel among them."""
        local, n = ndimage.label(grid.occupancy[free_box] == FREE, structure=_CONNECTIVITY_26)
        ids = np.arange(self._count, self._count + n)
        self._count += n
        self._labels.reshape(grid.shape)[free_box] = np.where(local > 0, local + ids[0], 0)
        stands = (self._standable.reshape(grid.shape)[free_box] > 0) & (local > 0)
        size = np.bincount(local[stands], minlength=n + 1)[1:]
        best = int(np.argmax(size))
        if size[best] < self.min_free_voxels:
            return _Cell(free_box, ids, -1, None)
        at = np.argwhere(stands & (local == best + 1)) + [s.start for s in free_box]
        world = crop.to_world(at - [s.start for s in box])
        centre = self.corner + (np.array(cell) + 0.5) * self.cell_m
        spot = at[_position_voxels(world, np.zeros(len(at), np.int64), centre[None])[0]]
        return _Cell(free_box, ids, int(ids[best]), spot)

    def _touching_pairs(self, grid: Grid, gone: np.ndarray,
                        labelled: list[tuple[int, int, int]]) -> np.ndarray:
        """The touching pairs of components (sorted rows, as ``_touching_components``):
        those kept (of neither ``gone`` component) and those of the voxels on the
        boundaries of the ``labelled`` cells with their 26 neighbours."""
        kept = self._touching[~np.isin(self._touching, gone).any(axis=1)]
        edge = []
        for cell in labelled:
            free_box, cell = self._cells[cell].box, self._cell_box(cell)
            ijk = np.argwhere(self._labels.reshape(grid.shape)[free_box] > 0) + [s.start for s in free_box]
            rim = np.any((ijk == [s.start for s in cell]) | (ijk == [s.stop - 1 for s in cell]), axis=1)
            edge.append(np.ravel_multi_index(tuple(ijk[rim].T), grid.shape))
        v = Voxels(np.concatenate(edge) if edge else np.zeros(0, np.int64), grid.shape)
        mine = self._labels[v.flat].astype(np.int64) - 1
        keys = [kept[:, 0] * self._count + kept[:, 1]]
        for d in _NEIGHBOURS_26:
            other = v.at(self._labels, d, 0).astype(np.int64) - 1
            hit = (other >= 0) & (other != mine)
            keys.append(np.minimum(mine[hit], other[hit]) * self._count + np.maximum(mine[hit], other[hit]))
        keys = np.unique(np.concatenate(keys))   # pairs as one number each: a 1-D unique is the fast one
        return np.stack([keys // self._count, keys % self._count], axis=1)

    # -- open space -----------------------------------------------------------------------------
    def _update_probes(self, grid: Grid, flipped: np.ndarray, first: bool) -> None:
        """Keep the voxels that pass the probes: a voxel that became free, or a voxel of
        whose probes one did, is tested; one of whose probes stopped being free fails."""
        occ, shape = grid.occupancy.reshape(-1), grid.shape
        free = occ[flipped] == FREE
        if not free.all():
            self._probed[around(flipped[~free], shape, self._probed_by)] = 0
        came = Voxels(grid.free_voxels() if first else flipped[free], shape)
        test, step = [], [shape[1] * shape[2], shape[2], 1]
        for d in [(0, 0, 0)] if first else self._probed_by:   # the voxels whose probe a freed voxel is
            test.append(came.flat[came.at(occ, d, OCCUPIED) == FREE] + int(np.dot(d, step)))
        v = Voxels(np.concatenate(test), shape)
        idx = np.arange(len(v.flat))
        for d in self._probes:
            idx = idx[v.at(occ, d, OCCUPIED, idx) == FREE]
        self._probed[v.flat[idx]] = 1
        old = self._probed_flat
        self._probed_flat = distinct(shape, np.concatenate([old[self._probed[old] > 0], v.flat[idx]]))

    def _opened(self, grid: Grid, flipped: np.ndarray, relabelled: bool) -> np.ndarray:
        """Pairs of components that touch across a vertical face between open voxels (as
        ``open_faces`` on the whole map): ``open_space`` on the box of the voxels that
        pass the probes, widened by the disc, if a voxel in it changed since the last
        time, else the last result; the pairs again when it or any labels changed."""
        if len(self._probed_flat) == 0:
            self._open_box = None
            return np.zeros((0, 2), np.int64)
        ijk = np.stack(np.unravel_index(self._probed_flat, grid.shape), axis=1)
        reach = math.ceil(self.open_radius_m / grid.voxel_size_m) + 1
        lo, hi = ijk.min(axis=0), ijk.max(axis=0) + 1
        box = tuple(slice(max(0, int(lo[a]) - reach), min(n, int(hi[a]) + reach))
                    for a, n in enumerate(grid.shape[:2])) + (slice(int(lo[2]), int(hi[2])),)
        at = np.stack(np.unravel_index(flipped, grid.shape), axis=1)
        inside = np.all((at >= [s.start for s in box]) & (at < [s.stop for s in box]), axis=1)
        if box != self._open_box or inside.any():
            self._open_mask = open_space(grid.occupancy[box] == FREE, grid.voxel_size_m, self.open_radius_m)
        elif not relabelled:
            return self._open_pairs
        self._open_box = box
        self._open_pairs = open_faces(self._labels.reshape(grid.shape)[box],
                                      [p[s] for p, s in zip(self._partition, box)], self._open_mask)
        return self._open_pairs

    # -- the topology -----------------------------------------------------------------------------
    def _topology(self, grid: Grid, crop: Grid, box: tuple[slice, ...], frontiers: np.ndarray,
                  visited_cells: set[tuple[int, int, int]], flipped: np.ndarray, relabelled: bool,
                  prior: dict[str, str] | None, keep: tuple[str, ...] | list[str]) -> Topology:
        """The locations in the lattice's order, their positions (counted from the
        crop's corner, as ``extract_topology`` does), explored flags and edges, and
        the rest by ``extract_topology``'s own steps."""
        opened = self._opened(grid, flipped, relabelled) if self.open_radius_m is not None else None
        cells = sorted(c for c, v in self._cells.items() if v.main >= 0)
        if not cells:
            return Topology()
        lattice = np.array(cells, dtype=np.int64)
        location_of = np.full(self._count, -1, dtype=np.int64)
        location_of[[self._cells[c].main for c in cells]] = np.arange(len(cells))
        spots = np.array([self._cells[c].spot for c in cells])
        positions = crop.to_world(spots - [s.start for s in box])
        ijk = np.unravel_index(frontiers, grid.shape)
        frontier_keys = _pack(np.stack([p[i] for p, i in zip(self._partition, ijk)], axis=1), self._partition)
        explored = ~np.isin(_pack(lattice, self._partition), frontier_keys)
        explored |= [c in visited_cells for c in cells]
        mobility = _mobility_pairs(self._touching, location_of)
        if opened is not None:
            opened = location_of[opened]
            opened = opened[np.all(opened >= 0, axis=1)]
        return _network(crop, lattice, positions, explored, mobility, opened, cell_m=self.cell_m,
                        comm_range_m=self.comm_range_m, sight_height_m=self.sight_height_m,
                        max_region_m=self.max_region_m, prior=prior, keep=keep)


def _probes(r: float) -> list[tuple[int, int, int]]:
    """Eight voxels of a disc of radius ``r`` (voxels) around a voxel, in its layer,
    nearly on its rim: along the axes and the diagonals, nearer than ``r`` (the
    distance at which ``open_space``'s distance transform stops counting a voxel)."""
    axis = math.ceil(r) - 1
    diagonal = int(r / math.sqrt(2))
    while diagonal > 0 and math.sqrt(2 * diagonal * diagonal) >= r:
        diagonal -= 1
    return ([(s * axis, 0, 0) for s in (1, -1)] + [(0, s * axis, 0) for s in (1, -1)]
            + [(a * diagonal, b * diagonal, 0) for a in (1, -1) for b in (1, -1)])
