"""ImprovePath: shortcuts and pushing away from obstacles, always admissible."""
import numpy as np
import pytest
from delve.planners.geometry import path_length
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.local_map import LocalMap
from delve.planners.gbplanner2.path_improvement import (
    improve_path,
    push_away_from_obstacles,
    segments_admissible,
    shortcut_path,
    truncate_path,
)

LEGGED = GBPlannerConfig.anymal_c()
AERIAL = GBPlannerConfig.rmf_obelix()


def whole(grid, cfg):
    return LocalMap(grid, grid.origin, grid.origin + np.array(grid.shape) * grid.voxel_size_m, cfg)


def zigzag(a, n, amplitude, up):
    xs = np.linspace(1.0, 14.0, n)
    ys = np.where(np.arange(n) % 2 == 0, -amplitude, amplitude)
    ys[0] = ys[-1] = 0.0
    return a + np.stack([xs, ys, np.zeros(n)], axis=1) + up


@pytest.mark.parametrize("cfg,up", [(AERIAL, np.array([0, 0, 1.5])), (LEGGED, np.array([0, 0, 0.5]))])
def test_improved_paths_stay_collision_free_and_keep_their_ends(cfg, up):
    g, a, _b = s.straight_tunnel(length_m=20, width_m=4, height_m=3, voxel_size_m=cfg.voxel_size_m)
    lm = whole(g, cfg)
    path = zigzag(a, 9, 0.8, up)
    assert segments_admissible(lm, path).all()
    better = improve_path(lm, path, cfg)
    assert segments_admissible(lm, better).all()
    assert np.allclose(better[0], path[0]) and np.allclose(better[-1], path[-1])
    assert path_length(better) < path_length(path)
    assert len(shortcut_path(lm, path)) == 2  # the tunnel is straight: one edge does


def test_push_moves_waypoints_away_from_a_wall_without_leaving_free_space():
    cfg = AERIAL
    g, a, _b = s.straight_tunnel(length_m=20, width_m=4, height_m=3, voxel_size_m=0.3)
    lm = whole(g, cfg)
    # close to the y = -2 m wall: the robot box is free only up to 0.2 m from it
    path = a + np.array([[2.0, 0, 1.5], [5.0, -1.7, 1.5], [8.0, -1.7, 1.5], [11.0, 0, 1.5]])
    assert segments_admissible(lm, path).all()
    pushed = push_away_from_obstacles(lm, path, cfg)
    assert np.all(pushed[1:3, 1] > path[1:3, 1] + 0.1)  # moved towards the middle
    assert np.all(np.linalg.norm(pushed - path, axis=1) <= cfg.path_safety_extension_m + 1e-9)
    assert segments_admissible(lm, pushed).all()


def test_truncation_cuts_at_the_length_limit():
    g, a, _b = s.straight_tunnel(length_m=30, width_m=4, height_m=3)
    lm = whole(g, LEGGED)
    path = a + np.array([[1.0, 0, 0.5], [6.0, 0, 0.5], [16.0, 0, 0.5], [25.0, 0, 0.5]])
    cut = truncate_path(lm, path, 12.0, LEGGED)
    assert path_length(cut) == pytest.approx(12.0)
    assert np.allclose(cut[-1], a + np.array([13.0, 0, 0.5]))
    assert np.array_equal(truncate_path(lm, path, 100.0, LEGGED), path)
