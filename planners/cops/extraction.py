"""The mobility-communication network a robot's voxel map reveals (COPS on 3D worlds).

:func:`extract_topology` turns an occupancy grid into a :class:`Topology`:

* Locations S are the cells of a FIXED world lattice of edge ``cell_m`` whose cell
  (0, 0, 0) has its lower corner at ``lattice_origin``: lattice index
  ``floor((world - lattice_origin) / cell_m)`` (of a voxel's centre), name
  ``c{i}_{j}_{k}`` (indices may be negative: ``c-1_3_0``). Robots that share the
  lattice origin name a place the same way, whatever their maps' origins. (Put a
  cell's centre where the team starts, so that the first tunnel is not cut along
  its centre line.) Components are the connected pieces, within one cell, of the
  *passable* known-free voxels (by default the *standable* ones; a caller may pass
  all known free space, since a LiDAR sees a floor in rings that the free space
  above joins). A cell is a location when its *main component*, the one with the
  most standable voxels, holds at least ``min_free_voxels`` of them.
* A location's position is the standable voxel of its main component whose centre is
  nearest the cell's centre (ties broken by the voxel's world position). Two robots
  whose maps differ (or whose voxels are not aligned) may pick slightly different
  voxels; the name, not the position, identifies a location.
* A location is *explored* when the cell holds no frontier voxel
  (:func:`delve.planners.frontier.frontier_voxels`): it is fully mapped; or when a
  robot has been there (one of the ``visited`` points lies in the cell), since a
  robot whose LiDAR never sees the roof above it would otherwise explore nothing.
* A mobility edge (->) joins two locations whose main components touch: two of
  their voxels are 26-neighbours (not only face neighbours, so that the stairs a
  sloped floor makes of standable voxels connect; a caller whose robot steps
  higher than a voxel marks the voxels of each step's riser standable too). Since
  each main component is connected within its cell, the two positions are then
  connected within the two cells. Voxels that belong to no location (a passage
  clipping the corner of a cell, a second passage through a cell) are not lost:
  the locations that one connected fragment of them touches are joined pairwise.
  An edge's length is the distance between the positions.
* **Open areas** (:mod:`delve.planners.cops.regions`): explored cells side by side
  whose locations' free space touches through open space (a horizontal disc of
  ``open_radius_m`` fits there: wider than a tunnel) are merged into one location,
  a region of at most ``max_region_m`` across, named after its member nearest cell
  (0, 0, 0); ``keep`` cells are never merged, ``prior`` merges (a ``merged`` map)
  always hold. Only explored cells are merged, so the cells of an open area that
  nobody has explored yet stay locations of their own, the frontiers' targets, and
  join the region once explored. A region's position is its member's position
  nearest the mean of its members' positions; it is explored when every member is;
  its edges are its members' edges to other locations, with lengths between
  positions. The topology's ``merged`` maps every member to its region.
  ``open_radius_m=None`` merges nothing (the lattice's cells alone).
* The dense steps run on the box of the known-free voxels only (plus a margin for
  the frontier test), so their cost follows the mapped part of the world.
* A communication edge (~>) joins two locations whose *sight points* (positions
  raised by ``sight_height_m``) are within ``comm_range_m`` and see each other: the
  straight segment, sampled every half voxel, crosses only known-free voxels.
  Mobility neighbours in sight are communication neighbours too, at any range.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..frontier import FRONTIER_DEPTH, frontier_voxels
from ..occupancy import FREE, Grid
from .regions import DEFAULT_MAX_REGION_M, DEFAULT_OPEN_RADIUS_M, group_cells, open_faces, open_space
from .topology import Topology

#: Edge of a lattice cell (one location per cell), metres.
DEFAULT_CELL_M = 8.0
#: Range of the radio: pairs farther apart are never communication neighbours, metres.
DEFAULT_COMM_RANGE_M = 60.0
#: A cell whose main component of standable voxels is smaller is not a location.
DEFAULT_MIN_FREE_VOXELS = 16
#: Line-of-sight samples are this fraction of a voxel apart ...
SIGHT_STEP_VOXELS = 0.5
#: ... after a first pass over every this-many-th of them.
SIGHT_COARSE_STRIDE = 4
#: At most this many line-of-sight samples are held in memory at once.
SIGHT_CHUNK_SAMPLES = 2_000_000
#: Distances to a cell's centre are rounded to this (m) before ties are broken, so
#: that maps with different origins pick the same voxel.
_DISTANCE_ROUNDING_M = 1e-6
#: Voxels touch when they are 26-neighbours.
_CONNECTIVITY_26 = np.ones((3, 3, 3), dtype=bool)
_HALF_NEIGHBOURS_26 = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
                       if (a, b, c) > (0, 0, 0)]


def extract_topology(
    occupancy: np.ndarray,
    origin: np.ndarray,
    voxel_size_m: float,
    *,
    standable: np.ndarray | None = None,
    free: np.ndarray | None = None,
    cell_m: float = DEFAULT_CELL_M,
    comm_range_m: float = DEFAULT_COMM_RANGE_M,
    min_free_voxels: int = DEFAULT_MIN_FREE_VOXELS,
    sight_height_m: float = 0.0,
    visited: np.ndarray | None = None,
    lattice_origin: np.ndarray | None = None,
    passable: np.ndarray | None = None,
    open_radius_m: float | None = DEFAULT_OPEN_RADIUS_M,
    max_region_m: float = DEFAULT_MAX_REGION_M,
    prior: dict[str, str] | None = None,
    keep: tuple[str, ...] | list[str] = (),
) -> Topology:
    """The topology (locations, explored ones, mobility and communication edges) of a map.

    ``occupancy`` is an int8 (nx, ny, nz) grid of UNKNOWN / FREE / OCCUPIED,
    ``origin`` the world position of voxel (0, 0, 0)'s lower corner. ``standable``
    is a bool mask of the voxels a robot can stand on or fly through (None: every
    known-free voxel); ``passable`` a bool mask of the voxels a robot may pass
    through (None: the standable ones), whose connectivity makes the components and
    the mobility edges, while only standable voxels count towards
    ``min_free_voxels`` and become positions; ``free`` the flat indices of the FREE voxels when the map
    keeps them (the frontier search then needs no scan of the grid); ``visited``
    (N, 3) world points where robots have been; ``lattice_origin`` the lattice's
    corner (default: the world's origin); ``open_radius_m``, ``max_region_m``,
    ``prior`` and ``keep`` shape the regions of open areas (see above). Raises
    ``ValueError`` for bad inputs.
    """
    grid = _checked_grid(occupancy, origin, voxel_size_m, free)
    _check_parameters(cell_m, comm_range_m, min_free_voxels, sight_height_m, open_radius_m, max_region_m)
    corner = _checked_point(lattice_origin, "lattice_origin")
    visited_cells = _visited_cells(visited, cell_m, corner)
    standable = _checked_mask(grid, standable, "standable")
    passable = _checked_mask(grid, passable, "passable")
    grid, box = _cropped(grid)
    mask = _known_free(grid, standable, box)
    passable_mask = mask if passable is None else _known_free(grid, passable, box)
    partition = _partition(grid, cell_m, corner)
    labels = _components_within_cells(mask | passable_mask, partition)
    topo = Topology()
    flat = np.flatnonzero(labels)
    if len(flat) == 0:
        return topo
    ijk = np.stack(np.unravel_index(flat, grid.shape), axis=1)
    component = labels.reshape(-1)[flat].astype(np.int64) - 1
    stands = mask.reshape(-1)[flat]
    cell_key = _pack(np.stack([partition[a][ijk[:, a]] for a in range(3)], axis=1), partition)
    location_of, location_keys = _locations(component, cell_key, stands, min_free_voxels)
    if len(location_keys) == 0:
        return topo
    lattice = _unpack(location_keys, partition)
    members = (location_of[component] >= 0) & stands
    world = grid.to_world(ijk[members])
    centres = corner + (lattice + 0.5) * cell_m
    positions = world[_position_voxels(world, location_of[component[members]], centres)]
    explored = ~np.isin(location_keys, _frontier_cell_keys(grid, partition))
    explored |= [tuple(c) in visited_cells for c in lattice.tolist()]
    mobility = _mobility_pairs(_touching_components(labels, partition), location_of)
    opened = None
    if open_radius_m is not None:
        loc = location_of[open_faces(labels, partition, open_space(mask | passable_mask, grid.voxel_size_m,
                                                                   open_radius_m))]
        opened = loc[np.all(loc >= 0, axis=1)]
    return _network(grid, lattice, positions, explored, mobility, opened, cell_m=cell_m,
                    comm_range_m=comm_range_m, sight_height_m=sight_height_m, max_region_m=max_region_m,
                    prior=prior, keep=keep)


def _network(grid: Grid, lattice: np.ndarray, positions: np.ndarray, explored: np.ndarray,
             mobility: np.ndarray, opened: np.ndarray | None, *, cell_m: float, comm_range_m: float,
             sight_height_m: float, max_region_m: float, prior: dict[str, str] | None,
             keep: tuple[str, ...] | list[str]) -> Topology:
    """The topology of the locations of lattice cells ``lattice`` (L, 3), in the cells'
    order, with their ``positions`` (L, 3), ``explored`` flags (L,), ``mobility`` pairs
    (E, 2) of locations, and ``opened`` pairs of locations open to each other (None:
    no regions): the regions of the explored open pairs, their edges, and the
    communication edges by line of sight through ``grid``."""
    names = [cell_name(c) for c in lattice]
    merged: dict[str, str] = {}
    if opened is not None:
        merged = group_cells(names, lattice, opened[np.all(explored[opened], axis=1)], cell_m=cell_m,
                             max_region_m=max_region_m, prior=prior, keep=keep)
    region = np.array([merged.get(n, n) for n in names])
    names, index = np.unique(region, return_inverse=True)
    positions = _region_positions(positions, index, len(names))
    explored = np.bincount(index, weights=~explored, minlength=len(names)) == 0
    mobility = _unique_pairs(index[mobility])
    mobility = mobility[mobility[:, 0] != mobility[:, 1]]
    topo = Topology(merged=merged)
    for name, pos, done in zip(names.tolist(), positions, explored):
        topo.add_location(name, pos, explored=bool(done))
    lengths = np.linalg.norm(positions[mobility[:, 0]] - positions[mobility[:, 1]], axis=1)
    for (a, b), length in zip(mobility.tolist(), lengths.tolist()):
        topo.add_mobility_edge(str(names[a]), str(names[b]), length)
    sight = positions + np.array([0.0, 0.0, sight_height_m])
    for a, b in _communication_pairs(grid, sight, comm_range_m, mobility).tolist():
        topo.add_communication_edge(str(names[a]), str(names[b]))
    return topo


# -- the lattice ------------------------------------------------------------------------
def lattice_cells(points: np.ndarray, cell_m: float = DEFAULT_CELL_M,
                  lattice_origin: np.ndarray | None = None) -> np.ndarray:
    """(N, 3) int64 lattice indices of world points (N, 3): ``floor((p - lattice_origin) / cell_m)``."""
    corner = np.zeros(3) if lattice_origin is None else np.asarray(lattice_origin, float)
    return np.floor((np.asarray(points, float).reshape(-1, 3) - corner) / cell_m).astype(np.int64)


def cell_name(cell: np.ndarray | tuple[int, int, int]) -> str:
    """A lattice cell's location name, ``c{i}_{j}_{k}``."""
    i, j, k = (int(c) for c in cell)
    return f"c{i}_{j}_{k}"


def _partition(grid: Grid, cell_m: float, corner: np.ndarray) -> list[np.ndarray]:
    """Per axis, the lattice index of each layer of voxels (of its centres)."""
    return [np.floor((grid.origin[a] - corner[a] + (np.arange(n) + 0.5) * grid.voxel_size_m) / cell_m)
            .astype(np.int64) for a, n in enumerate(grid.shape)]


def _pack(cells: np.ndarray, partition: list[np.ndarray]) -> np.ndarray:
    """One int64 key per lattice cell (N, 3) of the grid."""
    lo = np.array([p[0] for p in partition])
    span = np.array([p[-1] - p[0] + 1 for p in partition])
    c = cells - lo
    return (c[:, 0] * span[1] + c[:, 1]) * span[2] + c[:, 2]


def _unpack(keys: np.ndarray, partition: list[np.ndarray]) -> np.ndarray:
    lo = np.array([p[0] for p in partition])
    span = tuple(int(p[-1] - p[0] + 1) for p in partition)
    return np.stack(np.unravel_index(keys, span), axis=1) + lo


# -- checks -------------------------------------------------------------------------------
def _checked_grid(occupancy: np.ndarray, origin: np.ndarray, voxel_size_m: float,
                  free: np.ndarray | None) -> Grid:
    occ = np.asarray(occupancy)
    if occ.ndim != 3 or not np.issubdtype(occ.dtype, np.integer) or 0 in occ.shape:
        raise ValueError(f"occupancy must be a non-empty 3-D integer grid, got {occ.dtype} {occ.shape}")
    org = _checked_point(origin, "origin")
    if not _positive(voxel_size_m):
        raise ValueError(f"voxel_size_m must be a positive finite number, got {voxel_size_m!r}")
    if free is not None:
        free = np.asarray(free, dtype=np.int64).reshape(-1)
    return Grid(occ, org, float(voxel_size_m), free)


def _check_parameters(cell_m: float, comm_range_m: float, min_free_voxels: int, sight_height_m: float,
                      open_radius_m: float | None, max_region_m: float) -> None:
    if not _positive(cell_m):
        raise ValueError(f"cell_m must be a positive finite number, got {cell_m!r}")
    if not _non_negative(comm_range_m):
        raise ValueError(f"comm_range_m must be a non-negative finite number, got {comm_range_m!r}")
    if isinstance(min_free_voxels, bool) or not isinstance(min_free_voxels, (int, np.integer)) \
            or min_free_voxels < 1:
        raise ValueError(f"min_free_voxels must be a positive integer, got {min_free_voxels!r}")
    if not _non_negative(sight_height_m):
        raise ValueError(f"sight_height_m must be a non-negative finite number, got {sight_height_m!r}")
    if open_radius_m is not None and not _positive(open_radius_m):
        raise ValueError(f"open_radius_m must be a positive finite number or None, got {open_radius_m!r}")
    if not _positive(max_region_m):
        raise ValueError(f"max_region_m must be a positive finite number, got {max_region_m!r}")


def _checked_point(point: np.ndarray | None, what: str) -> np.ndarray:
    """A finite (x, y, z) as a float array (None: the world's origin)."""
    if point is None:
        return np.zeros(3)
    p = np.asarray(point, dtype=float).reshape(-1)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"{what} must be a finite (x, y, z), got {point!r}")
    return p


