"""A robot's onboard occupancy voxel map, built only from its own LiDAR scans.

Values: ``UNKNOWN = -1``, ``FREE = 0``, ``OCCUPIED = 1`` (the robot interface's).
A voxel a ray passes through becomes FREE unless it is already OCCUPIED; the voxel
a ray ends in becomes OCCUPIED. Sensing is exact, so no log-odds are needed.
"""

from __future__ import annotations

import functools
import weakref

import numpy as np

UNKNOWN = -1
FREE = 0
OCCUPIED = 1


#: Free space is carved by samples this far apart (voxels) along each ray.
FREE_STEP_VOXELS = 0.7


@functools.lru_cache(maxsize=4)
def _sample_distances(n: int) -> np.ndarray:
    """Distances (voxels, float32) of the first ``n`` samples along a ray, rounded up to a
    power of two: ``(k + 0.5) * step`` as the samples of a scan work them out."""
    n = 1 << max(n - 1, 1023).bit_length()
    return (np.arange(n, dtype=np.float32) + np.float32(0.5)) * np.float32(FREE_STEP_VOXELS)


def _distinct(flat: np.ndarray) -> np.ndarray:
    """``np.unique(flat)`` of 1-D integers (ascending, distinct) by one sort: numpy 2.4's
    ``np.unique`` hashes first, which is 10-20x slower on these arrays (thousands to
    hundreds of thousands of scattered voxel indices, measured)."""
    s = np.sort(flat)
    return s[np.concatenate(([True], s[1:] != s[:-1]))] if len(s) else s


class ChangeLog:
    """One consumer's record of the voxels a map changed since the consumer last took
    them (a planner that updates its results incrementally); independent of
    ``take_changes`` and of other consumers' logs. Keeps the arrays of flat indices
    the map recorded, so a record costs no copy."""

    __slots__ = ("_parts", "__weakref__")

    def __init__(self) -> None:
        self._parts: list[np.ndarray] = []

    def record(self, flat: np.ndarray) -> None:
        self._parts.append(flat)

    def take(self) -> np.ndarray:
        """Flat indices (ascending, distinct) of the voxels changed since the last take."""
        parts, self._parts = self._parts, []
        return _distinct(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)


