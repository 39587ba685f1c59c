"""Unseen wall near the robot: the surface of its onboard map within reach that no
camera has covered yet, and which it could see from where it stands.

The CERBERUS tree's inspections block takes requests "sent either by the exploration
planner or the Human Supervisor" (section 3.3.3). This is what the planner's request
is based on: a cheap measure (no joint-space search, unlike the scan points of
:mod:`.scan_points`) of how much wall around the robot is still unseen.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .visibility import OccupancyMap, line_of_sight, surface_voxels


@dataclass(frozen=True)
class UnseenWall:
    """The unseen surface within reach: its area (m², one voxel face per voxel), its
    share of all the surface within reach, and its centroid (None when there is none)."""

    area_m2: float
    fraction: float
    centroid: np.ndarray | None


def unseen_wall(voxel_map: OccupancyMap, eye: np.ndarray, radius_m: float, seen: np.ndarray) -> UnseenWall:
    """The surface voxels of ``voxel_map`` within ``radius_m`` of ``eye`` that ``seen``
    (a bool grid of the map's shape) does not mark and that ``eye`` has a line of sight
    to."""
    ijk, pts = surface_voxels(voxel_map, eye, radius_m)
    if not len(ijk):
        return UnseenWall(0.0, 0.0, None)
    unseen = ~seen[ijk[:, 0], ijk[:, 1], ijk[:, 2]]
    visible = np.zeros(len(ijk), bool)
    visible[unseen] = line_of_sight(voxel_map, np.asarray(eye, float), ijk[unseen])
    count = int(visible.sum())
    if not count:
        return UnseenWall(0.0, 0.0, None)
    area = count * float(voxel_map.voxel_size_m) ** 2
    return UnseenWall(area, count / len(ijk), pts[visible].mean(axis=0))


__all__ = ["UnseenWall", "unseen_wall"]