def _non_negative(x: object) -> bool:
    return isinstance(x, (int, float, np.number)) and not isinstance(x, bool) and math.isfinite(x) and x >= 0


def _positive(x: object) -> bool:
    return _non_negative(x) and x > 0  # type: ignore[operator]


def _visited_cells(visited: np.ndarray | None, cell_m: float,
                   corner: np.ndarray) -> set[tuple[int, int, int]]:
    if visited is None:
        return set()
    points = np.asarray(visited, dtype=float)
    if points.size == 0:
        return set()
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise ValueError(f"visited must be finite (N, 3) points, got shape {points.shape}")
    return {tuple(c) for c in lattice_cells(points, cell_m, corner).tolist()}


def _checked_mask(grid: Grid, mask: np.ndarray | None, what: str) -> np.ndarray | None:
    if mask is None:
        return None
    m = np.asarray(mask)
    if m.shape != grid.shape or m.dtype != bool:
        raise ValueError(f"{what} must be a bool mask of shape {grid.shape}, got {m.dtype} {m.shape}")
    return m


def _known_free(grid: Grid, mask: np.ndarray | None, box: tuple[slice, ...]) -> np.ndarray:
    """Dense bool mask of the known-free voxels of ``grid`` (already cut to ``box``)
    that ``mask`` (full size, cut here; None: every one) holds."""
    free = grid.occupancy == FREE
    return free if mask is None else free & mask[box]


