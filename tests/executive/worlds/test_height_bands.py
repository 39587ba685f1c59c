"""delve.executive.worlds.height_bands: the levels of a voxel world that a top view would
draw over each other."""
from __future__ import annotations

import math

import numpy as np
from delve.executive.worlds.height_bands import ALL_HEIGHTS, HeightBand, height_bands

VOXEL = 0.2


def levels(*slabs: tuple[int, int, int], shaft: tuple[int, int] | None = None, nz: int = 100) -> np.ndarray:
    """Free voxels: per slab (first layer, last layer + 1, side in voxels) a square drift
    level over the same ground, and a 3 x 3 shaft between layers ``shaft``."""
    free = np.zeros((40, 40, nz), dtype=bool)
    for a, b, side in slabs:
        free[:side, :side, a:b] = True
    if shaft:
        free[18:21, 18:21, shaft[0]:shaft[1]] = True
    return free


def test_two_levels_joined_by_a_shaft_are_two_bands_cut_in_the_shafts_middle():
    bands = height_bands(levels((0, 20, 40), (70, 90, 40), shaft=(20, 70)), -1.0, VOXEL)
    assert len(bands) == 2
    low, high = bands
    assert low.lo_m == -math.inf and high.hi_m == math.inf and low.hi_m == high.lo_m
    cut = round((low.hi_m + 1.0) / VOXEL)
    assert cut in (44, 45)                                               # mid-shaft: its layers are 20-69
    assert np.allclose(low.span_m, (-1.0, low.hi_m)) and np.allclose(high.span_m, (low.hi_m, 17.0))
    assert low.label == "heights -1 to 8 m" and high.label == "heights 8 to 17 m"
    points = np.array([[0, 0, -5.0], [0, 0, low.hi_m - 0.01], [0, 0, low.hi_m], [0, 0, 40.0]])
    assert low.holds(points).tolist() == [True, True, False, False]
    assert high.holds(points).tolist() == [False, False, True, True]


def test_one_level_is_every_height():
    assert height_bands(levels((10, 30, 40)), 0.0, VOXEL) == [ALL_HEIGHTS]
    assert height_bands(np.zeros((4, 4, 4), dtype=bool), 0.0, VOXEL) == [ALL_HEIGHTS]
    assert ALL_HEIGHTS.holds(np.array([[0, 0, -1e9], [1, 2, 1e9]])).all()


def test_drifts_closer_than_the_gap_are_one_level():
    gap = round(3.0 / VOXEL)
    assert len(height_bands(levels((0, 20, 40), (20 + gap - 1, 40 + gap, 40)), 0.0, VOXEL)) == 1
    assert len(height_bands(levels((0, 20, 40), (20 + gap + 1, 40 + gap, 40)), 0.0, VOXEL)) == 2


def test_a_small_gallery_above_joins_the_level_below():
    # 6 x 6 voxels over 20 layers: 2 % of the free volume; busy, but too small for a level.
    free = levels((0, 20, 40), (70, 90, 6), shaft=(20, 70))
    assert height_bands(free, 0.0, VOXEL) == [ALL_HEIGHTS]
    free = levels((0, 20, 40), (70, 90, 14), shaft=(20, 70))           # 12 %: a level of its own
    assert len(height_bands(free, 0.0, VOXEL)) == 2


def test_three_levels_keep_the_larger_neighbours_apart_from_a_small_middle_one():
    free = levels((0, 20, 40), (45, 50, 10), (80, 100, 40), nz=120)   # the middle one: 1 %
    bands = height_bands(free, 0.0, VOXEL)
    assert len(bands) == 2 and bands[0].span_m[1] <= 80 * VOXEL
    assert isinstance(bands[0], HeightBand)
