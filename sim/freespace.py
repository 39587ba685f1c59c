"""Free space from geometry that does not enclose it: open meshes, slab-and-wall
models, point clouds.

A closed inner surface (a scan of a tunnel's walls, watertight, its faces turned to
the passages) needs none of this: parity along vertical rays finds its inside
exactly (:func:`delve.sim.meshio.voxelise_interior`). Everything else is built here
in three steps:

1. **Rock.** For a mesh, every voxel the surface passes through
   (:func:`surface_rock`), plus the inside of each closed solid body in it (a wall
   box, a floor slab); for a point cloud, every voxel holding a point, inflated by
   ``inflation_m`` (:func:`point_rock`).
2. **Candidate air** (:func:`floored_space`): not rock, below the ceiling (the
   model's top or a height the user gives), and above a floor (some rock below it
   in its column), so that the space under a model and beside it is not air.
3. **Regions** (:func:`keep_regions`): the 6-connected parts of it; slivers under
   ``MIN_REGION_M3`` go unless a start is in one.

With scan origins a point cloud's free space is instead what the scanner saw
(:func:`carve_scans`): the voxels on the straight line from an origin to each
point, up to the first rock.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import open3d as o3d
from scipy import ndimage

#: Free regions smaller than this are dropped (slivers between surfaces, the inside
#: of a wall that is not closed) unless a start lies in one.
MIN_REGION_M3 = 1.0
#: Scan rays are walked in steps of this share of a voxel.
RAY_STEP_VOXELS = 0.5
#: Points farther than this from a scan origin are not carved from it.
SCAN_RANGE_M = 40.0
#: Scan origins (a trajectory's poses) closer than this to the last one kept are skipped.
SCAN_ORIGIN_SPACING_M = 1.0
#: Rays carved per batch (memory: batch x steps x 3 indices).
_RAY_BATCH = 2048
#: Sub-voxel offset of vertical rays from the column centres, so that they do not
#: run along the edges of models built on the voxel lattice.
_RAY_OFFSET_VOXELS = (0.0137, 0.0291)
#: Face-column pairs tested per batch when filling solids.
_COLUMN_BATCH = 2_000_000


@dataclass(frozen=True)
class Closure:
    """Whether a mesh encloses its passages.

    kind: "inner" (watertight, faces turned inwards: it encloses air), "solids"
        (no boundary edge, faces turned outwards: it encloses rock, like a Gazebo
        model of wall and slab boxes, touching or overlapping) or "open" (it has
        boundary edges).
    boundary_edges: edges that only one triangle uses (after merging equal vertices).
    solids: (vertices, triangles) of the closed parts that enclose rock: the whole
        mesh for "solids", each closed body for "open".
    """

    kind: str
    boundary_edges: int
    solids: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)


def mesh_closure(vertices: np.ndarray, triangles: np.ndarray) -> Closure:
    """How a mesh closes (see :class:`Closure`), by trimesh's edge and winding checks."""
    import trimesh
    from trimesh.grouping import group_rows

    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(triangles), process=True)
    boundary = len(group_rows(mesh.edges_sorted, require_count=1))
    if boundary == 0:
        if mesh.is_watertight and mesh.is_winding_consistent and mesh.volume < 0:
            return Closure("inner", 0)
        return Closure("solids", 0, [(np.asarray(mesh.vertices), np.asarray(mesh.faces))])
    solids = [(np.asarray(b.vertices), np.asarray(b.faces)) for b in mesh.split(only_watertight=False)
              if b.is_watertight and b.is_winding_consistent and b.volume > 0]
    return Closure("open", boundary, solids)


