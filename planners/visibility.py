"""What an eye sees of a voxel map: the surface voxels around it, line of sight to
them, the first rock along a direction, and the view of fixed body cameras (CERBERUS
paper, section 3.5: ray casting in the planner's volumetric map).

A surface voxel is seen from an eye when it lies within range and inside the
camera's view, and the straight line to it crosses no occupied voxel other than the
voxel itself and its 26 neighbours. Rays are marched at ``SAMPLES_PER_VOXEL``
samples per voxel. Pure numpy: a map is anything with ``occupancy``, ``origin`` and
``voxel_size_m`` (a :class:`~delve.planners.occupancy.Grid`, a robot's onboard map).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .occupancy import OCCUPIED

#: Line-of-sight samples per voxel along a ray.
SAMPLES_PER_VOXEL = 2
#: Rays are marched in chunks of this many, to bound memory.
_CHUNK = 2048


class OccupancyMap(Protocol):
    """An occupancy voxel map: an int8 (nx, ny, nz) array of UNKNOWN / FREE / OCCUPIED,
    the world position of the lower corner of voxel (0, 0, 0), and the voxel size."""

    @property
    def occupancy(self) -> np.ndarray: ...

    @property
    def origin(self) -> np.ndarray: ...

    @property
    def voxel_size_m(self) -> float: ...


def surface_voxels(voxel_map: OccupancyMap, centre: np.ndarray, radius_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Occupied voxels of the map whose centres lie within ``radius_m`` of ``centre``:
    their indices (N, 3) and centre positions (N, 3)."""
    occ = voxel_map.occupancy
    origin, vox = np.asarray(voxel_map.origin, float), float(voxel_map.voxel_size_m)
    centre = np.asarray(centre, float)
    lo = np.maximum(np.floor((centre - radius_m - origin) / vox).astype(int), 0)
    hi = np.minimum(np.floor((centre + radius_m - origin) / vox).astype(int) + 1, np.array(occ.shape))
    if np.any(hi <= lo):
        return np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3))
    box = occ[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    ijk = np.argwhere(box == OCCUPIED).astype(np.int64) + lo
    pts = origin + (ijk + 0.5) * vox
    near = np.linalg.norm(pts - centre, axis=1) <= radius_m
    return ijk[near], pts[near]


def line_of_sight(voxel_map: OccupancyMap, eye: np.ndarray, target_ijk: np.ndarray) -> np.ndarray:
    """(N,) bool: whether the straight line from ``eye`` to each target voxel's centre
    crosses no occupied voxel other than the target and its 26 neighbours (so that
    surface voxels seen at a slant along their own wall still count)."""
    occ = voxel_map.occupancy
    flat_occ = occ.reshape(-1)
    origin, vox = np.asarray(voxel_map.origin, float), float(voxel_map.voxel_size_m)
    target_ijk = np.asarray(target_ijk, dtype=np.int64).reshape(-1, 3)
    out = np.ones(len(target_ijk), dtype=bool)
    shape = np.array(occ.shape, dtype=np.int32)
    start_v = ((np.asarray(eye, float) - origin) / vox).astype(np.float32)      # in voxel units
    step = np.float32(1.0 / SAMPLES_PER_VOXEL)
    for first in range(0, len(target_ijk), _CHUNK):
        ijk = target_ijk[first:first + _CHUNK].astype(np.int32)
        rel = ijk.astype(np.float32) + np.float32(0.5) - start_v
        dist = np.linalg.norm(rel, axis=1)
        if not len(dist) or dist.max() <= 0:
            continue
        t = (np.arange(math.ceil(float(dist.max()) / step), dtype=np.float32) + np.float32(0.5)) * step
        direction = rel / np.maximum(dist, np.float32(1e-6))[:, None]
        # Each ray's samples before its target only (t < dist: a prefix of t), as one
        # ragged batch: half the samples of a rectangular one.
        n = np.searchsorted(t, dist, side="left")
        ray = np.repeat(np.arange(len(ijk)), n)
        k = np.arange(len(ray)) - np.repeat(np.cumsum(n) - n, n)
        idx = np.floor(start_v + direction[ray] * t[k][:, None]).astype(np.int32)
        check = (np.abs(idx - ijk[ray]) > 1).any(axis=1) & ((idx >= 0) & (idx < shape)).all(axis=1)
        i = idx[check]
        flat = (i[:, 0].astype(np.int64) * shape[1] + i[:, 1]) * shape[2] + i[:, 2]
        blocked = np.bincount(ray[check][flat_occ[flat] == OCCUPIED], minlength=len(ijk)) > 0
        out[first:first + len(ijk)] = ~blocked
    return out


def first_hit_m(voxel_map: OccupancyMap, eye: np.ndarray, directions: np.ndarray, max_range_m: float) -> np.ndarray:
    """(K,) distance along each unit direction from ``eye`` to the first occupied voxel
    of the map; ``max_range_m`` when there is none within it."""
    occ = voxel_map.occupancy
    origin, vox = np.asarray(voxel_map.origin, float), float(voxel_map.voxel_size_m)
    step = vox / SAMPLES_PER_VOXEL
    t = (np.arange(math.ceil(max_range_m / step)) + 0.5) * step
    samples = np.asarray(eye, float) + directions[:, None, :] * t[None, :, None]
    idx = np.floor((samples - origin) / vox).astype(np.int64)
    inside = np.all((idx >= 0) & (idx < np.array(occ.shape)), axis=2)
    hit = np.zeros(inside.shape, dtype=bool)
    i = idx[inside]
    hit[inside] = occ[i[:, 0], i[:, 1], i[:, 2]] == OCCUPIED
    first = np.where(hit.any(axis=1), t[np.argmax(hit, axis=1)], max_range_m)
    return np.minimum(first, max_range_m)


def joint_directions(candidates: np.ndarray, body_yaw_rad: float) -> np.ndarray:
    """(K, 3) world unit vectors of a pan-tilt camera's optical axis at each (yaw,
    pitch) in degrees, for a body turned ``body_yaw_rad`` about the vertical."""
    yaw = np.radians(candidates[:, 0]) + body_yaw_rad
    pitch = np.radians(candidates[:, 1])
    return np.stack([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)], axis=1)


