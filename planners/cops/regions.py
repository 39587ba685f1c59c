"""Locations that follow the free space: lattice cells merged into open areas.

A fixed lattice cuts an open area (a yard, a stope, a cavern) into many locations,
and COPS then spends plan steps and communications walking a team across one room.
Here face-adjacent lattice cells whose known free space is *open* where they meet
are merged into one location, a *region*:

* **Open space** (:func:`open_space`): the known-free voxels that a horizontal disc
  of radius ``open_radius_m`` of known free space covers, in their own layer (a
  morphological opening, made of two Euclidean distance transforms per layer with
  scipy). A tunnel 5 m wide, or the crossing of two, holds no such disc of 4 m;
  a 30 m yard is open up to its walls.
* Two cells side by side (sharing a vertical face) are **open to each other** when
  their locations' free space touches across that face between open voxels: a
  room continues there. A corridor stays a chain of cells; cells stacked vertically are
  never merged (levels stay apart).
* **Regions** (:func:`group_cells`): open pairs are merged (a union-find) in the
  order of their names, unless the region would span more than ``max_region_m``
  along an axis; merges the caller already made (``prior``) always hold, so a
  region only grows as the map grows. ``keep`` cells (the base's cell) are never
  merged.
* **Names.** A region is named after its member cell nearest the lattice's cell
  (0, 0, 0), the base's (:func:`region_order`: lattice distance, then the name).
  Every robot that sees the same members names the region the same way, and as a
  room is seen from where the team comes, cells added later are farther away and
  the name does not change. When it does (a nearer cell joins), the old name
  stays known as a member: ``merged`` maps every member cell that is not the
  region's name to it, topologies carry that map, and a union of topologies
  merges regions that share a cell (:meth:`delve.planners.cops.topology.Topology.merge`),
  so old names resolve to the new one everywhere.
"""
from __future__ import annotations

import re
from typing import Iterable, Mapping

import numpy as np
from networkx.utils import UnionFind
from scipy import ndimage

#: Free space that holds a horizontal disc of this radius (m) is wider than a tunnel
#: or a crossing of tunnels (the generated mines' tunnels are 3 to 5 m wide, a
#: crossing of two holds a disc of 3.5 m): an open area, as wide as an 8 m cell.
DEFAULT_OPEN_RADIUS_M = 4.0
#: A region spans at most this much (m) along any axis (eight 8 m cells: a 56 m yard
#: fits in one region wherever the lattice cuts it), so that a long wide drift or
#: cavern is a chain of regions, not one location.
DEFAULT_MAX_REGION_M = 64.0

#: 8-neighbours within a horizontal layer.
_IN_LAYER = np.zeros((3, 3, 3), dtype=bool)
_IN_LAYER[:, :, 1] = True
_CELL_NAME = re.compile(r"^c(-?\d+)_(-?\d+)_(-?\d+)$")


def cell_of_name(name: str) -> tuple[int, int, int] | None:
    """The lattice index of a cell's name ``c{i}_{j}_{k}``; None for other names."""
    m = _CELL_NAME.match(name)
    return (int(m[1]), int(m[2]), int(m[3])) if m else None


def region_order(name: str) -> tuple[float, str]:
    """Sort key of a region's candidate names: the squared lattice distance of the
    cell from cell (0, 0, 0), then the name (names that are no cells go last)."""
    cell = cell_of_name(name)
    return (float(sum(c * c for c in cell)) if cell is not None else float("inf"), name)


def region_name(members: Iterable[str]) -> str:
    """A region's name: its member first in :func:`region_order`."""
    return min(members, key=region_order)


def open_space(free: np.ndarray, voxel_size_m: float, radius_m: float = DEFAULT_OPEN_RADIUS_M) -> np.ndarray:
    """bool (nx, ny, nz): the voxels of the bool mask ``free`` that lie in a disc of
    radius ``radius_m`` within ``free`` in their own layer (z index): within
    ``radius_m`` of a voxel at least ``radius_m`` from every voxel off the mask.
    Voxels beyond the grid's sides count as off the mask."""
    r = radius_m / voxel_size_m
    out = np.zeros(free.shape, dtype=bool)
    padded = np.pad(free, ((1, 1), (1, 1), (0, 0)))
    # A disc of radius r holds a square of half-side r / sqrt(2): the chessboard
    # distance in each layer (cheap) picks the layers worth the Euclidean transforms.
    square = ndimage.distance_transform_cdt(padded, metric=_IN_LAYER) >= np.floor(r / np.sqrt(2))
    for k in np.flatnonzero(square.any(axis=(0, 1))):
        centres = ndimage.distance_transform_edt(padded[:, :, k]) >= r
        if centres.any():
            out[:, :, k] = (ndimage.distance_transform_edt(~centres) <= r)[1:-1, 1:-1] & free[:, :, k]
    return out


