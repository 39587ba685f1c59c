"""Unit tests of the carving geometry shared by the world generators."""

import numpy as np
import pytest

from delve.sim.worldgen_geometry import (VoxelCanvas, carve_cave_segment, carve_tunnel, landing_floor,
                                        segment_slabs)


def test_landing_floor_is_flat_at_the_ends_and_climbs_evenly_between():
    along = np.array([0.0, 2.0, 3.0, 5.0, 7.0, 8.0, 10.0])
    floor = landing_floor(along, 10.0, 1.0, 3.0, 3.0)
    np.testing.assert_allclose(floor, [1.0, 1.0, 1.0, 2.0, 3.0, 3.0, 3.0])
    np.testing.assert_allclose(landing_floor(along, 10.0, 1.0, 1.0, 3.0), 1.0)
    np.testing.assert_allclose(landing_floor(along, 10.0, 0.0, 1.0, 0.0), along / 10.0)
    with pytest.raises(ValueError, match="cannot climb"):
        landing_floor(along, 6.0, 0.0, 1.0, 3.0)


def test_carved_tunnel_floor_follows_its_landings():
    canvas = VoxelCanvas(np.array([0.0, -2.0, 0.0]), np.array([20.0, 2.0, 6.0]), 0.1)
    carve_tunnel(canvas, [0.0, 0.0, 0.0], [20.0, 0.0, 4.0], 3.0, 2.0, landing_m=4.0)

    def floor_at(x):
        i, j = (int((c - o) / 0.1) for c, o in zip((x, 0.0), canvas.origin[:2]))
        return canvas.origin[2] + (np.argmax(canvas.free[i, j]) + 0.5) * 0.1

    assert floor_at(1.0) == pytest.approx(0.05, abs=0.1)
    assert floor_at(3.9) == pytest.approx(0.05, abs=0.1)
    assert floor_at(10.0) == pytest.approx(2.0, abs=0.1)
    assert floor_at(16.5) == pytest.approx(4.0, abs=0.1)
    # the clearance samples follow the same floor
    slabs = segment_slabs([0.0, 0.0, 0.0], [20.0, 0.0, 4.0], 1.5, 2.0, landing_m=4.0)
    np.testing.assert_allclose(slabs[[0, 4, 10, 16, 20], 3], [0.0, 0.0, 2.0, 4.0, 4.0])


def test_cave_cap_floor_rises_only_beyond_a_joined_end():
    canvas = VoxelCanvas(np.array([-4.0, -3.0, 0.0]), np.array([14.0, 3.0, 5.0]), 0.1)
    shape = np.zeros((3, 2))
    carve_cave_segment(canvas, [0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 4.0, 4.0, 3.0, 3.0, shape, shape,
                       cap_rise=(0.0, 0.2))

    def floor_at(x):
        i, j = (int((c - o) / 0.1) for c, o in zip((x, 0.0), canvas.origin[:2]))
        return canvas.origin[2] + (np.argmax(canvas.free[i, j]) + 0.5) * 0.1

    assert floor_at(5.0) == pytest.approx(0.05, abs=0.1)
    assert floor_at(-1.5) == pytest.approx(0.05, abs=0.1)       # a dead end: level
    assert floor_at(11.5) == pytest.approx(0.3, abs=0.1)        # beyond a joined end: rises
