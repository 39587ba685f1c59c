"""Unit tests for delve.sim.payload: the pan-tilt-zoom inspection camera."""

import math

import networkx as nx
import numpy as np
import pytest

from delve.planners.scan_points import reachable_workspace, select_scan_points
from delve.sim.payload import PanTiltZoomCamera, PayloadSpec, joint_space_grid
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_tunnel, free_space_mesh

V = 0.25
POSE = np.array([0.0, 0.0, 0.5, 0.0])          # body at the origin, 0.5 m up, facing +x


@pytest.fixture(scope="module")
def world():
    """A 4 m wide, 3 m high tunnel along x from -10 to 10 m, with a rock pillar
    (x 2..3, y -0.5..0.5, floor to roof) ahead of the body."""
    canvas = VoxelCanvas(np.array([-10.0, -3.0, 0.0]), np.array([10.0, 3.0, 3.0]), V)
    carve_tunnel(canvas, [-10.0, 0.0, 0.0], [10.0, 0.0, 0.0], 4.0, 3.0)
    win = canvas.window([2.0 + 1e-6, -0.5 + 1e-6, 0.0], [3.0 - 1e-6, 0.5 - 1e-6, 3.0])
    canvas.free[win[0]] = False
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="payload-test", voxel_size_m=V, origin=canvas.origin, free=canvas.free,
                 mesh=mesh, centreline=nx.Graph(), start=[-5.0, 0.0, 0.01])


@pytest.fixture
def cam(world):
    return PanTiltZoomCamera(world)


def test_the_papers_1170_candidates(cam):
    grid = cam.view_directions()
    assert grid.shape == (1170, 2)
    yaws, pitches = np.unique(grid[:, 0]), np.unique(grid[:, 1])
    assert len(yaws) == 90 and len(pitches) == 13
    np.testing.assert_allclose(np.diff(yaws), 3.0)
    np.testing.assert_allclose(np.diff(pitches), 3.0)
    assert yaws.min() >= -135 and yaws.max() <= 135 and pitches.min() >= -10 and pitches.max() <= 30
    assert all(cam.within_limits(y, p) for y, p in grid)
    assert len(cam.view_directions(6.0)) == 45 * 6
    assert len(joint_space_grid((-135, 135), (-10, 30), 1.0)) == 270 * 40


def test_joint_limits(cam):
    for yaw, pitch in ((-135, -10), (135, 30), (0, 0)):
        cam.point_at(yaw, pitch)
    assert (cam.yaw_deg, cam.pitch_deg) == (0.0, 0.0)
    for yaw, pitch in ((136, 0), (-135.5, 0), (0, -10.5), (0, 31), (math.nan, 0)):
        with pytest.raises(ValueError, match="outside the joint limits"):
            cam.point_at(yaw, pitch)
    assert (cam.yaw_deg, cam.pitch_deg) == (0.0, 0.0)
    assert cam.point_at(90, 0) == pytest.approx(90 / cam.spec.slew_rate_deg_s)
    with pytest.raises(ValueError, match="zoom"):
        cam.point_at(0, 0, zoom=20)
    cam.point_at(0, 0, zoom=cam.zoom_for_distance(10.0))
    assert cam.zoom == pytest.approx(5.0)


@pytest.mark.parametrize("bad", [dict(horizontal_fov_deg=200), dict(vertical_fov_deg=0),
                                 dict(range_m=-1), dict(yaw_limits_deg=(10, -10)), dict(max_zoom=0.5)])
def test_spec_rejects_impossible_values(bad):
    with pytest.raises(ValueError, match="payload"):
        PayloadSpec(**bad)


def test_range_and_field_of_view(cam):
    eye = cam.camera_position(POSE)
    ahead = eye + np.array([[-3.0, 0.0, 0.0], [-4.9, 0.0, 0.0], [-5.5, 0.0, 0.0]])  # behind, in the tunnel
    seen_back = cam.sees(ahead, POSE, 180 - 45, 0) | cam.sees(ahead, POSE, -135, 0)
    assert not seen_back.any(), "135° of yaw does not reach straight back with a 60° view"
    left = eye + np.array([[0.0, 1.5, 0.0]])
    assert cam.sees(left, POSE, 90, 0)[0] and not cam.sees(left, POSE, 0, 0)[0]
    # ahead, short of the pillar; and 4.9 vs 5.5 m up the tunnel behind, with the camera turned
    near = eye + np.array([[1.0, 0.0, 0.0]])
    assert cam.sees(near, POSE, 0, 0)[0]
    far_left = eye + np.array([[1.0, 1.5, 0.0], [4.0, 1.8, 0.0], [5.5, 1.8, 0.0]])
    got = cam.visibility_matrix(far_left, POSE, cam.view_directions()).any(axis=1)
    assert got.tolist() == [True, True, False]