def grid_around(points: np.ndarray, voxel_size_m: float, top_z: float | None = None
                ) -> tuple[np.ndarray, tuple[int, int, int]]:
    """(origin, shape) of a grid aligned to multiples of the voxel size that holds
    ``points`` and, when given, reaches up to ``top_z``."""
    v = float(voxel_size_m)
    lo = np.floor(points.min(axis=0) / v) * v
    hi = points.max(axis=0).astype(float)
    if top_z is not None:
        hi[2] = max(hi[2], top_z)
    shape = np.floor((hi - lo) / v).astype(int) + 1
    return lo, (int(shape[0]), int(shape[1]), int(shape[2]))


def surface_rock(vertices: np.ndarray, triangles: np.ndarray, origin: np.ndarray, shape: tuple[int, int, int],
                 voxel_size_m: float, solids: Sequence[tuple[np.ndarray, np.ndarray]] = ()) -> np.ndarray:
    """Voxels the surface passes through (open3d's triangle-box test), and the inside
    of each closed solid body, as a bool grid."""
    v = float(voxel_size_m)
    rock = np.zeros(shape, dtype=bool)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.asarray(vertices, float)),
                                     o3d.utility.Vector3iVector(np.asarray(triangles, np.int32)))
    top = origin + np.asarray(shape) * v
    grid = o3d.geometry.VoxelGrid.create_from_triangle_mesh_within_bounds(mesh, v, origin, top)
    idx = np.array([vox.grid_index for vox in grid.get_voxels()], dtype=np.int64).reshape(-1, 3)
    idx = idx[np.all((idx >= 0) & (idx < np.asarray(shape)), axis=1)]
    rock[idx[:, 0], idx[:, 1], idx[:, 2]] = True
    for verts, tris in solids:
        rock |= solid_inside(verts, tris, origin, shape, v)
    return rock


def solid_inside(vertices: np.ndarray, triangles: np.ndarray, origin: np.ndarray, shape: tuple[int, int, int],
                 voxel_size_m: float) -> np.ndarray:
    """Voxels whose centres lie inside closed bodies whose faces turn outwards, as a
    bool grid. Along each column (a vertical line near its centre), a face turned
    down that the line meets going up enters a body (+1), a face turned up leaves
    one (-1); where the sum is positive the voxel is inside. Every face the line
    meets counts, also where two bodies touch, so touching and overlapping bodies
    give their union (parity, and a ray caster that reports one hit per point,
    would not)."""
    v = float(voxel_size_m)
    nx_, ny_, nz_ = shape
    tri = np.asarray(vertices, float)[np.asarray(triangles, np.int64)]           # (M, 3, 3)
    # column coordinates: column (i, j)'s line is at u = i, w = j
    u = (tri[..., 0] - origin[0]) / v - 0.5 - _RAY_OFFSET_VOXELS[0]
    w = (tri[..., 1] - origin[1]) / v - 0.5 - _RAY_OFFSET_VOXELS[1]
    area = (u[:, 1] - u[:, 0]) * (w[:, 2] - w[:, 0]) - (u[:, 2] - u[:, 0]) * (w[:, 1] - w[:, 0])
    keep = np.abs(area) > 1e-12                  # faces seen edge-on from above are never crossed
    tri, u, w, area = tri[keep], u[keep], w[keep], area[keep]
    i0 = np.clip(np.ceil(u.min(axis=1)), 0, nx_).astype(np.int64)
    i1 = np.clip(np.floor(u.max(axis=1)), -1, nx_ - 1).astype(np.int64)
    j0 = np.clip(np.ceil(w.min(axis=1)), 0, ny_).astype(np.int64)
    j1 = np.clip(np.floor(w.max(axis=1)), -1, ny_ - 1).astype(np.int64)
    ni, nj = np.maximum(i1 - i0 + 1, 0), np.maximum(j1 - j0 + 1, 0)
    count = ni * nj
    steps = np.zeros(nx_ * ny_ * (nz_ + 1))
    for lo, hi in _batches(count, _COLUMN_BATCH):
        reps = count[lo:hi]
        t = np.repeat(np.arange(lo, hi), reps)
        local = np.arange(len(t)) - np.repeat(np.cumsum(reps) - reps, reps)
        ci = i0[t] + local // np.maximum(nj[t], 1)
        cj = j0[t] + local % np.maximum(nj[t], 1)
        l1 = ((u[t, 1] - ci) * (w[t, 2] - cj) - (u[t, 2] - ci) * (w[t, 1] - cj)) / area[t]
        l2 = ((u[t, 2] - ci) * (w[t, 0] - cj) - (u[t, 0] - ci) * (w[t, 2] - cj)) / area[t]
        l3 = 1.0 - l1 - l2
        hit = (l1 >= 0) & (l2 >= 0) & (l3 >= 0)
        t, ci, cj, l1, l2, l3 = t[hit], ci[hit], cj[hit], l1[hit], l2[hit], l3[hit]
        z = l1 * tri[t, 0, 2] + l2 * tri[t, 1, 2] + l3 * tri[t, 2, 2]
        k = np.clip(np.floor((z - origin[2]) / v - 0.5).astype(np.int64) + 1, 0, nz_)
        sign = np.where(area[t] > 0, -1.0, 1.0)       # counter-clockwise from above: turned up
        steps += np.bincount((ci * ny_ + cj) * (nz_ + 1) + k, weights=sign, minlength=steps.size)
    winding = np.cumsum(steps.reshape(nx_, ny_, nz_ + 1)[:, :, :nz_], axis=2)
    return winding > 0.5


