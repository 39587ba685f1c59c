"""A voxel world's figures, and what looks wrong about it, before a long run.

:func:`survey` measures a :class:`~delve.sim.world.World`: its extent, voxels, free
volume and free regions. :func:`world_warnings` turns what looks wrong into one line
each, naming the ``world:`` key at fault where there is one:

- ``up_axis``: the world is far taller than wide (a mine read on its side);
- ``mesh``: the free volume is a tiny share of the bounding box; the mesh is open,
  or encloses solids rather than passages (its free space was built from the
  surface, see :mod:`delve.sim.freespace`);
- several disconnected free regions (robots explore only the one they start in).

Starts are checked in :mod:`delve.sim.start_landing`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .meshio import up_axis_rotation
from .world import World

#: A world more than this many times taller than its narrower horizontal extent ...
TALL_RATIO = 3.0
#: ... and taller than this gets a warning about its up axis.
TALL_MIN_M = 10.0
#: A free volume under this share of the bounding box gets a warning.
SPARSE_SHARE = 0.001
#: Free regions under this share of the free volume (specks of noise) are not counted
#: as separate regions in the warning.
REGION_MIN_SHARE = 0.01


@dataclass(frozen=True)
class Survey:
    """A world's figures: ``bounds_min``/``bounds_max`` (m), ``shape`` (voxels),
    ``free_voxels``, ``free_volume_m3``, ``box_volume_m3`` (the bounding box's),
    ``regions_m3`` (every free region's volume, largest first)."""

    bounds_min: np.ndarray
    bounds_max: np.ndarray
    shape: tuple[int, int, int]
    voxel_size_m: float
    free_voxels: int
    free_volume_m3: float
    box_volume_m3: float
    regions_m3: list[float]

    @property
    def extent_m(self) -> np.ndarray:
        return self.bounds_max - self.bounds_min

    @property
    def largest_share(self) -> float:
        """The largest free region's share of the free volume."""
        return self.regions_m3[0] / self.free_volume_m3 if self.free_volume_m3 > 0 else 0.0

    @property
    def significant_regions(self) -> list[float]:
        """The regions of at least REGION_MIN_SHARE of the free volume."""
        return [r for r in self.regions_m3 if r >= REGION_MIN_SHARE * self.free_volume_m3]


@dataclass(frozen=True)
class WorldWarning:
    """One thing that looks wrong: ``key`` is the ``world:`` key at fault (None when
    none is), ``message`` one line."""

    key: str | None
    message: str


def survey(world: World) -> Survey:
    """The figures of ``world``."""
    _, sizes = world.free_regions()
    v = world.voxel_size_m
    regions = sorted((float(n) * v ** 3 for n in sizes[1:] if n > 0), reverse=True)
    lo, hi = world.bounds_min, world.bounds_max
    free = int(sizes.sum())
    return Survey(bounds_min=lo, bounds_max=hi, shape=world.shape, voxel_size_m=v, free_voxels=free,
                  free_volume_m3=free * v ** 3, box_volume_m3=float(np.prod(hi - lo)), regions_m3=regions)


def world_warnings(world: World, figures: Survey) -> list[WorldWarning]:
    """What looks wrong about ``world`` (see the module notes), one line each."""
    out: list[WorldWarning] = []
    src = world.source
    ext = figures.extent_m
    narrow = float(min(ext[0], ext[1]))
    if ext[2] > TALL_MIN_M and ext[2] > TALL_RATIO * narrow:
        out.append(WorldWarning("up_axis", _tall_message(world, ext)))
    share = figures.free_volume_m3 / figures.box_volume_m3 if figures.box_volume_m3 > 0 else 0.0
    if share < SPARSE_SHARE:
        out.append(WorldWarning("mesh" if src else None,
                                f"free volume {figures.free_volume_m3:.1f} m³ is {share:.3%} of the "
                                f"{ext[0]:.0f} × {ext[1]:.0f} × {ext[2]:.0f} m bounding box: is the model "
                                f"read as it is meant (up axis, scale, which side of its surface is air)?"))
    if src is not None and src.closure in ("open", "solids"):
        what = (f"is open ({src.boundary_edges} boundary edges)" if src.closure == "open" else
                "encloses solids, not passages (its faces turn outwards, as a Gazebo model of boxes)")
        by = "ceiling_m" if src.ceiling_from == "scenario" else "the model top"
        out.append(WorldWarning("mesh", f"the mesh {what}: free space was built from its surface: rock "
                                        f"where it passes, a ceiling at {by}, z = {src.ceiling_z:.1f} m, the "
                                        f"floored regions under it"))
    regions = figures.significant_regions
    if len(regions) > 1:
        listed = ", ".join(f"{r:.0f}" for r in regions[:4]) + (", ..." if len(regions) > 4 else "")
        out.append(WorldWarning(None, f"{len(regions)} disconnected free regions ({listed} m³; the largest "
                                      f"{figures.largest_share:.0%} of the free volume): robots explore only "
                                      f"the region they start in"))
    return out


def _tall_message(world: World, ext: np.ndarray) -> str:
    src = world.source
    text = f"the world is {ext[2]:.0f} m tall but {min(ext[0], ext[1]):.0f} m across"
    if src is None:
        return text + ": is that meant?"
    said = {"file": f"as the file's header says, {_header(src.format, src.file_up_axis)}",
            "scenario": "as the scenario says", "default": "by default"}[src.up_axis_from]
    text += f", read with up_axis {src.up_axis} {said}"
    flattest = _flattest_axis(world, ext)
    if flattest is not None:
        text += f"; the flattest reading is up_axis: {flattest}"
    if src.up_axis_from == "file" and src.format == "Collada":
        text += " (Gazebo and RViz ignore Collada's <up_axis>, so Gazebo models often declare a wrong one)"
    return text


def _header(fmt: str, axis: str | None) -> str:
    if fmt == "Collada":
        return f"<up_axis>{(axis or 'y').upper()}_UP</up_axis>"
    return f"{fmt}: {axis} up"


def _flattest_axis(world: World, ext: np.ndarray) -> str | None:
    """The file's axis along which the model is thinnest (as the scenario's
    ``up_axis`` names it), when that is not the one used."""
    src = world.source
    rot = up_axis_rotation(src.up_axis)                 # file axes -> world axes
    file_ext = np.abs(rot.T) @ ext                      # the extents along the file's x, y, z
    axis = "xyz"[int(np.argmin(file_ext))]
    return None if axis == src.up_axis.lstrip("-") else axis