class VoxelMap:
    """Dense int8 occupancy grid with change tracking for map sharing.

    Implements the ``MapView`` protocol of ``delve.skills.robot``. Memory: one byte
    per voxel of the world's grid for ``occupancy`` (planners read it as a dense
    array, with flat indices over the world grid), one bit per voxel for the
    changes not yet taken, and the flat indices of the FREE voxels.
    """

    def __init__(self, shape: tuple[int, int, int], origin: np.ndarray, voxel_size_m: float):
        self.occupancy = np.full(shape, UNKNOWN, dtype=np.int8)
        self.origin = np.asarray(origin, dtype=float)
        self.voxel_size_m = float(voxel_size_m)
        self.version = 0
        #: Changed voxels not yet taken, one bit each (bit ``f % 8`` of byte ``f // 8``
        #: for flat index ``f``): an eighth of a bool grid, in whole 64-bit words so
        #: that take_changes finds the changes word by word.
        self._dirty = np.zeros(-(-self.occupancy.size // 64) * 8, dtype=np.uint8)
        self._free = np.zeros(0, dtype=np.int64)
        self._new_free: list[np.ndarray] = []
        self._free_stale = False
        self._refreed = False
        self._logs: weakref.WeakSet[ChangeLog] = weakref.WeakSet()
        #: Voxel indices of scan samples fit in int32 (cheaper) when flat indices do.
        self._axis_dtype = np.int32 if self.occupancy.size < 2**31 else np.int64

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.occupancy.shape  # type: ignore[return-value]

    def integrate_scan(
        self, sensor: np.ndarray, directions: np.ndarray, ranges: np.ndarray, max_range_m: float
    ) -> None:
        """Carve free space along each ray and mark the voxels the hits fall in.

        ``ranges`` is np.inf for rays without a return within ``max_range_m``.
        """
        hit = np.isfinite(ranges)
        vox = self.voxel_size_m
        occ = self.occupancy.reshape(-1)
        # Free space: samples every 0.7 voxel along each ray, up to half a voxel before
        # its hit, worked out per axis in voxel units (float32) to keep it light.
        step = np.float32(FREE_STEP_VOXELS)
        free_len = np.where(hit, ranges / vox - 0.5, max_range_m / vox).astype(np.float32)
        counts = np.maximum(np.floor(free_len / step).astype(np.int64), 0)
        total = int(counts.sum())
        if total:
            first = np.cumsum(counts) - counts
            t = _sample_distances(int(counts.max()))[np.arange(total) - np.repeat(first, counts)]
            start = ((sensor - self.origin) / vox).astype(np.float32)
            d32 = directions.astype(np.float32)
            axes = []
            for a in range(3):
                x = np.repeat(d32[:, a], counts)   # each sample's ray's direction
                x *= t
                x += start[a]
                axes.append(np.floor(x, out=x).astype(self._axis_dtype))
            self._mark(axes, occ, UNKNOWN, FREE)
        if hit.any():
            ends = (sensor + directions[hit] * (ranges[hit] + 0.25 * vox)[:, None] - self.origin) / vox
            self._mark(list(np.floor(ends).astype(np.int64).T), occ, None, OCCUPIED)
        self.version += 1

    def _mark(self, axes: list[np.ndarray], occ: np.ndarray, only: int | None, value: int) -> None:
        """Set voxels (given by per-axis indices) to ``value``: all of them inside the
        grid, or only those currently equal to ``only``."""
        nx, ny, nz = self.shape
        i, j, k = axes
        if i.dtype == np.int32:   # one unsigned comparison per axis tests both bounds
            inside = (i.view(np.uint32) < nx) & (j.view(np.uint32) < ny) & (k.view(np.uint32) < nz)
        else:
            inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny) & (k >= 0) & (k < nz)
        # Indices of samples outside the grid may wrap around in int32: they are dropped.
        flat = ((i * ny + j) * nz + k)[inside]
        was = occ[flat]
        keep = was == only if only is not None else was != value
        flat, was = flat[keep].astype(np.int64), was[keep]
        if value == FREE:
            self._new_free.append(_distinct(flat))
        elif (was == FREE).any():
            self._free_stale = True   # voxels left FREE: the list of free voxels holds them
        occ[flat] = value
        self._touch(flat)

    def _touch(self, flat: np.ndarray) -> None:
        """Record voxels ``flat`` as changed."""
        np.bitwise_or.at(self._dirty, flat >> 3, np.left_shift(1, flat & 7).astype(np.uint8))
        self._log(flat)

    def _log(self, flat: np.ndarray) -> None:
        """Record voxels ``flat`` as changed in every consumer's change log."""
        for log in self._logs:
            log.record(flat)

    def change_log(self) -> ChangeLog:
        """A new consumer's log of the voxels that change from now on (:class:`ChangeLog`)."""
        log = ChangeLog()
        self._logs.add(log)
        return log

    def set_sphere(self, centre: np.ndarray, radius_m: float, value: int) -> None:
        """Set every voxel within ``radius_m`` of ``centre`` to ``value``."""
        r = int(np.ceil(radius_m / self.voxel_size_m))
        c = np.floor((np.asarray(centre) - self.origin) / self.voxel_size_m).astype(np.int64)
        span = np.arange(-r, r + 1)
        d = np.stack(np.meshgrid(span, span, span, indexing="ij"), axis=-1).reshape(-1, 3)
        d = d[(d**2).sum(axis=1) * self.voxel_size_m**2 <= radius_m**2]
        axes = [c[a] + d[:, a] for a in range(3)]
        nx, ny, nz = self.shape
        i, j, k = axes
        inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny) & (k >= 0) & (k < nz)
        flat = ((i * ny + j) * nz + k)[inside]
        self.occupancy.reshape(-1)[flat] = value
        self._touch(flat)
        self._free_stale = True
        self._refreed = True  # a voxel set here may be freed again by a later scan
        self.version += 1

    def free_voxels(self) -> np.ndarray:
        """Flat indices of the FREE voxels, in the order they became free. Kept up to
        date as scans arrive, so planners need not scan the whole grid."""
        if self._new_free:
            self._free = np.concatenate([self._free, *self._new_free])
            self._new_free = []
        if self._free_stale:
            self._free = self._free[self.occupancy.reshape(-1)[self._free] == FREE]
            self._free_stale = False
        if self._refreed:
            _, first = np.unique(self._free, return_index=True)  # voxels freed twice
            self._free = self._free[np.sort(first)]
            self._refreed = False
        return self._free

    def take_changes(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat indices (ascending) and values of the voxels changed since the last call."""
        words = self._dirty.view(np.uint64)
        changed = np.flatnonzero(words)
        bits = np.unpackbits(self._dirty.reshape(-1, 8)[changed].reshape(-1), bitorder="little")
        at = np.flatnonzero(bits.view(bool))     # 0/1 bytes: a bool scan is the fast one
        flat = changed[at >> 6] * 64 + (at & 63)
        words[changed] = 0
        return flat, self.occupancy.reshape(-1)[flat].copy()

    def merge(self, flat: np.ndarray, values: np.ndarray) -> None:
        """Merge voxels from another map of the same geometry; OCCUPIED wins over FREE."""
        occ = self.occupancy.reshape(-1)
        current = occ[flat]
        merged = np.maximum(current, values)
        self._new_free.append(flat[(current == UNKNOWN) & (merged == FREE)])
        self._free_stale = True
        self._log(flat[merged != current])
        occ[flat] = merged
        self.version += 1