@dataclass(frozen=True)
class BodyCameras:
    """The fixed wide cameras on the body (the ANYmal's Alphasense Core): a ring
    ``horizontal_fov_deg`` wide around the heading (360: all round) and
    ``vertical_fov_deg`` high about ``pitch_deg`` of elevation, ``height_m`` above the
    body centre, that sees surface within ``range_m``."""

    range_m: float = 5.0
    horizontal_fov_deg: float = 360.0
    vertical_fov_deg: float = 60.0
    pitch_deg: float = 0.0
    height_m: float = 0.1

    def eye(self, position: np.ndarray) -> np.ndarray:
        return np.asarray(position, float) + np.array([0.0, 0.0, self.height_m])

    def in_view(self, points: np.ndarray, eye: np.ndarray, yaw_rad: float) -> np.ndarray:
        """(N,) bool: inside range and the cameras' view (ignoring occlusion)."""
        rel = np.asarray(points, float).reshape(-1, 3) - eye
        dist = np.linalg.norm(rel, axis=1)
        elevation = np.degrees(np.arctan2(rel[:, 2], np.hypot(rel[:, 0], rel[:, 1])))
        ok = (dist <= self.range_m) & (np.abs(elevation - self.pitch_deg) <= self.vertical_fov_deg / 2)
        if self.horizontal_fov_deg < 360.0:
            bearing = np.degrees(np.arctan2(rel[:, 1], rel[:, 0]) - yaw_rad)
            ok &= np.abs((bearing + 180.0) % 360.0 - 180.0) <= self.horizontal_fov_deg / 2
        return ok

    def visible(self, voxel_map: OccupancyMap, position: np.ndarray, yaw_rad: float,
                skip: np.ndarray | None = None) -> np.ndarray:
        """Indices (N, 3) of the surface voxels the cameras see from a body at
        ``position`` facing ``yaw_rad``: in range, in view and in line of sight. Voxels
        where ``skip`` ((nx, ny, nz) bool, e.g. those seen before) is True are left out
        before any ray is marched."""
        eye = self.eye(position)
        ijk, pts = surface_voxels(voxel_map, eye, self.range_m)
        ijk = ijk[self.in_view(pts, eye, yaw_rad)]
        if skip is not None:
            ijk = ijk[~skip[ijk[:, 0], ijk[:, 1], ijk[:, 2]]]
        return ijk[line_of_sight(voxel_map, eye, ijk)]


__all__ = ["SAMPLES_PER_VOXEL", "BodyCameras", "OccupancyMap", "first_hit_m", "joint_directions", "line_of_sight",
           "surface_voxels"]
