"""delve.planners.gbplanner2.planning_map: the onboard map as GBPlanner2 is given it
(sealed rock surface, rock where paths were blocked) and its start pose."""
from __future__ import annotations

import numpy as np
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.local_map import LocalMap
from delve.planners.gbplanner2.planning_map import MapSealer, blocked_spot, mark_blocked_spots, sealed_grid, start_pose
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid


def test_sealed_grid_closes_one_voxel_gaps_in_the_rock_surface():
    occ = np.full((5, 5, 5), UNKNOWN, np.int8)
    occ[1:4, 1:4, 1:4] = FREE
    occ[0, :, :] = OCCUPIED
    grid = Grid(occ, np.zeros(3), 0.2)
    out = sealed_grid(grid)
    assert out.occupancy[1, 0, 0] == OCCUPIED  # unknown, touches rock
    assert out.occupancy[4, 4, 4] == UNKNOWN   # unknown, no rock beside it
    assert np.array_equal(out.occupancy == FREE, occ == FREE)
    assert grid.occupancy[1, 0, 0] == UNKNOWN  # the map itself is untouched


def test_map_sealer_equals_sealing_the_whole_grid_after_each_change():
    rng = np.random.default_rng(3)
    occ = np.full((9, 7, 6), UNKNOWN, np.int8)
    grid = Grid(occ, np.zeros(3), 0.2)
    sealer = MapSealer()
    first = sealer.update(grid)
    assert np.array_equal(first.occupancy, sealed_grid(grid).occupancy)
    for _ in range(40):
        # Scans make voxels free or rock, rock turns free, a reset makes them unknown
        # again; on the grid's faces and corners too.
        changed = rng.choice(occ.size, size=int(rng.integers(0, 12)), replace=False)
        occ.reshape(-1)[changed] = rng.choice([UNKNOWN, FREE, OCCUPIED], size=len(changed))
        out = sealer.update(grid, changed)
        assert np.array_equal(out.occupancy, sealed_grid(grid).occupancy)
    assert out.occupancy is first.occupancy   # one array, kept up to date
    assert sealer.update(Grid(np.full((4, 4, 4), OCCUPIED, np.int8), np.zeros(3), 0.2), changed).shape == (4, 4, 4)


def test_blocked_spot_and_its_rock():
    path = np.array([[0.0, 0.0, 1.5], [2.0, 0.0, 1.5], [2.0, 2.0, 1.5]])
    assert np.allclose(blocked_spot(np.array([1.0, 0.0, 1.5]), path, 0.7), [1.7, 0.0, 1.5])
    # At a corner: towards the next waypoint, not the one reached.
    assert np.allclose(blocked_spot(np.array([2.0, 0.0, 1.5]), path, 0.7), [2.0, 0.7, 1.5])
    assert blocked_spot(np.zeros(3), None, 0.7) is None
    occ = np.zeros((20, 20, 15), np.int8)
    grid = Grid(occ, np.zeros(3), 0.2)
    out = mark_blocked_spots(grid, [np.array([2.0, 2.0, 1.5])], 0.3, 0.7)
    rock = np.argwhere(out.occupancy == OCCUPIED)
    assert len(rock) and grid.occupancy.max() == 0
    centres = grid.to_world(rock)
    assert np.all(np.hypot(centres[:, 0] - 2.0, centres[:, 1] - 2.0) <= 0.3 + 0.2)
    assert centres[:, 2].min() >= 0.7 and centres[:, 2].max() <= 1.9 + 1e-9
    assert mark_blocked_spots(grid, [], 0.3, 0.7) is grid


def test_start_pose_moves_off_the_wall_only_when_the_robot_box_touches_rock():
    grid, a, _ = syn.straight_tunnel(length_m=20)         # 4 m wide: walls at y = a[1] -/+ 2 m
    cfg = GBPlannerConfig.anymal_c()
    middle = np.asarray(a, float) + np.array([8.0, 0.0, 0.5])
    assert np.allclose(start_pose(grid, cfg, middle, 0.4), middle)
    at_wall = middle + np.array([0.0, 2.0 - 0.5 * cfg.robot_box_size_m[1] + 0.1, 0.0])
    lm = LocalMap(grid, at_wall - 2.0, at_wall + 2.0, cfg)
    assert lm.box_has_occupied(at_wall)
    clear = start_pose(grid, cfg, at_wall, 0.4)
    assert 0 < np.linalg.norm(clear - at_wall) <= 0.4 + 1e-9 and not lm.box_has_occupied(clear)
    assert np.allclose(start_pose(grid, cfg, at_wall, 0.0), at_wall)     # 0: off
