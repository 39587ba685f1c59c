"""Occupancy voxel grids as planners see them: plain numpy arrays.

A grid is an int8 array (nx, ny, nz) with values :data:`UNKNOWN`, :data:`FREE` and
:data:`OCCUPIED`, an ``origin`` (world position of the lower corner of voxel
(0, 0, 0)) and a ``voxel_size_m``. These values are the robot interface's
(``delve.skills.robot``) and the simulator's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

UNKNOWN = -1
FREE = 0
OCCUPIED = 1


@dataclass(frozen=True)
class Grid:
    """An occupancy array with its placement in the world."""

    occupancy: np.ndarray
    origin: np.ndarray
    voxel_size_m: float
    #: The FREE voxels' flat indices when the map keeps them: an array, or a function
    #: that gives it (asked only by the planners that need it, since bringing a large
    #: map's list up to date costs milliseconds).
    free: np.ndarray | Callable[[], np.ndarray] | None = None

    def free_voxels(self) -> np.ndarray:
        """Flat indices of the FREE voxels: ``free`` when the map keeps them, else
        found by scanning the grid."""
        if callable(self.free):
            return self.free()
        if self.free is not None:
            return self.free
        return np.flatnonzero(self.occupancy.reshape(-1) == FREE)


    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(self.occupancy.shape)  # type: ignore[return-value]

    def to_index(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) world points -> (N, 3) integer voxel indices (may be out of bounds)."""
        return np.floor((np.asarray(points, float) - self.origin) / self.voxel_size_m).astype(np.int64)

    def to_world(self, idx: np.ndarray) -> np.ndarray:
        """(N, 3) voxel indices -> (N, 3) world positions of the voxel centres."""
        return self.origin + (np.asarray(idx, float) + 0.5) * self.voxel_size_m

    def in_bounds(self, idx: np.ndarray) -> np.ndarray:
        idx = np.asarray(idx)
        return np.all((idx >= 0) & (idx < np.array(self.shape)), axis=-1)

    def value_at(self, points: np.ndarray) -> np.ndarray:
        """Occupancy at world points; UNKNOWN outside the grid."""
        idx = self.to_index(np.atleast_2d(points))
        inside = self.in_bounds(idx)
        out = np.full(len(idx), UNKNOWN, dtype=np.int8)
        i = idx[inside]
        out[inside] = self.occupancy[i[:, 0], i[:, 1], i[:, 2]]
        return out