def test_occlusion_by_the_pillar(cam):
    eye = cam.camera_position(POSE)
    behind_pillar = np.array([[3.8, eye[1], eye[2]]])
    beside = np.array([[3.8, 1.5, eye[2]]])
    assert not cam.sees(behind_pillar, POSE, 0, 0)[0]
    assert cam.sees(beside, POSE, 0, 0)[0]
    # the pillar's own face is seen (points on the rock surface count)
    face = np.array([[2.0, 0.0, eye[2]]])
    assert cam.sees(face, POSE, 0, 0)[0]


def test_pitch_and_zoom_narrow_the_view(cam):
    eye = cam.camera_position(POSE)
    up = eye + np.array([[2.0, 0.0, 1.6]])        # 38.7° up
    assert not cam.sees(up, POSE, 0, 0)[0] and cam.sees(up, POSE, 0, 28)[0]
    side = eye + np.array([[1.5, 0.6, 0.0]])      # 21.8° to the left
    assert cam.sees(side, POSE, 0, 0, zoom=1.0)[0] and not cam.sees(side, POSE, 0, 0, zoom=3.0)[0]
    h, v = cam.fov_deg(1.0)
    assert (h, v) == pytest.approx((60.0, 36.0))
    assert cam.fov_deg(2.0)[0] == pytest.approx(math.degrees(2 * math.atan(math.tan(math.radians(30)) / 2)))


def test_body_pose_forms_agree(cam):
    yaw = math.radians(90)
    pose4 = np.array([-5.0, 0.0, 0.5, yaw])
    mat = np.eye(4)
    mat[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    mat[:3, 3] = [-5.0, 0.0, 0.5]
    pts = np.array([[-5.0, 1.5, 0.7], [-3.0, 0.0, 0.7], [-5.5, -1.5, 1.0], [-7.0, 0.5, 1.5]])
    cand = cam.view_directions(9.0)
    np.testing.assert_array_equal(cam.visibility_matrix(pts, pose4, cand), cam.visibility_matrix(pts, mat, cand))
    # facing +y, yaw 0 looks left of the tunnel axis, yaw -90 looks down the tunnel (+x)
    assert cam.sees(pts[:1], pose4, 0, 0)[0] and cam.sees(pts[1:2], pose4, -90, 0)[0]
    with pytest.raises(ValueError, match="body pose"):
        cam.sees(pts, np.zeros(3), 0, 0)


def test_capture_uses_the_commanded_joints(cam):
    eye = cam.camera_position(POSE)
    left = eye + np.array([[0.0, 1.5, 0.0]])
    cam.point_at(0, 0)
    assert not cam.capture(left, POSE)[0]
    cam.point_at(90, 0)
    assert cam.capture(left, POSE)[0]


def test_camera_and_scan_point_planner_together(cam, world):
    """The camera's visibility drives the planner: a full scan from scratch, a point
    scan once the front is seen, and the scans cover what they promise."""
    idx = np.argwhere(~world.free)
    pts = world.index_to_center(idx)
    pts = pts[np.linalg.norm(pts - cam.camera_position(POSE), axis=1) <= 5.0]
    cand = cam.view_directions()
    vis = cam.visibility_matrix(pts, POSE, cand)
    reach = reachable_workspace(pts, POSE, cand, vis)
    assert 0 < reach.sum() < len(pts)
    full = select_scan_points(pts[reach], POSE, cand, cam.visibility_matrix, int(reach.sum()))
    assert full.full_scan and full.covered_fraction == 1.0
    for yaw, pitch in full.scan_points:
        cam.point_at(yaw, pitch)
    seen = np.zeros(len(pts), dtype=bool)
    for yaw, pitch in full.scan_points:
        seen |= cam.sees(pts, POSE, yaw, pitch)
    assert seen[reach].all()
    front = reach & (pts[:, 0] > 0.0)
    unseen = reach & ~front
    part = select_scan_points(pts[unseen], POSE, cand, vis[unseen], int(reach.sum()))
    assert not part.full_scan and part.covered_fraction == 1.0
    assert part.n_scan_points <= full.n_scan_points