def _batches(count: np.ndarray, size: int):
    """(lo, hi) ranges of ``count`` whose sums stay near ``size``."""
    lo, total = 0, 0
    for i, c in enumerate(count):
        total += int(c)
        if total >= size:
            yield lo, i + 1
            lo, total = i + 1, 0
    if lo < len(count):
        yield lo, len(count)


def point_rock(points: np.ndarray, origin: np.ndarray, shape: tuple[int, int, int], voxel_size_m: float,
               inflation_m: float) -> np.ndarray:
    """Voxels holding a point, and every voxel whose centre lies within
    ``inflation_m`` of such a voxel's centre, as a bool grid."""
    v = float(voxel_size_m)
    rock = np.zeros(shape, dtype=bool)
    idx = point_voxels(points, origin, shape, v)
    rock[idx[:, 0], idx[:, 1], idx[:, 2]] = True
    r = int(math.floor(float(inflation_m) / v + 1e-9))
    if r > 0:
        o = np.arange(-r, r + 1)
        ball = (o[:, None, None] ** 2 + o[None, :, None] ** 2 + o[None, None, :] ** 2) * v * v \
            <= float(inflation_m) ** 2 + 1e-9
        rock = ndimage.binary_dilation(rock, structure=ball)
    return rock


def point_voxels(points: np.ndarray, origin: np.ndarray, shape: tuple[int, int, int],
                 voxel_size_m: float) -> np.ndarray:
    """Unique voxel indices (N, 3) of the points that fall inside the grid."""
    idx = np.floor((np.asarray(points, float) - origin) / float(voxel_size_m)).astype(np.int64)
    idx = idx[np.all((idx >= 0) & (idx < np.asarray(shape)), axis=1)]
    return np.unique(idx, axis=0)


def ceiling_index(origin: np.ndarray, voxel_size_m: float, ceiling_z: float) -> int:
    """The voxel layer that holds the ceiling plane; it and every layer above are rock."""
    return int(math.floor((float(ceiling_z) - float(origin[2])) / float(voxel_size_m) + 1e-9))


def floored_space(rock: np.ndarray, ceiling_k: int) -> np.ndarray:
    """Candidate air: not rock, below layer ``ceiling_k``, with rock somewhere below
    it in its column (a floor)."""
    below = np.zeros_like(rock)
    np.logical_or.accumulate(rock[:, :, :-1], axis=2, out=below[:, :, 1:])
    air = below & ~rock
    air[:, :, max(ceiling_k, 0):] = False
    return air