def _cropped(grid: Grid) -> tuple[Grid, tuple[slice, ...]]:
    """The grid cut to the box of the known-free voxels and a margin deep enough for
    the frontier test, and the box, so that the dense steps below scale with the
    mapped part of the world, not the whole map."""
    free = grid.free_voxels()
    if len(free) == 0:
        return grid, tuple(slice(0, n) for n in grid.shape)
    ijk = np.unravel_index(free, grid.shape)
    sub, box = _crop(grid, [int(a.min()) for a in ijk], [int(a.max()) for a in ijk])
    sub_free = np.ravel_multi_index(tuple(a - b.start for a, b in zip(ijk, box)), sub.shape)
    return Grid(sub.occupancy, sub.origin, sub.voxel_size_m, np.sort(sub_free)), box


def _crop(grid: Grid, lo: list[int], hi: list[int]) -> tuple[Grid, tuple[slice, ...]]:
    """The grid cut to the box of voxels ``lo`` to ``hi`` (inclusive, per axis: those of
    the known-free voxels) widened by the frontier test's margin, and the box."""
    margin = FRONTIER_DEPTH + 1
    lo = [max(0, a - margin) for a in lo]
    hi = [min(n, b + 1 + margin) for b, n in zip(hi, grid.shape)]
    box = tuple(slice(a, b) for a, b in zip(lo, hi))
    return Grid(grid.occupancy[box], grid.origin + np.array(lo) * grid.voxel_size_m, grid.voxel_size_m), box


