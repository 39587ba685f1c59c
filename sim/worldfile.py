"""A :class:`~delve.sim.world.World` from a file a user already has: a mesh in any
format :mod:`delve.sim.geometry_io` reads, closed or not, or a point cloud.

1. The geometry is scaled to metres (``scale``, else the file's unit, else 1) and
   turned so that the up axis becomes +z (``up_axis``, else what the file declares,
   Collada's ``<up_axis>`` or glTF's +y, else z).
2. Free space:

   - a **closed inner surface** (watertight, faces turned to the passages): parity
     along vertical rays, exact (:func:`delve.sim.meshio.voxelise_interior`); the
     file's mesh stays the rock the LiDAR sees;
   - **any other mesh** (open scans, Gazebo slab-and-wall models, closed solids):
     rock where the surface passes and inside closed solids, a ceiling at the
     model's top (or ``ceiling_m``), and the floored regions under it
     (:mod:`delve.sim.freespace`);
   - a **point cloud**: rock around each point (``inflation_m``, one voxel by
     default); free space is what rays from ``scan_origins`` (or a ``trajectory``
     file) saw, or without them the floored regions under the ceiling.

   Worlds not from a closed inner surface get a rock mesh rebuilt around their
   free voxels (as the procedural worlds have), so that what the LiDAR sees and
   what the robots may enter agree.
3. The start is ``start`` (on the floor or in free space; ValueError otherwise),
   else a floor point near the lowest-x end of the largest free region.

The world's ``source`` (:class:`~delve.sim.world.WorldSource`) says what was done.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence

import networkx as nx
import numpy as np
import open3d as o3d

from . import freespace
from .geometry_io import Geometry, read_geometry
from .limits import DEFAULT_VOXEL_SIZE_M, check_voxels, voxel_count
from .meshio import closed_mesh_world, place_start, up_axis_rotation
from .world import World, WorldSource
from .worldgen_geometry import free_space_mesh


def from_file(path: str | Path, *, scale: float | None = None, up_axis: str | None = None,
              voxel_size_m: float = 0.2, start: Sequence[float] | None = None, ceiling_m: float | None = None,
              scan_origins: Sequence[Sequence[float]] | None = None, trajectory: str | Path | None = None,
              inflation_m: float | None = None, seeds: Sequence[Sequence[float]] = (),
              name: str | None = None) -> World:
    """A World from a mesh or point-cloud file (see the module notes).

    ``scale``: metres per file unit; ``up_axis``: the file's axis that points up
    ("x", "y", "z", "-x", ...); both default to what the file says. ``ceiling_m``:
    z (m, after scaling and turning) of the ceiling that closes an open model.
    ``scan_origins``: scanner positions (world coordinates, like ``start``);
    ``trajectory``: a file of them in the cloud's own frame (x y z per line, a
    TUM trajectory, or .npy/.pcd/.ply points). ``inflation_m``: how far rock
    reaches around each point. ``seeds``: other start points (the robots'), whose
    regions are kept even when small. ValueError for a wrong file or parameter.
    """
    path = Path(path)
    v = _positive("voxel_size_m", voxel_size_m)
    geo = read_geometry(path)
    rot, up, up_from = _up_axis(geo, up_axis)
    if scale is not None:
        factor, scale_from = _positive("scale", scale), "scenario"
    elif geo.unit_m is not None and not math.isclose(geo.unit_m, 1.0):
        factor, scale_from = geo.unit_m, "file"
    else:
        factor, scale_from = 1.0, "default"
    verts = (geo.vertices * factor) @ rot.T
    if ceiling_m is not None:
        ceiling_m = float(ceiling_m)
        if not math.isfinite(ceiling_m) or ceiling_m <= verts[:, 2].min():
            raise ValueError(f"ceiling_m {ceiling_m:g} is not above the model's bottom "
                             f"(z = {verts[:, 2].min():.2f} m)")
    _check_size(verts, v, ceiling_m, path.name, scale is not None, factor)
    src = dict(file=path.name, format=geo.format, up_axis=up, up_axis_from=up_from, file_up_axis=geo.up_axis,
               scale=factor, scale_from=scale_from)
    name = name or path.stem
    points = [list(start)] if start is not None else []
    points += [list(s) for s in seeds]
    if geo.is_points:
        world = _points_world(geo, verts, v, name, src, ceiling_m, scan_origins, trajectory, inflation_m,
                              points, rot, factor, path)
    else:
        world = _mesh_world(geo, verts, v, name, src, ceiling_m, points)
    return place_start(world, start, f"world file '{path.name}'")


def _check_size(verts: np.ndarray, v: float, ceiling_m: float | None, file: str, scaled: bool,
                factor: float) -> None:
    """ValueError before any grid is built when the model's box (up to the ceiling)
    holds more voxels than a world may (sim/limits.py); it names ``scale`` when
    the scenario gave one and the box is too large even at the default voxel size."""
    if len(verts) == 0:
        return
    lo, hi = verts.min(axis=0), verts.max(axis=0).astype(float)
    if ceiling_m is not None:
        hi[2] = max(hi[2], ceiling_m)
    extent = hi - lo
    what = f"the model in {file!r} (a box of {extent[0]:.3g} x {extent[1]:.3g} x {extent[2]:.3g} m)"
    check_voxels(voxel_count(extent, v), v, what, "scale" if scaled else None,
                 voxel_count(extent, DEFAULT_VOXEL_SIZE_M) if scaled else None)


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive number, got {value}")
    return value


def _up_axis(geo: Geometry, up_axis: str | None) -> tuple[np.ndarray, str, str]:
    if up_axis is not None:
        return up_axis_rotation(up_axis), str(up_axis).strip().lower().lstrip("+"), "scenario"
    if geo.up_axis is not None:
        return up_axis_rotation(geo.up_axis), geo.up_axis, "file"
    return up_axis_rotation("z"), "z", "default"


def _mesh_world(geo: Geometry, verts: np.ndarray, v: float, name: str, src: dict, ceiling_m: float | None,
                seeds: list) -> World:
    closure = freespace.mesh_closure(verts, geo.triangles)
    src.update(closure=closure.kind, boundary_edges=closure.boundary_edges)
    if closure.kind == "inner":
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                         o3d.utility.Vector3iVector(np.asarray(geo.triangles)))
        world = closed_mesh_world(mesh, v, name)
        if ceiling_m is not None:
            world.free[:, :, max(freespace.ceiling_index(world.origin, v, ceiling_m), 0):] = False
            src.update(ceiling_z=ceiling_m, ceiling_from="scenario")
        world.source = WorldSource(free_space="closed", **src)
        return world
    top = ceiling_m if ceiling_m is not None else float(verts[:, 2].max())
    origin, shape = freespace.grid_around(verts, v, top)
    rock = freespace.surface_rock(verts, geo.triangles, origin, shape, v, closure.solids)
    air = freespace.floored_space(rock, freespace.ceiling_index(origin, v, top))
    free = freespace.keep_regions(air, v, freespace.seed_voxels(air, origin, v, seeds))
    src.update(ceiling_z=top, ceiling_from="scenario" if ceiling_m is not None else "model top")
    return _voxel_world(free, origin, v, name, WorldSource(free_space="surface", **src))


def _points_world(geo: Geometry, verts: np.ndarray, v: float, name: str, src: dict, ceiling_m: float | None,
                  scan_origins, trajectory, inflation_m: float | None, seeds: list, rot: np.ndarray,
                  factor: float, path: Path) -> World:
    inflation = v if inflation_m is None else float(inflation_m)
    if not math.isfinite(inflation) or inflation < 0:
        raise ValueError(f"inflation_m must be >= 0, got {inflation_m}")
    origins = np.zeros((0, 3))
    if scan_origins is not None:
        origins = np.asarray(scan_origins, dtype=float).reshape(-1, 3)
    if trajectory is not None:
        traj = read_trajectory(path.parent / trajectory)
        origins = np.concatenate([origins, (traj * factor) @ rot.T])
    origins = freespace.thin_origins(origins)
    top = ceiling_m if ceiling_m is not None else float(verts[:, 2].max())
    everything = np.concatenate([verts, origins]) if len(origins) else verts
    origin, shape = freespace.grid_around(everything, v, top)
    rock = freespace.point_rock(verts, origin, shape, v, inflation)
    rock[:, :, max(freespace.ceiling_index(origin, v, top), 0):] = True
    src.update(inflation_m=inflation, ceiling_z=top,
               ceiling_from="scenario" if ceiling_m is not None else "model top")
    if len(origins):
        targets = freespace.point_voxels(verts, origin, shape, v)
        free, used = freespace.carve_scans(rock, origin, v, origins, targets)
        if used == 0:
            raise ValueError(f"no scan origin lies in free space inside the cloud of '{path.name}' "
                             f"({len(origins)} given, after thinning to {freespace.SCAN_ORIGIN_SPACING_M} m)")
        src.update(scan_origins=used)
        return _voxel_world(free, origin, v, name, WorldSource(free_space="scans", **src))
    air = freespace.floored_space(rock, freespace.ceiling_index(origin, v, top))
    free = freespace.keep_regions(air, v, freespace.seed_voxels(air, origin, v, seeds))
    return _voxel_world(free, origin, v, name, WorldSource(free_space="points", **src))


def _voxel_world(free: np.ndarray, origin: np.ndarray, v: float, name: str, source: WorldSource) -> World:
    if not free.any():
        ext = np.asarray(free.shape) * v
        how = {"scenario": "from up_axis", "file": "from the file's header", "default": "by default"}
        raise ValueError(f"world file '{source.file}' gives no free space: no region under the ceiling "
                         f"(z = {source.ceiling_z:.1f} m) has a floor below it; the model is {ext[0]:.1f} × "
                         f"{ext[1]:.1f} × {ext[2]:.1f} m read with up axis {source.up_axis} "
                         f"{how[source.up_axis_from]}: is that the axis that points up?")
    return World(name=name, voxel_size_m=v, origin=origin, free=free, mesh=free_space_mesh(free, origin, v),
                 centreline=nx.Graph(), start=np.zeros(3), source=source)


def read_trajectory(path: Path) -> np.ndarray:
    """Scanner positions (N, 3) from a trajectory file: .npy or a point cloud (.pcd,
    .ply), or text with x y z per line (a TUM trajectory, ``t x y z qx qy qz qw``,
    gives its columns 2-4; '#' starts a comment)."""
    if not path.is_file():
        raise ValueError(f"trajectory file not found: '{path.name}'")
    if path.suffix.lower() in (".npy", ".pcd", ".ply"):
        return read_geometry(path).vertices
    try:
        delimiter = "," if path.suffix.lower() == ".csv" else None
        rows = np.loadtxt(path, comments="#", delimiter=delimiter, ndmin=2)
    except ValueError:
        raise ValueError(f"cannot read trajectory '{path.name}': lines of numbers x y z (or t x y z qx qy qz "
                         f"qw) expected") from None
    if rows.shape[1] < 3:
        raise ValueError(f"cannot read trajectory '{path.name}': fewer than 3 numbers a line")
    return rows[:, 1:4] if rows.shape[1] == 8 else rows[:, :3]
