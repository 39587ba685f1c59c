"""Worlds from triangle meshes (PLY / OBJ / STL), and writing scan-like meshes.

:func:`from_mesh` turns a closed mesh of a tunnel's *inner* surface (a scan of
a mine or cave, or a mesh saved by :meth:`World.save_mesh`) into a
:class:`~delve.sim.world.World`. It assumes that the mesh encloses the
passages: every vertical line enters and leaves the enclosed air an even
number of times, so the air is found by parity along one vertical ray per
voxel column. Open scans (missing patches) give streaks of wrong voxels in
the columns that pass through the holes; columns with an odd number of
crossings are left as rock.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import sys
from pathlib import Path
from typing import Any, Iterator, Sequence

import networkx as nx
import numpy as np
import open3d as o3d
from scipy import ndimage

from .world import MESH_SUFFIXES, START_ABOVE_FLOOR_M, World

#: Rotations that turn a mesh's named up axis into +z (proper rotations, det = +1).
UP_AXIS_ROTATIONS = {
    "z": np.eye(3),
    "-z": np.diag([1.0, -1.0, -1.0]),
    "y": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
    "-y": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
    "x": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
    "-x": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
}
#: Sub-voxel offset of the vertical rays from the column centres, so that rays
#: do not run exactly along the edges of meshes built on the same voxel lattice.
_RAY_OFFSET_VOXELS = (0.0137, 0.0291)
#: Headroom a start point needs above the floor.
START_HEADROOM_M = 1.0
#: The automatic start is looked for within this distance of the lowest-x free voxel.
START_SEARCH_DEPTH_M = 3.0


def up_axis_rotation(up_axis: str) -> np.ndarray:
    """3x3 rotation that maps the named axis ("x", "y", "z", "-x", "-y", "-z") onto +z."""
    key = str(up_axis).strip().lower().lstrip("+")
    if key not in UP_AXIS_ROTATIONS:
        raise ValueError(f"unknown up_axis {up_axis!r}: use one of "
                         f"{', '.join(sorted(UP_AXIS_ROTATIONS))}")
    return UP_AXIS_ROTATIONS[key]


@contextlib.contextmanager
def native_output_silenced() -> Iterator[None]:
    """Silence what native code prints to the process's stdout and stderr (Open3D's
    warnings, the RPly reader's complaints about a broken PLY), so that a broken mesh
    gives delve's one line and nothing before it. Python's own streams are flushed
    first and the C library's before the descriptors are restored."""
    previous = o3d.utility.get_verbosity_level()
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    saved: list[tuple[int, int]] = []
    try:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (AttributeError, ValueError, OSError):
                pass
        with open(os.devnull, "wb") as devnull:
            for fd in (1, 2):
                try:
                    saved.append((fd, os.dup(fd)))
                    os.dup2(devnull.fileno(), fd)
                except OSError:
                    pass
            yield
    finally:
        _flush_c_stdio()
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
        o3d.utility.set_verbosity_level(previous)


def _flush_c_stdio() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass


def read_mesh(path: str | Path) -> o3d.geometry.TriangleMesh:
    """Read a PLY / OBJ / STL mesh; ValueError "cannot read mesh 'path'" if absent,
    unreadable or without triangles. What the native readers print is silenced."""
    path = Path(path)
    if not path.is_file() or path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"cannot read mesh '{path.name}'")
    with native_output_silenced():
        mesh = o3d.io.read_triangle_mesh(str(path), print_progress=False)
    if len(mesh.triangles) == 0 or len(mesh.vertices) == 0:
        raise ValueError(f"cannot read mesh '{path.name}': no triangles in it (a broken or empty "
                         f"{path.suffix.lstrip('.').upper()} file?)")
    return mesh