# -- components and locations ------------------------------------------------------------
def _components_within_cells(mask: np.ndarray, partition: list[np.ndarray]) -> np.ndarray:
    """int32 labels (0 off the mask, else 1, 2, ...) of the 26-connected components of
    ``mask`` cut at the cell boundaries, so that each component lies in one cell.

    The cut is a layer of False inserted at each boundary before labelling."""
    cut, kept = mask, []
    for axis, cells in enumerate(partition):
        bounds = np.flatnonzero(np.diff(cells)) + 1
        cut = np.insert(cut, bounds, False, axis=axis)
        layers = np.arange(len(cells))
        kept.append(layers + np.searchsorted(bounds, layers, side="right"))
    labels, _ = ndimage.label(cut, structure=_CONNECTIVITY_26)
    for axis, layers in enumerate(kept):  # one axis at a time: faster than np.ix_
        labels = labels.take(layers, axis=axis)
    return labels


def _locations(component: np.ndarray, cell_key: np.ndarray, stands: np.ndarray,
               min_free_voxels: int) -> tuple[np.ndarray, np.ndarray]:
    """Per component, the number of its location (-1 if it is none); and per location
    (in key order) its cell's key. A location is a cell's main component (the one with
    the most standable voxels, ``stands``) with at least ``min_free_voxels`` of them;
    equal counts go to the lower label."""
    size = np.bincount(component, weights=stands).astype(np.int64)
    comp_cell = np.empty(len(size), dtype=np.int64)
    comp_cell[component] = cell_key
    order = np.lexsort((np.arange(len(size)), -size, comp_cell))
    _, first = np.unique(comp_cell[order], return_index=True)
    main = order[first]
    main = main[size[main] >= min_free_voxels]
    location_of = np.full(len(size), -1, dtype=np.int64)
    location_of[main] = np.arange(len(main))
    return location_of, comp_cell[main]


