"""delve.planners.visibility: surface voxels, line of sight, first hits and the body
cameras' view on an occupancy grid."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import OCCUPIED, Grid
from delve.planners.visibility import BodyCameras, first_hit_m, joint_directions, line_of_sight, surface_voxels


@pytest.fixture(scope="module")
def tunnel():
    """A 24 m tunnel along x, 4 m wide and 3 m high, mapped all along; floor at z = 1 m."""
    return syn.straight_tunnel(length_m=24)


def test_surface_voxels_are_the_occupied_voxels_within_range(tunnel):
    grid, start, _ = tunnel
    eye = np.asarray(start, float) + np.array([8.0, 0.0, 0.5])
    ijk, pts = surface_voxels(grid, eye, 5.0)
    assert len(pts) > 100
    assert np.all(np.linalg.norm(pts - eye, axis=1) <= 5.0)
    assert np.all(grid.occupancy[ijk[:, 0], ijk[:, 1], ijk[:, 2]] == OCCUPIED)
    assert np.allclose(pts, grid.to_world(ijk))


def test_line_of_sight_is_blocked_by_rock_on_the_map():
    grid = syn.carve((12, 6, 5), 0.2, [syn.Tunnel((1, 3, 1), (11, 3, 1), 4.0, 3.0)])
    occ = grid.occupancy.copy()
    pillar = grid.to_index(np.array([[6.0, 3.0, 2.0]]))[0]
    occ[pillar[0] - 1:pillar[0] + 2, pillar[1] - 1:pillar[1] + 2, :] = OCCUPIED     # a pillar, floor to roof
    m = Grid(occ, grid.origin, grid.voxel_size_m)
    eye = np.array([3.0, 3.0, 2.0])
    far_wall = grid.to_index(np.array([[9.0, 3.0, 4.1]]))         # the roof, behind the pillar
    near_wall = grid.to_index(np.array([[4.0, 3.0, 4.1]]))        # the roof, before it
    assert occ[tuple(far_wall[0])] == OCCUPIED and occ[tuple(near_wall[0])] == OCCUPIED
    assert not line_of_sight(m, eye, far_wall)[0]
    assert line_of_sight(m, eye, near_wall)[0]


def _sight_one_ray(m: Grid, eye: np.ndarray, target: np.ndarray) -> bool:
    """The definition, one target at a time: samples half a voxel apart (float32, voxel
    units) up to the target's centre; blocked by rock outside its 26 neighbours."""
    start = ((eye - m.origin) / m.voxel_size_m).astype(np.float32)
    rel = target.astype(np.float32) + np.float32(0.5) - start
    dist = np.linalg.norm(rel)
    direction = rel / max(dist, np.float32(1e-6))
    for k in range(int(np.ceil(dist / np.float32(0.5))) + 1):
        t = (np.float32(k) + np.float32(0.5)) * np.float32(0.5)
        if not t < dist:
            break
        i = np.floor(start + direction * t).astype(np.int32)
        inside = np.all((i >= 0) & (i < np.array(m.occupancy.shape)))
        if inside and np.abs(i - target).max() > 1 and m.occupancy[tuple(i)] == OCCUPIED:
            return False
    return True


def test_line_of_sight_equals_marching_each_ray_on_its_own():
    rng = np.random.default_rng(4)
    for _ in range(6):
        occ = (rng.random((40, 40, 20)) < rng.uniform(0.02, 0.1)).astype(np.int8)
        m = Grid(occ, np.array([-1.0, 2.0, 0.5]), 0.2)
        eye = m.origin + rng.uniform([2, 2, 1], [6, 6, 3])
        ijk, _ = surface_voxels(m, eye, 4.0)
        ijk = np.vstack([ijk[:150], rng.integers(-3, 43, (20, 3))])   # some outside the grid
        seen = line_of_sight(m, eye, ijk)
        assert seen.any() and not seen.all()
        assert seen.tolist() == [_sight_one_ray(m, eye, t) for t in ijk]


def test_first_hit_is_the_nearest_rock_along_each_direction(tunnel):
    grid, start, _ = tunnel
    eye = np.asarray(start, float) + np.array([8.0, 0.0, 1.0])       # 1 m above the floor
    down, up, along = np.array([[0, 0, -1.0], [0, 0, 1.0], [1.0, 0, 0]])
    hits = first_hit_m(grid, eye, np.array([down, up, along]), 5.0)
    assert hits[0] == pytest.approx(1.0, abs=2 * grid.voxel_size_m)
    assert hits[1] == pytest.approx(2.0, abs=2 * grid.voxel_size_m)
    assert hits[2] == 5.0                                            # nothing within range


def test_joint_directions_are_unit_vectors_turned_with_the_body():
    cand = np.array([[0.0, 0.0], [90.0, 0.0], [0.0, 30.0]])
    axes = joint_directions(cand, np.pi / 2)
    assert np.allclose(np.linalg.norm(axes, axis=1), 1.0)
    assert np.allclose(axes[0], [0, 1, 0], atol=1e-12)
    assert np.allclose(axes[1], [-1, 0, 0], atol=1e-12)
    assert axes[2][2] == pytest.approx(0.5)


def test_body_cameras_see_a_band_about_the_horizon():
    cams = BodyCameras(range_m=5.0, vertical_fov_deg=60.0)
    eye = np.zeros(3)
    pts = np.array([[3.0, 0, 0], [-3.0, 0, 1.0], [1.0, 0, 2.0], [6.0, 0, 0], [0, 3.0, -1.0]])
    assert cams.in_view(pts, eye, 0.0).tolist() == [True, True, False, False, True]
    front = BodyCameras(horizontal_fov_deg=180.0)
    assert front.in_view(pts, eye, 0.0).tolist() == [True, False, False, False, True]


def test_body_cameras_see_the_walls_around_them_and_skip_what_they_are_told(tunnel):
    grid, start, _ = tunnel
    position = np.asarray(start, float) + np.array([8.0, 0.0, 0.5])
    cams = BodyCameras()
    seen = cams.visible(grid, position, 0.0)
    assert len(seen) > 50
    assert np.all(grid.occupancy[seen[:, 0], seen[:, 1], seen[:, 2]] == OCCUPIED)
    skip = np.zeros(grid.shape, bool)
    skip[seen[0, 0], seen[0, 1], seen[0, 2]] = True
    again = cams.visible(grid, position, 0.0, skip=skip)
    assert len(again) == len(seen) - 1
