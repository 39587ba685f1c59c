"""COHORT's global frontiers (Kulkarni et al. 2022, section IV-B, Figure 3).

On every new submap the hub finds the submap's *wavefront*: a breadth-first search
over the voxels the submap visited (FREE in the submap), started from the robot's
trajectory, returns the unvisited voxels next to visited ones (face neighbours):
the submap's frontier points (centres of unknown voxels next to free ones). All
submaps' frontier points are then re-checked against the common map (a point another
submap knows is deleted), re-clustered by 26-connectivity, and clusters smaller than
f_min points are left out. Everything is at the common map's resolution r_C
(:class:`~delve.planners.cohort.common_map.CommonMap`); points are flat indices of it.

Departure (the surface band): the paper's submaps are Voxblox TSDF maps, in which the
space just behind an observed surface is known (the truncation band), so the rock
behind a wall is no frontier. delve's occupancy maps mark only the voxel a ray ended
in, and LiDAR rays that graze a wall carve the air beside it without hitting every
voxel of it: the unknown rock behind such a wall would be taken for frontier (in a
two-robot run of ``tunnel_network``, 9 frontier points in 10 lay in rock). So a point
within :data:`SURFACE_BAND_BLOCKS` blocks (26-neighbourhood) of an OCCUPIED block of
the common map counts as known, as the truncation band would have it; that removed
96 % of the points in rock and 23 % of those in air (the rim of true frontiers, next
to the walls) in that run.

Departure: the paper deletes the points of clusters below f_min; here they are only
left out of the clusters, so that a frontier seen in pieces by several submaps (each
piece below f_min) is counted whole once the pieces touch. Points are still deleted as
soon as the common map knows them, so they cannot pile up.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..frontier import FrontierCluster
from ..occupancy import FREE, OCCUPIED, UNKNOWN
from .common_map import CommonMap

#: A frontier point this many blocks (Chebyshev) or fewer from an OCCUPIED block counts
#: as known: the truncation band of the paper's TSDF submaps (see the module's docstring).
SURFACE_BAND_BLOCKS = 1

#: "Next to": the six face neighbours (wavefront); clusters join at 26-connectivity.
FACE_STRUCTURE = ndimage.generate_binary_structure(3, 1)
FULL_STRUCTURE = ndimage.generate_binary_structure(3, 3)


def _crop(common: CommonMap, blocks: np.ndarray, margin: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Voxel indices (N, 3) of ``blocks`` and the corners (lo, hi) of the box around them,
    ``margin`` voxels wider, clipped to the map."""
    ijk = np.stack(np.unravel_index(blocks, common.shape), axis=1)
    lo = np.maximum(ijk.min(axis=0) - margin, 0)
    hi = np.minimum(ijk.max(axis=0) + margin + 1, np.array(common.shape))
    return ijk, lo, hi


def submap_frontier(common: CommonMap, blocks: np.ndarray, values: np.ndarray,
                    trajectory: np.ndarray | None = None) -> np.ndarray:
    """The frontier points of one submap: flat indices (ascending) of the common map.

    ``blocks``, ``values``: the submap at r_C (:meth:`CommonMap.pool`). The search
    (a labelling of the visited voxels by 26-connectivity, which is the breadth-first
    search done for every voxel at once) starts from the blocks of ``trajectory``
    ((k, 3) robot positions in this submap); visited voxels it cannot reach are left
    out (seen through a gap the robot never passed, often a sliver of another drift).
    Without a trajectory point on a visited voxel it starts from all of them. A
    point is returned when it is unknown in this submap; the re-check against the
    common map (:func:`recheck`) is the caller's.
    """
    visited = blocks[values == FREE]
    if len(visited) == 0:
        return np.zeros(0, dtype=np.int64)
    ijk, lo, hi = _crop(common, visited)
    size = tuple(hi - lo)
    reached = np.zeros(size, dtype=bool)
    reached[tuple((ijk - lo).T)] = True
    known = np.zeros(size, dtype=bool)
    kijk = np.stack(np.unravel_index(blocks[values != UNKNOWN], common.shape), axis=1) - lo
    inside = np.all((kijk >= 0) & (kijk < np.array(size)), axis=1)
    known[tuple(kijk[inside].T)] = True
    if trajectory is not None and len(trajectory):
        labels, _ = ndimage.label(reached, structure=FULL_STRUCTURE)
        t = common.grid.to_index(np.asarray(trajectory, float).reshape(-1, 3)) - lo
        t = t[np.all((t >= 0) & (t < np.array(size)), axis=1)]
        seeds = np.unique(labels[tuple(t.T)])
        seeds = seeds[seeds > 0]
        if len(seeds):
            reached = np.isin(labels, seeds)
    wave = ndimage.binary_dilation(reached, structure=FACE_STRUCTURE) & ~known
    w = np.argwhere(wave) + lo
    return np.ravel_multi_index(tuple(w.T), common.shape).astype(np.int64)