def _position_voxels(world: np.ndarray, location: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(L,) per location, the row of ``world`` (voxel centres, one row per voxel of
    ``location``) that is its position: its voxel nearest its cell's centre; ties go to
    the lowest (x, y, z)."""
    dist = np.round(np.linalg.norm(world - centres[location], axis=1) / _DISTANCE_ROUNDING_M)
    best = np.full(len(centres), np.inf)
    np.minimum.at(best, location, dist)
    tied = np.flatnonzero(dist == best[location])
    order = tied[np.lexsort((world[tied, 2], world[tied, 1], world[tied, 0], location[tied]))]
    _, first = np.unique(location[order], return_index=True)
    return order[first]


def _region_positions(positions: np.ndarray, region: np.ndarray, n: int) -> np.ndarray:
    """(n, 3): per region, the position of its member (rows of ``positions``, region
    ``region``) nearest the mean of its members' positions; ties go to the first."""
    mean = np.stack([np.bincount(region, weights=positions[:, a], minlength=n) for a in range(3)], axis=1)
    mean /= np.bincount(region, minlength=n)[:, None]
    gap = np.round(np.linalg.norm(positions - mean[region], axis=1) / _DISTANCE_ROUNDING_M)
    order = np.lexsort((np.arange(len(region)), gap, region))
    _, first = np.unique(region[order], return_index=True)
    return positions[order[first]]


def _frontier_cell_keys(grid: Grid, partition: list[np.ndarray]) -> np.ndarray:
    """Keys of the cells that hold a frontier voxel."""
    f = frontier_voxels(grid)
    ijk = np.unravel_index(f, grid.shape)
    return np.unique(_pack(np.stack([partition[a][ijk[a]] for a in range(3)], axis=1), partition))


# -- edges ----------------------------------------------------------------------------------
def _touching_components(labels: np.ndarray, partition: list[np.ndarray]) -> np.ndarray:
    """(E, 2) sorted pairs of distinct components (0-based) with 26-neighbouring voxels.

    Components lie within cells and two components of one cell never touch, so only
    neighbours across a cell boundary are compared: per offset and per axis it
    moves along, the layers on either side of that axis's boundaries."""
    out = []
    for d in _HALF_NEIGHBOURS_26:
        src = tuple(slice(max(0, -o), n - max(0, o)) for o, n in zip(d, labels.shape))
        dst = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(d, labels.shape))
        near, far = labels[src], labels[dst]
        for axis, o in enumerate(d):
            if o == 0:
                continue
            cells = partition[axis]
            layer = np.arange(src[axis].start, src[axis].stop)
            for i in np.flatnonzero(cells[layer] != cells[layer + o]).tolist():
                at = (slice(None),) * axis + (i,)
                a, b = near[at], far[at]
                hit = (a != b) & (a > 0) & (b > 0)
                out.append(np.stack([a[hit], b[hit]], axis=1))
    pairs = np.sort(np.concatenate(out).astype(np.int64) - 1, axis=1) if out else np.zeros((0, 2), np.int64)
    n = int(labels.max())
    keys = np.unique(pairs[:, 0] * n + pairs[:, 1])
    return np.stack([keys // n, keys % n], axis=1)


def _mobility_pairs(touching: np.ndarray, location_of: np.ndarray) -> np.ndarray:
    """(E, 2) sorted rows (a, b), a < b, of locations whose components touch, directly
    or through one connected fragment of components that are no location."""
    loc = location_of[touching]
    direct = np.all(loc >= 0, axis=1)
    return _unique_pairs(np.concatenate([loc[direct], _bridged_pairs(touching[~direct], location_of)]))


def _unique_pairs(pairs: np.ndarray) -> np.ndarray:
    """Distinct rows (a, b) of ``pairs`` as a < b, sorted."""
    pairs = np.sort(np.asarray(pairs, dtype=np.int64).reshape(-1, 2), axis=1)
    return np.unique(pairs, axis=0)


def _bridged_pairs(touching: np.ndarray, location_of: np.ndarray) -> np.ndarray:
    """(E, 2) pairs of locations that touch one connected fragment of non-location components."""
    n = len(location_of)
    loc = location_of[touching]
    both = np.all(loc < 0, axis=1)
    adj = coo_matrix((np.ones(int(both.sum())), (touching[both, 0], touching[both, 1])), shape=(n, n))
    _, fragment = connected_components(adj, directed=False)
    one = touching[~both]
    frag = fragment[np.where(loc[~both, 0] < 0, one[:, 0], one[:, 1])]
    touched = np.unique(np.stack([frag, loc[~both].max(axis=1)], axis=1), axis=0)
    out = [(a, b) for group in np.split(touched[:, 1], np.flatnonzero(np.diff(touched[:, 0])) + 1)
           for i, a in enumerate(group) for b in group[i + 1:]]
    return np.array(out, dtype=np.int64).reshape(-1, 2)


def _communication_pairs(grid: Grid, sight: np.ndarray, comm_range_m: float,
                         mobility: np.ndarray) -> np.ndarray:
    """(E, 2) sorted rows (a, b), a < b, of sight points within range (or mobility
    neighbours) that see each other."""
    near = mobility[:0]
    if comm_range_m > 0:
        near = cKDTree(sight).query_pairs(comm_range_m, output_type="ndarray")
    pairs = _unique_pairs(np.concatenate([near, mobility]))
    return pairs[line_of_sight(grid, sight[pairs[:, 0]], sight[pairs[:, 1]])]


def line_of_sight(grid: Grid, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N,) bool: whether each segment a[n] -> b[n] crosses only known-free voxels.

    Samples every ``SIGHT_STEP_VOXELS`` voxel along each segment, ends included; a
    first pass over every ``SIGHT_COARSE_STRIDE``-th sample drops the segments that
    are plainly blocked."""
    a = (np.atleast_2d(np.asarray(a, float)) - grid.origin) / grid.voxel_size_m
    b = (np.atleast_2d(np.asarray(b, float)) - grid.origin) / grid.voxel_size_m
    samples = np.ceil(np.linalg.norm(b - a, axis=1) / SIGHT_STEP_VOXELS).astype(np.int64) + 1
    seen = np.ones(len(a), dtype=bool)
    for stride in (SIGHT_COARSE_STRIDE, 1):
        idx = np.flatnonzero(seen)
        seen[idx] = _all_free(grid, a[idx], b[idx], samples[idx], stride)
    return seen


def _all_free(grid: Grid, a: np.ndarray, b: np.ndarray, samples: np.ndarray, stride: int) -> np.ndarray:
    """Whether every ``stride``-th of the evenly spaced ``samples`` of each segment (and
    its end) is known free; at most ``SIGHT_CHUNK_SAMPLES`` samples in memory at once."""
    counts = (samples - 2) // stride + 2
    ends = np.cumsum(counts)
    out = np.ones(len(a), dtype=bool)
    start = 0
    while start < len(a):
        limit = ends[start] - counts[start] + SIGHT_CHUNK_SAMPLES
        stop = max(start + 1, int(np.searchsorted(ends, limit, side="right")))
        part = slice(start, stop)
        out[part] = _blocked_samples(grid, a[part], b[part], samples[part], counts[part], stride) == 0
        start = stop
    return out


def _blocked_samples(grid: Grid, a: np.ndarray, b: np.ndarray, samples: np.ndarray, counts: np.ndarray,
                     stride: int) -> np.ndarray:
    """Per segment (voxel units), how many of its ``counts`` samples (every
    ``stride``-th of ``samples``, and the last) are not known free."""
    seg = np.repeat(np.arange(len(a)), counts)
    first = np.cumsum(counts) - counts
    last = samples[seg] - 1
    t = np.minimum((np.arange(len(seg)) - first[seg]) * stride, last) / last
    inside = np.ones(len(seg), dtype=bool)
    flat = np.zeros(len(seg), dtype=np.int64)
    for axis, n in enumerate(grid.shape):
        c = np.floor(a[seg, axis] + (b[seg, axis] - a[seg, axis]) * t).astype(np.int64)
        inside &= (c >= 0) & (c < n)
        flat = flat * n + c
    free = inside & (grid.occupancy.reshape(-1)[np.where(inside, flat, 0)] == FREE)
    return np.bincount(seg[~free], minlength=len(a))