def seed_voxels(air: np.ndarray, origin: np.ndarray, voxel_size_m: float,
                seeds: Sequence[Sequence[float]]) -> list[tuple[int, int, int]]:
    """The air voxels that hold the points ``seeds`` (starts), or the one just above a
    point that lies on a floor (in the rock voxel the floor passes through)."""
    out = []
    for p in seeds:
        idx = np.floor((np.asarray(p, float).reshape(3) - origin) / float(voxel_size_m)).astype(int)
        for k in (idx[2], idx[2] + 1):
            c = (int(idx[0]), int(idx[1]), int(k))
            if all(0 <= c[a] < air.shape[a] for a in range(3)) and air[c]:
                out.append(c)
                break
    return out


def keep_regions(air: np.ndarray, voxel_size_m: float, seeds: Sequence[tuple[int, int, int]] = (),
                 min_region_m3: float = MIN_REGION_M3) -> np.ndarray:
    """The 6-connected regions of ``air`` of at least ``min_region_m3``, and those
    holding a seed voxel, as a bool grid."""
    labels, n = ndimage.label(air)
    if n == 0:
        return air.copy()
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    keep = sizes * float(voxel_size_m) ** 3 >= min_region_m3
    for s in seeds:
        keep[labels[s]] = True
    keep[0] = False
    return keep[labels]


def thin_origins(origins: np.ndarray, spacing_m: float = SCAN_ORIGIN_SPACING_M) -> np.ndarray:
    """Scan origins in their order, skipping each that lies within ``spacing_m`` of
    the last one kept."""
    kept: list[np.ndarray] = []
    for p in np.asarray(origins, float).reshape(-1, 3):
        if not kept or np.linalg.norm(p - kept[-1]) >= spacing_m:
            kept.append(p)
    return np.array(kept).reshape(-1, 3)


def carve_scans(rock: np.ndarray, origin: np.ndarray, voxel_size_m: float, scan_origins: np.ndarray,
                targets: np.ndarray, range_m: float = SCAN_RANGE_M) -> tuple[np.ndarray, int]:
    """What a scanner at each of ``scan_origins`` saw: the voxels on the straight line
    from the origin to the centre of each target voxel (N, 3 indices) within
    ``range_m``, up to the first rock voxel. Returns (free bool grid, origins used:
    those in the grid and not in rock)."""
    v = float(voxel_size_m)
    shape = np.asarray(rock.shape)
    free = np.zeros(rock.shape, dtype=bool)
    centres = origin + (np.asarray(targets, float) + 0.5) * v
    step = RAY_STEP_VOXELS * v
    used = 0
    for o in np.asarray(scan_origins, float).reshape(-1, 3):
        oi = np.floor((o - origin) / v).astype(int)
        if np.any(oi < 0) or np.any(oi >= shape) or rock[tuple(oi)]:
            continue
        used += 1
        d = centres - o
        length = np.linalg.norm(d, axis=1)
        near = (length > 0) & (length <= range_m)
        d, length = d[near] / length[near, None], length[near]
        for s in range(0, len(length), _RAY_BATCH):
            dd, ll = d[s:s + _RAY_BATCH], length[s:s + _RAY_BATCH]
            t = np.arange(int(math.ceil(ll.max() / step)) + 1) * step
            valid = t[None, :] <= ll[:, None]
            pts = o + t[None, :, None] * dd[:, None, :]
            idx = np.floor((pts - origin) / v).astype(np.int64)
            valid &= np.all((idx >= 0) & (idx < shape), axis=2)
            idx = np.where(valid[..., None], idx, 0)
            hit = rock[idx[..., 0], idx[..., 1], idx[..., 2]] & valid
            first = np.where(hit.any(axis=1), hit.argmax(axis=1), t.size)
            seen = valid & (np.arange(t.size)[None, :] < first[:, None])
            sel = idx[seen]
            free[sel[:, 0], sel[:, 1], sel[:, 2]] = True
    return free & ~rock, used
