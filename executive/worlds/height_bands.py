"""Height bands of a voxel world: the levels that a top view would draw over each other.

A two-level mine's upper drifts run 12-15 m above its lower ones, often straight over
them; a single top view then shows one on top of the other and no path can be told apart.
``map.png`` and the preview's ``top.png`` draw one top view per band instead.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: A layer of voxels is busy when it holds at least this share of the busiest layer's free
#: voxels (a ramp or shaft between two levels holds about 2 %, a level's drifts 30-100 %).
BUSY_SHARE = 0.1
#: Busy layers closer than this (m) are one band: more than a drift's height, less than the
#: 8-10 m of rock between a level's roof and the next level's floor.
MIN_GAP_M = 3.0
#: A band with less free volume than this share of the world's joins its neighbour.
MIN_VOLUME_SHARE = 0.1


@dataclass(frozen=True)
class HeightBand:
    """Heights ``lo_m <= z < hi_m`` (the lowest band open below, the highest above);
    ``span_m``: the heights its free space fills, for labels."""

    lo_m: float = -math.inf
    hi_m: float = math.inf
    span_m: tuple[float, float] = (-math.inf, math.inf)

    def holds(self, points: np.ndarray) -> np.ndarray:
        """Whether each of ``points`` ((N, 3), m) lies in the band."""
        return self.holds_heights(np.asarray(points, float).reshape(-1, 3)[:, 2])

    def holds_heights(self, z: np.ndarray) -> np.ndarray:
        """Whether each of the heights ``z`` (m) lies in the band."""
        return (z >= self.lo_m) & (z < self.hi_m)

    @property
    def label(self) -> str:
        return f"heights {self.span_m[0]:.0f} to {self.span_m[1]:.0f} m"


#: Every height: a world of one band.
ALL_HEIGHTS = HeightBand()


def height_bands(free: np.ndarray, origin_z: float, voxel_size_m: float) -> list[HeightBand]:
    """The bands (lowest first) of a world whose free voxels are ``free`` (nx, ny, nz):
    runs of busy layers (:data:`BUSY_SHARE`) at least :data:`MIN_GAP_M` apart, split at
    the emptiest layer between them, each with at least :data:`MIN_VOLUME_SHARE` of the
    free volume. One band, :data:`ALL_HEIGHTS`, when the world does not split."""
    counts = np.count_nonzero(free, axis=(0, 1))
    if not counts.any():
        return [ALL_HEIGHTS]
    busy = np.flatnonzero(counts >= BUSY_SHARE * counts.max())
    gaps = np.flatnonzero(np.diff(busy) > round(MIN_GAP_M / voxel_size_m))
    cuts = [_cut(counts, int(busy[g]) + 1, int(busy[g + 1])) for g in gaps]
    while cuts:
        edges = [0, *cuts, len(counts)]
        shares = [counts[a:b].sum() / counts.sum() for a, b in zip(edges, edges[1:])]
        small = int(np.argmin(shares))
        if shares[small] >= MIN_VOLUME_SHARE:
            break
        # Join the small band to its smaller neighbour (the only one at either end).
        above = small < len(cuts) and (small == 0 or shares[small + 1] <= shares[small - 1])
        del cuts[small if above else small - 1]
    if not cuts:
        return [ALL_HEIGHTS]
    edges = [0, *cuts, len(counts)]
    bands = []
    for i, (a, b) in enumerate(zip(edges, edges[1:])):
        filled = a + np.flatnonzero(counts[a:b])
        bands.append(HeightBand(lo_m=-math.inf if i == 0 else origin_z + a * voxel_size_m,
                                hi_m=math.inf if b == len(counts) else origin_z + b * voxel_size_m,
                                span_m=(origin_z + filled[0] * voxel_size_m,
                                        origin_z + (filled[-1] + 1) * voxel_size_m)))
    return bands


def _cut(counts: np.ndarray, a: int, b: int) -> int:
    """The first layer of the band above a cut between layers ``a`` and ``b`` (exclusive):
    the emptiest one, the nearest the middle of them where several are (a shaft's layers)."""
    low = a + np.flatnonzero(counts[a:b] == counts[a:b].min())
    return int(low[np.argmin(np.abs(low - (a + b - 1) / 2))])
