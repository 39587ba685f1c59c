"""delve.executive.worlds.height_bands: the levels of a voxel world that a top view would
draw over each other."""
from __future__ import annotations

import math

import numpy as np
from delve.executive.worlds.height_bands import ALL_HEIGHTS, height_bands

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
    assert low.layers(-1.0, VOXEL, 100) == slice(0, cut) and high.layers(-1.0, VOXEL, 100) == slice(cut, 100)


def test_one_level_is_every_height():
    assert height_bands(levels((10, 30, 40)), 0.0, VOXEL) == [ALL_HEIGHTS]
    assert height_bands(np.zeros((4, 4, 4), dtype=bool), 0.0, VOXEL) == [ALL_HEIGHTS]
    assert ALL_HEIGHTS.holds(np.array([[0, 0, -1e9], [1, 2, 1e9]])).all()


def test_drifts_at_least_the_gap_apart_are_two_levels():
    gap = round(3.0 / VOXEL)                                           # quiet layers of 3 m
    assert len(height_bands(levels((0, 20, 40), (20 + gap, 40 + gap, 40)), 0.0, VOXEL)) == 2
    assert len(height_bands(levels((0, 20, 40), (20 + gap - 1, 40 + gap, 40)), 0.0, VOXEL)) == 1


def two_levels_and_a_gallery(x: slice) -> np.ndarray:
    """Levels at layers 0-19 and 70-89 over x, y 0-40 voxels; a gallery of 13 x 13 voxels
    (busy: over a tenth of a level's layer) at layers 45-54 over ``x``: 2.6 % of the volume."""
    free = np.zeros((60, 40, 100), dtype=bool)
    free[:40, :40, 0:20] = free[:40, :40, 70:90] = True
    free[x, :13, 45:55] = True
    return free


def test_a_small_gallery_off_to_one_side_joins_the_nearer_level():
    bands = height_bands(two_levels_and_a_gallery(slice(45, 58)), 0.0, VOXEL)
    assert len(bands) == 2 and np.allclose(bands[0].span_m, (0.0, 20 * VOXEL))
    assert np.allclose(bands[1].span_m, (45 * VOXEL, 90 * VOXEL))             # the upper one, 10 layers nearer


def test_a_small_gallery_over_a_level_stays_a_level_of_its_own():
    bands = height_bands(two_levels_and_a_gallery(slice(0, 13)), 0.0, VOXEL)    # joined, it would hide drifts
    assert [b.label for b in bands] == ["heights 0 to 4 m", "heights 9 to 11 m", "heights 14 to 18 m"]
