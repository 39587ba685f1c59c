"""delve.planners.unseen_wall: how much wall near the robot no camera has covered."""
import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.unseen_wall import unseen_wall
from delve.planners.visibility import surface_voxels


@pytest.fixture(scope="module")
def tunnel():
    """A 24 m tunnel along x, 4 m wide and 3 m high, mapped all along; floor at z = 1 m."""
    grid, start, _ = syn.straight_tunnel(length_m=24)
    return grid, start + np.array([10.0, 0.0, 1.0])


def test_all_of_the_wall_in_sight_is_unseen_before_any_camera_looked(tunnel):
    grid, eye = tunnel
    seen = np.zeros(grid.occupancy.shape, bool)
    wall = unseen_wall(grid, eye, 4.0, seen)
    assert wall.fraction > 0.9 and wall.area_m2 > 20.0
    assert np.linalg.norm(wall.centroid[:2] - eye[:2]) < 1.0  # the tunnel around the eye
    # Each unseen voxel in sight counts one voxel face.
    ijk, _ = surface_voxels(grid, eye, 4.0)
    assert wall.area_m2 <= len(ijk) * grid.voxel_size_m ** 2 + 1e-9


def test_seen_wall_does_not_count(tunnel):
    grid, eye = tunnel
    seen = np.zeros(grid.occupancy.shape, bool)
    ijk, pts = surface_voxels(grid, eye, 4.0)
    seen[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = pts[:, 2] < eye[2]  # the lower half was seen
    part = unseen_wall(grid, eye, 4.0, seen)
    assert 0.2 < part.fraction < 0.8 and part.centroid[2] > eye[2]
    seen[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    none = unseen_wall(grid, eye, 4.0, seen)
    assert (none.area_m2, none.fraction, none.centroid) == (0.0, 0.0, None)


def test_no_wall_in_reach(tunnel):
    grid, _ = tunnel
    far = np.array([-1000.0, 0.0, 0.0])
    assert unseen_wall(grid, far, 4.0, np.zeros(grid.occupancy.shape, bool)).area_m2 == 0.0