def near_surface(common: CommonMap, points: np.ndarray, band: int = SURFACE_BAND_BLOCKS) -> np.ndarray:
    """Whether each of ``points`` (flat indices of the common map) has an OCCUPIED block
    at most ``band`` blocks away (Chebyshev distance; outside the map counts as not)."""
    span = np.arange(-band, band + 1)
    offsets = np.stack(np.meshgrid(span, span, span, indexing="ij"), axis=-1).reshape(-1, 3)
    ijk = np.stack(np.unravel_index(points, common.shape), axis=1)
    q = (ijk[:, None, :] + offsets[None, :, :]).reshape(-1, 3)
    inside = np.all((q >= 0) & (q < np.array(common.shape)), axis=1)
    rock = np.zeros(len(q), dtype=bool)
    rock[inside] = common.occupancy[tuple(q[inside].T)] == OCCUPIED
    return rock.reshape(len(points), len(offsets)).any(axis=1)


def recheck(common: CommonMap, points: np.ndarray) -> np.ndarray:
    """The ``points`` (flat indices of the common map) that are still frontier: UNKNOWN
    there (a point another submap has since mapped is deleted) and not within the
    surface band of known rock (:func:`near_surface`)."""
    points = points[common.values(points) == UNKNOWN]
    return points[~near_surface(common, points)]


def map_frontier(common: CommonMap) -> np.ndarray:
    """The frontier points of the whole common map, as :func:`recheck` keeps them:
    every UNKNOWN block next to a FREE one (face neighbours), outside the surface band,
    without the submaps' search from the trajectory. Looser than the points the hub
    keeps, for confirming that the map is closed (flat indices, ascending)."""
    occ = common.occupancy
    wave = ndimage.binary_dilation(occ == FREE, structure=FACE_STRUCTURE) & (occ == UNKNOWN)
    return recheck(common, np.flatnonzero(wave).astype(np.int64))


def cluster_frontiers(common: CommonMap, points: np.ndarray, f_min: int) -> list[FrontierCluster]:
    """Frontier clusters: the 26-connected components of ``points`` (flat indices of
    the common map) with at least ``f_min`` points, largest first (ties: lowest first
    point), each with its points (ascending) and their centroid.

    26-neighbours are the pairs at Chebyshev distance 1 (a KD-tree over the points'
    voxel indices): the points are scattered over the whole explored world, so this
    costs what the points cost, where a labelling of their bounding box would cost its
    volume.
    """
    points = np.unique(points)
    if len(points) == 0:
        return []
    ijk = np.stack(np.unravel_index(points, common.shape), axis=1)
    pairs = cKDTree(ijk).query_pairs(1.0, p=np.inf, output_type="ndarray")
    adj = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points), len(points)))
    _, label = connected_components(adj, directed=False)
    counts = np.bincount(label)
    keep = np.flatnonzero(counts >= f_min)
    if len(keep) == 0:
        return []
    first = np.full(len(counts), len(points))
    np.minimum.at(first, label, np.arange(len(points)))
    keep = keep[np.lexsort((first[keep], -counts[keep]))]
    centres = common.centres(points)
    clusters = []
    for c in keep:
        members = label == c
        clusters.append(FrontierCluster(voxels=points[members], centroid=centres[members].mean(axis=0)))
    return clusters


class GlobalFrontiers:
    """Every submap's frontier points, by submap key (``(robot, index)``), in arrival order.

    ``points`` maps a key to its points (flat indices of the common map, ascending).
    """

    def __init__(self) -> None:
        self.points: dict[tuple[str, int], np.ndarray] = {}

    def add(self, key: tuple[str, int], points: np.ndarray) -> None:
        """Store (or replace) the frontier points of submap ``key``."""
        self.points[key] = np.asarray(points, dtype=np.int64)

    def recheck(self, common: CommonMap) -> int:
        """Delete every point the common map knows; returns how many were deleted."""
        dropped = 0
        for key, pts in self.points.items():
            kept = recheck(common, pts)
            dropped += len(pts) - len(kept)
            self.points[key] = kept
        return dropped

    def all_points(self) -> np.ndarray:
        """Every submap's points, merged (ascending, unique)."""
        if not self.points:
            return np.zeros(0, dtype=np.int64)
        return np.unique(np.concatenate(list(self.points.values())))
