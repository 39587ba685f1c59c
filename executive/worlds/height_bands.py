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
#: Measured against the busiest layer, a level of small drifts over a large cavern whose
#: layers hold ten times as much may stay quiet, and the two one band.
BUSY_SHARE = 0.1
#: Runs of busy layers with at least this much (m) of quiet layers between them are bands of
#: their own: more than a drift's height, less than the 8-10 m of rock between a level's roof
#: and the next level's floor.
MIN_GAP_M = 3.0
#: A band with less free volume than this share of the world's joins a neighbour whose
#: footprint it overlaps by at most :data:`MAX_HIDDEN_SHARE` of its own (a gallery off to
#: one side); one it would hide stays a band.
MIN_VOLUME_SHARE = 0.1
MAX_HIDDEN_SHARE = 0.1


@dataclass(frozen=True)
class HeightBand:
    """Heights ``lo_m <= z < hi_m`` (the lowest band open below, the highest above);
    ``span_m``: the heights its free space fills, for labels."""

    lo_m: float = -math.inf
    hi_m: float = math.inf
    span_m: tuple[float, float] = (-math.inf, math.inf)

    def holds_heights(self, z: np.ndarray) -> np.ndarray:
        """Whether each of the heights ``z`` (m) lies in the band."""
        return (z >= self.lo_m) & (z < self.hi_m)

    def holds(self, points: np.ndarray) -> np.ndarray:
        """Whether each of ``points`` ((N, 3), m) lies in the band."""
        return self.holds_heights(np.asarray(points, float).reshape(-1, 3)[:, 2])

    def layers(self, origin_z: float, voxel_size_m: float, nz: int) -> slice:
        """The voxel layers (of ``nz`` from ``origin_z``) whose centres lie in the band, as
        a slice: a grid's ``[..., band.layers(...)]`` is a view, not a copy."""
        at = np.flatnonzero(self.holds_heights(origin_z + (np.arange(nz) + 0.5) * voxel_size_m))
        return slice(int(at[0]), int(at[-1]) + 1) if len(at) else slice(0, 0)

    def within(self, points: np.ndarray) -> np.ndarray:
        """The ``points`` ((N, 3), m) that lie in the band."""
        points = np.asarray(points, float).reshape(-1, 3)
        return points[self.holds(points)]

    @property
    def label(self) -> str:
        """The heights its free space fills, rounded to metres."""
        return f"heights {self.span_m[0]:.0f} to {self.span_m[1]:.0f} m"


#: Every height: a world of one band.
ALL_HEIGHTS = HeightBand()


def height_bands(free: np.ndarray, origin_z: float, voxel_size_m: float) -> list[HeightBand]:
    """The bands (lowest first) of a world whose free voxels are ``free`` (nx, ny, nz):
    runs of busy layers (:data:`BUSY_SHARE`) with at least :data:`MIN_GAP_M` of quiet
    layers between them, cut at the emptiest of those; a band with less than
    :data:`MIN_VOLUME_SHARE` of the free volume joins a neighbour it would not hide.
    One band, :data:`ALL_HEIGHTS`, when the world does not split."""
    counts = np.count_nonzero(free, axis=(0, 1))
    if not counts.any():
        return [ALL_HEIGHTS]
    busy = np.flatnonzero(counts >= BUSY_SHARE * counts.max())
    quiet = np.diff(busy) - 1
    gaps = np.flatnonzero(quiet * voxel_size_m >= MIN_GAP_M - 1e-9)
    cuts = _join_small([_cut(counts, int(busy[g]) + 1, int(busy[g + 1])) for g in gaps], free, counts)
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


def _join_small(cuts: list[int], free: np.ndarray, counts: np.ndarray) -> list[int]:
    """``cuts`` without those between a small band (:data:`MIN_VOLUME_SHARE`) and the
    neighbour whose footprint it overlaps least (the nearer one of two alike), where that
    overlap is at most :data:`MAX_HIDDEN_SHARE` of its own footprint; the smallest first."""
    cuts = list(cuts)
    kept: set[int] = set()   # small bands that would hide either neighbour
    layer = np.arange(len(counts))
    while cuts:
        spans = list(zip([0, *cuts], [*cuts, len(counts)]))
        small = [i for i, (a, b) in enumerate(spans)
                 if counts[a:b].sum() < MIN_VOLUME_SHARE * counts.sum() and i not in kept]
        if not small:
            break
        i = min(small, key=lambda k: counts[slice(*spans[k])].sum())
        own = free[..., slice(*spans[i])].any(axis=2)

        def centre(k: int) -> float:
            a, b = spans[k]
            return float(np.average(layer[a:b], weights=counts[a:b]))

        # Per neighbour: the columns band i shares with it, then how far apart their centres are.
        costs = {j: (np.count_nonzero(own & free[..., slice(*spans[j])].any(axis=2)), abs(centre(j) - centre(i)))
                 for j in (i - 1, i + 1) if 0 <= j < len(spans)}
        j = min(costs, key=costs.__getitem__)
        if costs[j][0] > MAX_HIDDEN_SHARE * np.count_nonzero(own):
            kept.add(i)
            continue
        del cuts[min(i, j)]
        kept = set()   # band numbers shift, and the joined band is judged again
    return cuts