def open_faces(labels: np.ndarray, partition: list[np.ndarray], open_mask: np.ndarray) -> np.ndarray:
    """(E, 2) sorted pairs of distinct components (0-based labels - 1) that touch
    across a vertical face between two lattice cells (face neighbours along x or y)
    where ``open_mask`` holds on both sides (the open area goes on across the face:
    a corridor's mouth next to a room does not). ``labels`` are the int labels of
    components within cells (0: none), ``partition`` per axis the lattice index of
    each layer of voxels."""
    out = []
    for axis in (0, 1):
        cells = partition[axis]
        for i in np.flatnonzero(np.diff(cells)).tolist():
            a = labels.take(i, axis=axis)
            b = labels.take(i + 1, axis=axis)
            wide = open_mask.take(i, axis=axis) & open_mask.take(i + 1, axis=axis)
            hit = (a > 0) & (b > 0) & (a != b) & wide
            out.append(np.stack([a[hit], b[hit]], axis=1))
    if not out:
        return np.zeros((0, 2), np.int64)
    pairs = np.sort(np.concatenate(out).astype(np.int64) - 1, axis=1)
    return np.unique(pairs, axis=0).reshape(-1, 2)


class _Regions:
    """Union-find of cells (networkx's) with each region's lattice box."""

    def __init__(self, where: Mapping[str, tuple[int, int, int]]):
        self.where, self.sets = where, UnionFind()
        self.box: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def root(self, name: str) -> str:
        if name not in self.box:
            cell = np.array(self.where.get(name) or cell_of_name(name) or (0, 0, 0))
            self.box[name] = (cell, cell)
        return self.sets[name]

    def joined_box(self, u: str, v: str) -> tuple[np.ndarray, np.ndarray]:
        (a, b), (c, d) = self.box[self.root(u)], self.box[self.root(v)]
        return np.minimum(a, c), np.maximum(b, d)

    def union(self, u: str, v: str) -> None:
        if self.root(u) != self.root(v):
            joined = self.joined_box(u, v)
            self.sets.union(u, v)
            self.box[self.root(u)] = joined

    def merged(self) -> dict[str, str]:
        """Member -> region name, for every member that is not its region's name."""
        out = {m: region_name(group) for group in self.sets.to_sets() for m in group}
        return {m: n for m, n in sorted(out.items()) if m != n}


def group_cells(names: list[str], cells: np.ndarray, open_pairs: np.ndarray, *, cell_m: float,
                max_region_m: float = DEFAULT_MAX_REGION_M, prior: Mapping[str, str] | None = None,
                keep: Iterable[str] = ()) -> dict[str, str]:
    """The regions of locations ``names`` (lattice indices ``cells``, (L, 3)), as
    ``merged``: member cell -> region name, for every member that is not its
    region's name (single cells do not appear).

    ``open_pairs`` (E, 2) are index pairs of locations open to each other; each is
    merged, in the order of their names, unless the region would then span more
    than ``max_region_m`` along an axis. ``prior`` (a ``merged`` map made before, of
    cells that may no longer be locations) always holds. Cells in ``keep`` are never
    merged."""
    kept = set(keep)
    regions = _Regions({n: tuple(int(v) for v in c) for n, c in zip(names, np.asarray(cells).reshape(-1, 3).tolist())})
    for member, name in sorted((prior or {}).items()):
        if not {member, name} & kept:
            regions.union(member, name)
    limit = int(np.floor(max_region_m / cell_m + 1e-9))
    pairs = {tuple(sorted((names[a], names[b]))) for a, b in np.asarray(open_pairs).reshape(-1, 2).tolist()}
    for u, v in sorted(pairs):
        lo, hi = regions.joined_box(u, v)
        if not {u, v} & kept and np.all(hi - lo + 1 <= limit):
            regions.union(u, v)
    return regions.merged()