def voxelise_interior(mesh: o3d.geometry.TriangleMesh, voxel_size_m: float):
    """Voxels whose centres the closed mesh encloses, by parity along vertical rays.

    Returns (free bool grid, origin). The grid has at least one voxel of
    rock all round and is aligned to multiples of ``voxel_size_m``.
    """
    v = float(voxel_size_m)
    verts = np.asarray(mesh.vertices)
    lo = np.floor(verts.min(axis=0) / v) * v - v
    shape = np.ceil((verts.max(axis=0) - lo) / v).astype(int) + 1
    nx_, ny_, nz_ = (int(n) for n in shape)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))

    xs = lo[0] + (np.arange(nx_) + 0.5 + _RAY_OFFSET_VOXELS[0]) * v
    ys = lo[1] + (np.arange(ny_) + 0.5 + _RAY_OFFSET_VOXELS[1]) * v
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    z0 = lo[2] - v
    rays = np.zeros((nx_ * ny_, 6), dtype=np.float32)
    rays[:, 0], rays[:, 1], rays[:, 2], rays[:, 5] = gx.ravel(), gy.ravel(), z0, 1.0
    hits = scene.list_intersections(o3d.core.Tensor(rays))
    ray_ids = hits["ray_ids"].numpy().astype(np.int64)
    t = hits["t_hit"].numpy().astype(np.float64)

    order = np.lexsort((t, ray_ids))
    ray_ids, t = ray_ids[order], t[order]
    # one crossing reported twice (a ray through a shared edge or vertex) counts once
    dup = np.zeros(len(t), dtype=bool)
    dup[1:] = (ray_ids[1:] == ray_ids[:-1]) & (np.abs(t[1:] - t[:-1]) < 1e-6 * v)
    ray_ids, t = ray_ids[~dup], t[~dup]
    counts = np.bincount(ray_ids, minlength=nx_ * ny_)
    keep = (counts % 2 == 0)[ray_ids]
    ray_ids, t = ray_ids[keep], t[keep]

    # toggle parity at the first voxel centre above each crossing, then integrate up z
    # (by xor in one byte a voxel: a count and its cumulative sum would take 12)
    k = np.floor((z0 + t - lo[2]) / v - 0.5).astype(np.int64) + 1
    k = np.clip(k, 0, nz_)
    toggles = np.zeros((nx_, ny_, nz_ + 1), dtype=np.uint8)
    np.bitwise_xor.at(toggles.reshape(-1), ray_ids * (nz_ + 1) + k, np.uint8(1))
    free = np.bitwise_xor.accumulate(toggles[:, :, :nz_], axis=2).astype(bool)
    return free, lo


def default_start(world: World) -> np.ndarray:
    """A point on the floor near the lowest-x end of the largest free region.

    The floor voxel must have START_HEADROOM_M of air above it; among those
    within START_SEARCH_DEPTH_M of the lowest-x one, the one farthest from
    the walls wins. ValueError if the world has no such floor.
    """
    v = world.voxel_size_m
    free = world.free
    labels, sizes = world.free_regions()          # cached: the checks before a run reuse them
    if not sizes.any():
        raise ValueError(f"world {world.name!r} has no free space")
    main = labels == int(np.argmax(sizes))
    head = max(int(math.ceil(START_HEADROOM_M / v)), 1)
    floor = main.copy()
    floor[:, :, 0] = False
    floor[:, :, 1:] &= ~free[:, :, :-1]
    for dz in range(1, head):
        floor[:, :, :-dz] &= free[:, :, dz:]
        floor[:, :, -dz:] = False
    idx = np.argwhere(floor)
    if len(idx) == 0:
        raise ValueError(f"world {world.name!r} has no floor with {START_HEADROOM_M} m headroom")
    near = idx[idx[:, 0] <= idx[:, 0].min() + int(math.ceil(START_SEARCH_DEPTH_M / v))]
    i0 = int(near[:, 0].min())
    i1 = min(int(near[:, 0].max()) + 1 + head, free.shape[0])
    clearance = ndimage.distance_transform_edt(np.pad(free[i0:i1], 1))
    lift = min(head - 1, int(round(0.5 / v)))
    score = clearance[near[:, 0] - i0 + 1, near[:, 1] + 1, near[:, 2] + lift + 1]
    best = near[np.lexsort((near[:, 2], near[:, 1], near[:, 0], -score))[0]]
    centre = world.index_to_center(best[None])[0]
    floor_z = world.origin[2] + best[2] * v
    return np.array([centre[0], centre[1], floor_z + START_ABOVE_FLOOR_M])


