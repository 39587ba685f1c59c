"""delve.planners.trail: the way back along the traversed path, loops cut out where
the map shows the shortcut passable."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from delve.planners.trail import TrailWalk, backtrack_path, jump_check


def test_backtrack_path_cuts_loops_out():
    out = [(x, 0.0, 1.5) for x in np.arange(0.0, 10.01, 0.5)]      # out along x to 10
    back = [(x, 0.0, 1.5) for x in np.arange(9.5, 4.99, -0.5)]     # back to 5 (a dead end)
    side = [(5.0, y, 1.5) for y in np.arange(0.5, 5.01, 0.5)]      # then along y
    trail = np.array(out + back + side)
    path = backtrack_path(trail)
    assert np.allclose(path[0], trail[-1]) and np.allclose(path[-1], trail[0])
    assert path[:, 0].max() <= 5.0 + 1e-9  # the dead end beyond x = 5 is skipped
    length = np.linalg.norm(np.diff(path, axis=0), axis=1).sum()
    assert length == pytest.approx(10.0, abs=1.0)
    exact = backtrack_path(trail, loop_radius_m=0.0)
    assert len(exact) == len(trail) and np.allclose(exact, trail[::-1])


def test_backtrack_path_stops_after_distance():
    trail = np.array([(x, 0.0, 1.5) for x in np.arange(0.0, 20.01, 0.5)])
    path = backtrack_path(trail, 4.2)
    assert np.allclose(path[0], trail[-1])
    assert np.allclose(path[-1], (20.0 - 4.2, 0.0, 1.5))


def test_exact_rest_of_a_walk_goes_back_to_the_leg_it_was_on():
    trail = np.array([(0, 0, 1.5), (1, 0, 1.5), (2, 0, 1.5), (2, 1, 1.5), (1.4, 0.2, 1.5)], float)
    walk = TrailWalk.plan(trail, loop_radius_m=0.75)
    assert list(walk.indices) == [4, 1, 0]  # the loop through (2, 0) and (2, 1) cut out
    # Blocked half way along the jump 4 -> 1: back to 4, then every point as walked.
    rest = walk.exact_rest(np.array([1.2, 0.1, 1.5]))
    assert np.allclose(rest, trail[::-1])


def test_jump_check_refuses_a_trench_for_a_legged_robot():
    occ = np.full((40, 10, 15), UNKNOWN, np.int8)
    occ[:, :, 5:] = FREE
    occ[:, :, 4] = OCCUPIED                   # floor at z = 1.0 (voxel 4 top)
    occ[18:22, :, 4] = FREE                   # a 0.8 m trench with its bottom 0.6 m lower
    occ[18:22, :, 1] = OCCUPIED
    occ[18:22, :, 2:4] = FREE
    grid = Grid(occ, np.zeros(3), 0.2)
    ok = jump_check(grid, aerial=False, body_height_m=0.5, max_step_m=0.3)
    assert ok(np.array([1.0, 1.0, 1.5]), np.array([3.0, 1.0, 1.5]))
    assert not ok(np.array([3.2, 1.0, 1.5]), np.array([4.8, 1.0, 1.5]))
    aerial = jump_check(grid, aerial=True, body_height_m=0.5, max_step_m=0.3)
    assert aerial(np.array([3.2, 1.0, 1.5]), np.array([4.8, 1.0, 1.5]))
