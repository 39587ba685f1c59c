"""A robot's onboard occupancy voxel map, built only from its own LiDAR scans.

Values: ``UNKNOWN = -1``, ``FREE = 0``, ``OCCUPIED = 1`` (the robot interface's).
A voxel a ray passes through becomes FREE unless it is already OCCUPIED; the voxel
a ray ends in becomes OCCUPIED. Sensing is exact, so no log-odds are needed.
"""

from __future__ import annotations

import numpy as np

UNKNOWN = -1
FREE = 0
OCCUPIED = 1


class VoxelMap:
    """Dense int8 occupancy grid with change tracking for map sharing.

    Implements the ``MapView`` protocol of ``delve.skills.robot``.
    """

    def __init__(self, shape: tuple[int, int, int], origin: np.ndarray, voxel_size_m: float):
        self.occupancy = np.full(shape, UNKNOWN, dtype=np.int8)
        self.origin = np.asarray(origin, dtype=float)
        self.voxel_size_m = float(voxel_size_m)
        self.version = 0
        self._dirty = np.zeros(shape, dtype=bool)

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.occupancy.shape  # type: ignore[return-value]

    def flat_index(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Flat voxel indices of (N, 3) points and a mask of those inside the grid."""
        idx = np.floor((points - self.origin) / self.voxel_size_m).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < np.array(self.shape)), axis=1)
        idx = idx[inside]
        return np.ravel_multi_index(idx.T, self.shape), inside

    def integrate_scan(
        self, sensor: np.ndarray, directions: np.ndarray, ranges: np.ndarray, max_range_m: float
    ) -> None:
        """Carve free space along each ray and mark the voxels the hits fall in.

        ``ranges`` is np.inf for rays without a return within ``max_range_m``.
        """
        hit = np.isfinite(ranges)
        step = 0.7 * self.voxel_size_m
        free_len = np.where(hit, ranges - 0.5 * self.voxel_size_m, max_range_m)
        counts = np.maximum(np.floor(free_len / step).astype(np.int64), 0)
        total = int(counts.sum())
        occ = self.occupancy.reshape(-1)
        if total:
            ray = np.repeat(np.arange(len(counts)), counts)
            first = np.cumsum(counts) - counts
            t = (np.arange(total) - first[ray] + 0.5) * step
            pts = sensor + directions[ray] * t[:, None]
            flat, _ = self.flat_index(pts)
            flat = flat[occ[flat] == UNKNOWN]
            occ[flat] = FREE
            self._dirty.reshape(-1)[flat] = True
        if hit.any():
            ends = sensor + directions[hit] * (ranges[hit] + 0.25 * self.voxel_size_m)[:, None]
            flat, _ = self.flat_index(ends)
            flat = flat[occ[flat] != OCCUPIED]
            occ[flat] = OCCUPIED
            self._dirty.reshape(-1)[flat] = True
        self.version += 1

    def take_changes(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat indices and values of the voxels changed since the last call."""
        flat = np.flatnonzero(self._dirty)
        self._dirty.reshape(-1)[flat] = False
        return flat, self.occupancy.reshape(-1)[flat].copy()

    def merge(self, flat: np.ndarray, values: np.ndarray) -> None:
        """Merge voxels from another map of the same geometry; OCCUPIED wins over FREE."""
        occ = self.occupancy.reshape(-1)
        current = occ[flat]
        occ[flat] = np.maximum(current, values)
        self.version += 1

    def known_fraction_of(self, flat: np.ndarray) -> float:
        """Fraction of the voxels ``flat`` that this map knows as FREE."""
        if len(flat) == 0:
            return 0.0
        return float(np.count_nonzero(self.occupancy.reshape(-1)[flat] == FREE) / len(flat))
