"""delve.planners.artifacts.ray_hits: a detection located by the median first hit of
its bounding box's rays on the voxel map."""
from __future__ import annotations

import numpy as np
from delve.planners.artifacts.ray_hits import locate
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN

VOXEL = 0.2
ORIGIN = np.array([-2.0, -4.0, -4.0])
SHAPE = (50, 40, 40)          # x in [-2, 8), y and z in [-4, 4)


def _map(wall: bool, fill: int = FREE) -> np.ndarray:
    occ = np.full(SHAPE, fill, dtype=np.int8)
    if wall:
        occ[35, :, :] = OCCUPIED          # voxels x in [5.0, 5.2)
    return occ


def _box_rays(n: int = 7, half_angle_deg: float = 5.0) -> np.ndarray:
    """A bounding box's rays around +x: an n x n fan of directions."""
    a = np.radians(np.linspace(-half_angle_deg, half_angle_deg, n))
    yaw, pitch = np.meshgrid(a, a)
    return np.stack([np.ones(yaw.size), np.tan(yaw.ravel()), np.tan(pitch.ravel())], axis=1)


def test_rays_from_the_origin_hit_the_wall_at_x_5():
    hit = locate(_map(wall=True), ORIGIN, VOXEL, np.zeros(3), _box_rays(), max_range_m=10.0)
    assert hit is not None
    assert 5.0 <= hit[0] <= 5.0 + VOXEL / 2 + 1e-9          # at most one half-voxel sample step past the face
    assert np.allclose(hit[1:], 0.0, atol=VOXEL)


def test_the_median_ignores_a_few_rays_that_go_astray():
    occ = _map(wall=True)
    occ[15, 20, 20] = OCCUPIED              # one voxel at x = 1 m that catches 9 of the 81 rays
    hit = locate(occ, ORIGIN, VOXEL, np.zeros(3), _box_rays(n=9, half_angle_deg=20.0), max_range_m=10.0)
    assert 5.0 <= hit[0] <= 5.1


def test_rays_through_unknown_or_free_only_locate_nothing():
    for fill in (FREE, UNKNOWN):
        assert locate(_map(wall=False, fill=fill), ORIGIN, VOXEL, np.zeros(3), _box_rays(), 10.0) is None


def test_a_wall_beyond_max_range_or_too_few_hits_locate_nothing():
    assert locate(_map(wall=True), ORIGIN, VOXEL, np.zeros(3), _box_rays(), max_range_m=4.5) is None
    one_ray = np.array([[1.0, 0.0, 0.0]])
    assert locate(_map(wall=True), ORIGIN, VOXEL, np.zeros(3), one_ray, 10.0, min_hits=3) is None
    assert locate(_map(wall=True), ORIGIN, VOXEL, np.zeros(3), one_ray, 10.0, min_hits=1) is not None


def test_rays_leaving_the_grid_do_not_count():
    occ = _map(wall=True)
    sideways = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])    # out through y and z faces
    assert locate(occ, ORIGIN, VOXEL, np.zeros(3), sideways, 50.0, min_hits=1) is None
    rays = np.vstack([sideways, _box_rays(n=3)])                                   # 3 astray + 9 on the wall
    assert locate(occ, ORIGIN, VOXEL, np.zeros(3), rays, 50.0, min_hits=9) is not None
    assert locate(occ, ORIGIN, VOXEL, np.zeros(3), rays, 50.0, min_hits=10) is None


def test_directions_need_not_be_unit_and_many_rays_are_chunked():
    rays = np.repeat(_box_rays(n=3) * 7.0, 200, axis=0)       # 1800 rays, longer than one chunk
    hit = locate(_map(wall=True), ORIGIN, VOXEL, np.zeros(3), rays, max_range_m=10.0)
    assert 5.0 <= hit[0] <= 5.1
