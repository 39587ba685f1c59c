"""Where a camera detection is: rays through the pixels of its bounding box cast into
the robot's voxel map, and the median of their first hits (CERBERUS paper, section
3.5, "Detection filtering" and Figure 19).

Rays are marched by :func:`~delve.planners.visibility.first_hit_m` (numpy, all rays
at once, two samples per voxel), the same ray caster the inspection skill uses on
the same maps. A hit lands at most one sample step (half a voxel, 10 cm on 0.2 m
voxels) past the face of the voxel it enters, far below the 5 m scoring radius;
a ray that only grazes the corner of a voxel may skip it, which the median over
the box's rays absorbs. An exact 3D DDA would walk voxel by voxel in a Python
loop per step; open3d's RaycastingScene casts against triangles (the map would have
to be meshed at every call) and VoxelBlockGrid is a TSDF store, neither of which
fits an int8 map that changes every LiDAR scan.
"""
from __future__ import annotations

import numpy as np

from ..occupancy import Grid
from ..visibility import first_hit_m
from .params import CameraFusionParams

#: Rays marched at once, to bound memory (rays x samples x 3 floats).
_CHUNK = 512


def locate(occupancy: np.ndarray, origin: np.ndarray, voxel_size_m: float, ray_origin: np.ndarray,
           rays: np.ndarray, max_range_m: float,
           min_hits: int = CameraFusionParams.min_ray_hits) -> np.ndarray | None:
    """The (3,) median, per coordinate, of the first points where ``rays`` ((K, 3)
    directions, normalised here) from ``ray_origin`` enter an OCCUPIED voxel of the
    int8 map ``occupancy`` (lower corner of voxel (0, 0, 0) at ``origin``), or None
    when fewer than ``min_hits`` rays hit. A ray that leaves the grid, or passes
    ``max_range_m``, without entering an occupied voxel does not count: unknown and
    free voxels are seen through."""
    rays = np.asarray(rays, float).reshape(-1, 3)
    norms = np.linalg.norm(rays, axis=1)
    rays = rays[norms > 0] / norms[norms > 0, None]
    if len(rays) < min_hits:
        return None
    grid = Grid(np.asarray(occupancy), np.asarray(origin, float), float(voxel_size_m))
    eye = np.asarray(ray_origin, float)
    dist = np.concatenate([first_hit_m(grid, eye, rays[i:i + _CHUNK], max_range_m)
                           for i in range(0, len(rays), _CHUNK)])
    hit = dist < max_range_m      # first_hit_m says max_range_m for "no hit within range"
    if hit.sum() < min_hits:
        return None
    return np.median(eye + rays[hit] * dist[hit, None], axis=0)


__all__ = ["locate"]
