"""The adaptive local bounding box (PCA of the local point cloud)."""
import math

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.bounds import adaptive_local_bound, local_point_cloud
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.occupancy import UNKNOWN, Grid

CFG = GBPlannerConfig.anymal_c()


@pytest.mark.parametrize("yaw_deg", [0.0, 30.0, 100.0])
def test_pca_box_aligns_with_the_tunnel_axis(yaw_deg):
    g, a, b = s.straight_tunnel(length_m=40, width_m=4, height_m=3, yaw_deg=yaw_deg)
    axis = (b - a) / np.linalg.norm(b - a)
    p = (a + b) / 2 + np.array([0, 0, 0.5])
    box = adaptive_local_bound(g, p, CFG)
    assert abs(box.axes[:, 0] @ axis) > 0.99  # first axis along the tunnel
    assert abs(box.axes[:, 2][2]) > 0.95  # smallest spread: the height
    assert np.allclose(box.axes.T @ box.axes, np.eye(3), atol=1e-9)
    # long along the tunnel (clipped to the largest size), narrow across it
    assert box.half_extents_m[0] == pytest.approx(CFG.bounding_box_size_max_m / 2)
    assert box.half_extents_m[1] < 3.5
    assert box.contains(p[None])[0]
    corners = box.corners()
    assert corners.shape == (8, 3)
    lo, hi = box.aabb()
    assert np.all(lo <= p) and np.all(p <= hi)


def test_box_sides_never_below_the_minimum_and_samples_stay_inside():
    g, a, b = s.straight_tunnel(length_m=30, width_m=2, height_m=2)
    p = (a + b) / 2 + np.array([0, 0, 0.5])
    box = adaptive_local_bound(g, p, CFG)
    mins = np.sort(CFG.bounding_box_size_min_m)[::-1] / 2
    assert np.all(box.half_extents_m >= mins - 1e-12)
    pts = box.sample(np.random.default_rng(0), 500)
    assert box.contains(pts).all()


def test_too_few_points_gives_an_axis_aligned_minimum_box():
    g = Grid(np.full((20, 20, 20), UNKNOWN, np.int8), np.zeros(3), 0.2)
    p = np.array([2.0, 2.0, 2.0])
    assert len(local_point_cloud(g, p, CFG)) == 0
    box = adaptive_local_bound(g, p, CFG)
    assert np.allclose(box.axes, np.eye(3))
    assert np.allclose(2 * box.half_extents_m, sorted(CFG.bounding_box_size_min_m, reverse=True))
    assert math.isclose(box.volume_m3, float(np.prod(CFG.bounding_box_size_min_m)))