def closed_mesh_world(world_mesh: o3d.geometry.TriangleMesh, voxel_size_m: float, name: str) -> World:
    """A World (start not set yet) from a closed inner surface in metres, z up: its
    inside by parity along vertical rays; the mesh, with vertex normals, is its rock."""
    world_mesh.compute_vertex_normals()
    free, origin = voxelise_interior(world_mesh, voxel_size_m)
    return World(name=name, voxel_size_m=voxel_size_m, origin=origin, free=free,
                 mesh=world_mesh, centreline=nx.Graph(), start=np.zeros(3))


def from_mesh(path: str | Path, *, scale: float = 1.0, up_axis: str = "z",
              voxel_size_m: float = 0.2, start: Sequence[float] | None = None,
              name: str | None = None) -> World:
    """A World from a closed mesh of a tunnel's inner surface (PLY / OBJ / STL).

    The mesh is scaled by ``scale`` (e.g. 0.01 for centimetres), rotated so
    that ``up_axis`` becomes +z, and its interior voxelised by parity along
    vertical rays (the mesh must enclose the passages; see the module notes).
    The start is ``start`` if given (ValueError if it is not in free space),
    else a floor point near the lowest-x end. The centreline graph is empty.
    """
    scale = float(scale)
    if not math.isfinite(scale) or scale <= 0:
        raise ValueError(f"scale must be a positive number, got {scale}")
    v = float(voxel_size_m)
    if not math.isfinite(v) or v <= 0:
        raise ValueError(f"voxel_size_m must be positive, got {voxel_size_m}")
    rot = up_axis_rotation(up_axis)
    path = Path(path)
    mesh = read_mesh(path)
    verts = (np.asarray(mesh.vertices) * scale) @ rot.T
    world_mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                           o3d.utility.Vector3iVector(np.asarray(mesh.triangles)))
    return place_start(closed_mesh_world(world_mesh, v, name or path.stem), start, f"mesh world '{path}'")


def place_start(world: World, start: Any, where: str) -> World:
    """Set ``world.start`` to ``start`` (checked: a ValueError naming ``where`` when no
    robot can stand there), or to :func:`default_start` when none is given."""
    if start is None:
        world.start = default_start(world)
        return world
    world.start = np.asarray(start, dtype=float).reshape(3)
    problem = world.start_problem(world.start)
    if problem:
        raise ValueError(f"start {world.start.tolist()} in {where}: {problem}")
    return world


def write_scan_mesh(mesh: o3d.geometry.TriangleMesh, path: str | Path, *,
                    noise_m: float = 0.0, seed: int = 0, target_triangles: int | None = None,
                    scale: float = 1.0, up_axis: str = "z") -> Path:
    """Write a z-up metric mesh the way a scanner might deliver it (binary PLY).

    Optionally decimated to ``target_triangles`` (quadric), each vertex moved
    by Gaussian noise of ``noise_m`` per axis (``seed`` drives it), then
    expressed in file units and axes such that
    ``from_mesh(path, scale=scale, up_axis=up_axis)`` restores the metric,
    z-up geometry.
    """
    out = o3d.geometry.TriangleMesh(mesh)
    if target_triangles is not None and len(out.triangles) > target_triangles:
        out = out.simplify_quadric_decimation(int(target_triangles))
        out.remove_degenerate_triangles()
        out.remove_unreferenced_vertices()
    verts = np.asarray(out.vertices).copy()
    if noise_m > 0:
        verts += np.random.default_rng(seed).normal(0.0, noise_m, verts.shape)
    verts = (verts @ up_axis_rotation(up_axis)) / float(scale)     # inverse of from_mesh
    file_mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                          o3d.utility.Vector3iVector(np.asarray(out.triangles)))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not o3d.io.write_triangle_mesh(str(path), file_mesh, write_ascii=False,
                                      write_vertex_normals=False, write_vertex_colors=False,
                                      print_progress=False):
        raise OSError(f"open3d could not write mesh '{path}'")
    return path
