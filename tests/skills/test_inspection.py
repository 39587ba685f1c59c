"""delve.skills.inspection and .inspection_steps: the inspection subtree and its
geometry, on a fake robot that walks a synthetic tunnel map with the simulator's
pan-tilt-zoom payload."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import py_trees
import pytest
import yaml
from delve.executive.tree_loader import build_tree, load_tree
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import Grid
from delve.sim.payload import PanTiltZoomCamera
from delve.skills.base import Skill
from delve.planners.visibility import BodyCameras, joint_directions
from delve.skills import all_skills
from delve.skills.inspection import SEEN_SERVICE, SeenRecord, body_pose, joints_toward, plan_inspection
from delve.skills.robot import PathStatus
from py_trees.common import Status

from . import fakes
from .fakes import make_ctx

TREES = Path(__file__).resolve().parents[2] / "trees"
#: Body cameras that see only a thin band about the horizon: most of the payload's
#: workspace stays unseen, so a request calls for a full scan.
NARROW = {"body_camera_vertical_fov_deg": 10.0}


def camera_robot(grid: Grid, position, payload: bool = True) -> fakes.FakeRobot:
    """The fake robot carrying the simulator's pan-tilt-zoom camera (or nothing)."""
    camera = PanTiltZoomCamera(None, occlusion_tolerance_m=grid.voxel_size_m) if payload else None
    return fakes.FakeRobot(grid, position, payload=camera)


def inspect(ctx, **params):
    """The inspection of ``trees/subtrees/inspections.yaml`` without its SuccessIsFailure
    (SUCCESS when done), each of ``params`` given to the step that declares it."""
    tree = yaml.safe_load((TREES / "subtrees" / "inspections.yaml").read_text())["child"]
    skills = all_skills()
    left = dict(params)

    def place(node):
        cls = skills.get(node["type"])
        for key in [k for k in left if cls is not None and k in cls.PARAMS]:
            node[key] = left.pop(key)
        for child in node.get("children", []):
            place(child)

    place(tree)
    assert not left, f"no step takes {sorted(left)}"
    return build_tree(tree, ctx)


class Walker(Skill):
    """A lower-priority block like Explore: follows a fixed path and, halted, stops the
    robot whatever it is doing (the behaviour the inspection must survive)."""

    def __init__(self, name, ctx, path, **kw):
        super().__init__(name, ctx, **kw)
        self.path = path
        self.following = False

    def initialise(self) -> None:
        self.following = False

    def update(self) -> Status:
        if not self.following:
            self.robot.follow_path(self.path)
            self.following = True
        return Status.RUNNING if self.robot.path_status == PathStatus.FOLLOWING else Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.following:
            self.robot.stop()
        self.following = False


def events(ctx, kind: str) -> list[dict]:
    return [dict(f, t=f.get("t")) for e, f in ctx.events if e == kind]


def step(node, ctx, robot, dt_s: float = 0.2) -> Status:
    node.tick_once()
    robot.step(dt_s)
    ctx.clock.now_s = round(ctx.clock.now_s + dt_s, 6)
    return node.status


def request(ctx, point=None, key: str = "inspection_request") -> dict:
    client = py_trees.blackboard.Client(name="test")
    client.register_key(key=f"/r1/{key}", access=py_trees.common.Access.WRITE)
    value = {"point": point, "requested_s": ctx.clock.now_s}
    client.set(f"/r1/{key}", value)
    return value


def read(key: str):
    return py_trees.blackboard.Blackboard.storage.get(f"/r1/{key}")


@pytest.fixture(autouse=True)
def clean_blackboard():
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()


@pytest.fixture(scope="module")
def tunnel():
    """A 24 m tunnel along x, 4 m wide and 3 m high, mapped all along; floor at z = 1 m."""
    return syn.straight_tunnel(length_m=24)


def body(p, dx=0.0):
    return np.asarray(p, float) + np.array([dx, 0.0, 0.5])


def straight_path(start, length_m: float, spacing_m: float = 2.0) -> np.ndarray:
    n = int(round(length_m / spacing_m))
    return np.array([start + np.array([spacing_m * (i + 1), 0.0, 0.0]) for i in range(n)])


# ------------------------------------------------------------------------- geometry
def test_joints_toward_a_point_on_a_candidates_axis_give_that_candidate():
    cam = PanTiltZoomCamera(None, occlusion_tolerance_m=0.2)
    pose = np.array([1.0, 2.0, 0.5, 0.7])
    cand = np.array([[-100.5, -8.0], [40.5, 22.0], [133.5, 28.0]])
    axes = joint_directions(cand, pose[3])
    for c, axis in zip(cand, axes, strict=True):
        target = cam.camera_position(pose) + 3.0 * axis
        assert np.allclose(joints_toward(cam, pose, target), c, atol=1e-6)
        # the axis is what the payload's own view model calls straight ahead
        assert cam.in_view(target[None], pose, c[None])[0, 0]


def test_walking_counts_what_the_body_cameras_saw_earlier(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 10))
    fresh = SeenRecord(np.zeros(grid.shape, bool))
    walked = SeenRecord(np.zeros(grid.shape, bool))
    for x in np.arange(2.0, 10.01, 1.0):             # the walk up to here, looking about
        robot._pos = body(start, x)
        walked.look(robot, BodyCameras())
    fresh.look(robot, BodyCameras())
    before = plan_inspection(robot, fresh)
    after = plan_inspection(robot, walked)
    assert before.workspace_points == after.workspace_points > 0
    assert after.selection.unseen_fraction < before.selection.unseen_fraction


def test_scan_points_cover_the_unseen_part_from_the_payloads_1170_candidates(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 8))
    record = SeenRecord(np.zeros(grid.shape, bool))
    record.look(robot, BodyCameras(vertical_fov_deg=10.0))
    plan = plan_inspection(robot, record)
    assert len(robot.payload.view_directions()) == 1170
    assert plan.selection.full_scan and plan.selection.unseen_fraction > 0.5
    assert plan.selection.covered_fraction == 1.0
    assert 0 < len(plan.scans) < 60
    # Every scan sits on the 3° grid within the joint limits, zoomed 1..10.
    for s in plan.scans:
        assert robot.payload.within_limits(s.yaw_deg, s.pitch_deg)
        assert 1.0 <= s.zoom <= 10.0


# ------------------------------------------------------------------------- the skill
def test_no_request_fails_and_keeps_recording_what_the_body_cameras_see(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 6))
    ctx = make_ctx(robot)
    node = inspect(ctx)
    assert step(node, ctx, robot) == Status.FAILURE
    record = ctx.services[SEEN_SERVICE]
    assert record.seen.sum() > 100 and record.updates == 1
    for _ in range(10):                               # 2 s at 5 Hz: once a second
        step(node, ctx, robot)
    assert record.updates == 3
    assert not events(ctx, "inspection_start")


def test_full_scan_pauses_scans_every_point_and_resumes_the_same_path(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    path = straight_path(robot.position, 12.0)
    robot.follow_path(path)
    for _ in range(5):
        robot.step(0.2)
    ctx = make_ctx(robot)
    node = inspect(ctx, dwell_s=0.5, **NARROW)
    left = robot.remaining_path
    sent = request(ctx)
    assert step(node, ctx, robot) == Status.RUNNING
    (plan,) = events(ctx, "inspection_scan_points")
    assert plan["full_scan"] and plan["mode"] == "autonomous_full_scan" and plan["unseen_fraction"] > 0.5
    (pause,) = events(ctx, "inspection_pause")
    assert np.allclose(pause["path"], left, atol=1e-3)
    assert robot.path_status == PathStatus.IDLE
    paused_at, t0 = robot.position, ctx.clock.now_s
    while not events(ctx, "inspection_resume"):
        assert step(node, ctx, robot) == Status.RUNNING
        assert ctx.clock.now_s < 200
    scans = events(ctx, "inspection_scan")
    assert len(scans) == plan["scan_points"]
    assert all(not s["moving"] and np.allclose(s["position"], paused_at, atol=1e-3) for s in scans)
    # each scan takes its slew and the dwell, in sim time
    assert ctx.clock.now_s - t0 >= plan["scan_points"] * 0.5
    # resumed on the same path: the waypoints not yet reached at the request
    (resume,) = events(ctx, "inspection_resume")
    assert resume["way_back_waypoints"] == 0
    assert np.allclose(robot.paths[-1], left) and np.allclose(resume["path"], left, atol=1e-3)
    status = Status.RUNNING
    while status == Status.RUNNING:                   # it walks the rest of the path, then ends
        status = step(node, ctx, robot)
        assert ctx.clock.now_s < 300
    assert status == Status.SUCCESS
    assert np.allclose(robot.position, path[-1])
    (done,) = events(ctx, "inspection_done")
    assert done["full_scan"] and done["covered_fraction"] > 0.95
    result = read("inspection_result")
    assert result["ok"] and result["full_scan"] and len(result["scan_points"]) == plan["scan_points"]
    assert result["requested_s"] == sent["requested_s"]
    assert read("inspection_request") is None
    # the payload's captures count as seen: a second request finds little left to scan
    robot._pos = paused_at
    request(ctx)
    step(node, ctx, robot)
    second = events(ctx, "inspection_scan_points")[-1]
    assert second["unseen_fraction"] < 0.5 * plan["unseen_fraction"]


def test_point_scan_scans_while_the_robot_walks_on(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 2))
    ctx = make_ctx(robot)
    node = inspect(ctx, dwell_s=0.3, resume_until_path_end=False)
    path = straight_path(robot.position, 16.0)
    robot.follow_path(path)
    for _ in range(25):                               # walk 5 m, the body cameras looking about
        step(node, ctx, robot)
    left = robot.remaining_path
    request(ctx)
    status = step(node, ctx, robot)
    (plan,) = events(ctx, "inspection_scan_points")
    assert not plan["full_scan"] and plan["mode"] == "autonomous_point_scan"
    assert not events(ctx, "inspection_pause")
    assert np.allclose(robot.paths[-1], left)         # the robot walks on along the same path
    while status == Status.RUNNING:
        assert robot.path_status == PathStatus.FOLLOWING
        status = step(node, ctx, robot)
    assert status == Status.SUCCESS
    scans = events(ctx, "inspection_scan")
    assert scans and all(s["moving"] for s in scans)
    assert len({tuple(s["position"]) for s in scans}) == len(scans)
    (done,) = events(ctx, "inspection_done")
    assert not done["full_scan"] and done["covered_fraction"] > 0


def test_inspections_put_the_block_below_on_hold_and_survive_its_stop(tunnel):
    """In a priority selector, the block below (here a walker that stops the robot as
    it is halted, as Explore does) is interrupted; a point scan keeps walking its path,
    and once the inspection is done the block below runs again."""
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 2))
    ctx = make_ctx(robot)
    inspection = inspect(ctx, dwell_s=0.3, resume_until_path_end=False)
    walker = Walker("Walk", ctx, straight_path(robot.position, 18.0))
    root = py_trees.composites.Selector("Blocks", memory=False, children=[
        py_trees.decorators.SuccessIsFailure("Inspections", inspection), walker])
    for _ in range(20):
        assert step(root, ctx, robot) == Status.RUNNING
    assert walker.status == Status.RUNNING
    left = robot.remaining_path
    request(ctx)
    step(root, ctx, robot)
    assert inspection.status == Status.RUNNING and walker.status == Status.INVALID
    step(root, ctx, robot)                            # the walker stopped it; the inspection walks on
    assert robot.path_status == PathStatus.FOLLOWING
    assert np.allclose(robot.paths[-1][-1], left[-1])
    while inspection.status == Status.RUNNING:
        step(root, ctx, robot)
        assert robot.path_status in (PathStatus.FOLLOWING, PathStatus.ARRIVED)
    assert events(ctx, "inspection_done")
    assert walker.status != Status.INVALID            # the block below runs again


def test_a_point_out_of_reach_fails_when_approaching_is_off(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 2))
    ctx = make_ctx(robot)
    node = inspect(ctx, approach_point=False)
    request(ctx, point=[start[0] + 15.0, start[1], 3.9])
    assert step(node, ctx, robot) == Status.FAILURE
    (failed,) = events(ctx, "inspection_failed")
    assert failed["reason"] == "point_out_of_range"
    result = read("inspection_result")
    assert result["ok"] is False and result["reason"] == "point_out_of_range"
    assert read("inspection_request") is None


def test_a_point_in_reach_is_inspected_around_it(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    ctx = make_ctx(robot)
    node = inspect(ctx, dwell_s=0.2)
    point = [start[0] + 6.5, start[1], 3.9]            # the roof, 2.5 m ahead
    request(ctx, point=point)
    status = step(node, ctx, robot)
    while status == Status.RUNNING:
        status = step(node, ctx, robot)
    assert status == Status.SUCCESS
    (plan,) = events(ctx, "inspection_scan_points")
    assert 0 < plan["workspace_points"] < 200           # the area around the point, not all about
    result = read("inspection_result")
    assert result["point"] == point and result["full_scan"] and result["covered_fraction"] == 1.0


@pytest.mark.parametrize(("point", "payload", "reason"), [
    ([1.0, 2.0], True, "bad_point"),
    ([1.0, float("nan"), 2.0], True, "bad_point"),
    (None, False, "no_payload"),
])
def test_impossible_requests_fail_with_a_reason(tunnel, point, payload, reason):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4), payload=payload)
    ctx = make_ctx(robot)
    node = inspect(ctx)
    request(ctx, point=point)
    assert step(node, ctx, robot) == Status.FAILURE
    assert events(ctx, "inspection_failed")[0]["reason"] == reason
    assert read("inspection_request") is None


def test_a_newer_request_is_kept_for_the_next_run(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    ctx = make_ctx(robot)
    node = inspect(ctx, dwell_s=0.2, **NARROW)
    request(ctx)
    step(node, ctx, robot)
    newer = request(ctx, point=[start[0] + 6.5, start[1], 3.9])
    status = Status.RUNNING
    while status == Status.RUNNING:
        status = step(node, ctx, robot)
    assert status == Status.SUCCESS
    assert read("inspection_request") == newer
    while not events(ctx, "inspection_done")[1:]:
        step(node, ctx, robot)
    assert read("inspection_request") is None


def test_the_inspections_subtree_is_idle_without_a_request(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    ctx = make_ctx(robot)
    root = load_tree(TREES / "subtrees" / "inspections.yaml", ctx)
    root.tick_once()
    assert root.status == Status.FAILURE
    request(ctx)
    root.tick_once()
    assert root.status == Status.RUNNING
    assert body_pose(robot)[:3].tolist() == robot.position.tolist()


def test_a_point_out_of_reach_is_walked_to_then_the_same_path_resumed(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 2))
    path = straight_path(robot.position, 6.0)
    robot.follow_path(path)
    robot.step(1.0)
    left = robot.remaining_path
    ctx = make_ctx(robot)
    node = inspect(ctx, dwell_s=0.2)
    request(ctx, point=[start[0] + 14.0, start[1], 3.9])             # the roof, 11 m ahead
    assert step(node, ctx, robot) == Status.RUNNING
    (approach,) = events(ctx, "inspection_approach")
    (pause,) = events(ctx, "inspection_pause")
    assert pause["reason"] == "walk to the point" and np.allclose(pause["path"], left, atol=1e-3)
    status = Status.RUNNING
    while status == Status.RUNNING:
        status = step(node, ctx, robot)
        assert ctx.clock.now_s < 120
    assert status == Status.SUCCESS
    (plan,) = events(ctx, "inspection_scan_points")
    assert plan["position"][0] > start[0] + 8.0                       # it went there first
    (resume,) = events(ctx, "inspection_resume")
    assert resume["way_back_waypoints"] > 0
    assert np.allclose(np.asarray(resume["path"])[-len(left):], left, atol=1e-3)
    assert np.allclose(robot.position, path[-1])                      # and went on to its end
    assert read("inspection_result")["covered_fraction"] > 0.9


def mode(value: str, autonomous_scans: bool = True) -> None:
    py_trees.blackboard.Blackboard.set("/r1/mode", value)
    py_trees.blackboard.Blackboard.set("/r1/autonomous_scans", autonomous_scans)


def test_the_robot_requests_a_scan_where_its_map_shows_unseen_wall(tunnel):
    """NoticeUnseenWall in the inspections subtree: exploring beside wall no camera has
    covered, the robot asks for an area scan (the supervisor's scan, from the planner),
    at most every check period and not again within min_spacing_m."""
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    ctx = make_ctx(robot)
    notice = build_tree({"type": "NoticeUnseenWall", "check_period_s": 10.0, "min_spacing_m": 6.0}, ctx)
    notice.tick_once()
    assert notice.status == Status.SUCCESS and read("inspection_request") is None  # not exploring
    mode("explore", autonomous_scans=False)
    notice.tick_once()
    assert read("inspection_request") is None  # the supervisor has not enabled it
    mode("explore")
    notice.tick_once()
    asked = read("inspection_request")
    assert asked == {"point": None, "requested_s": 0.0, "source": "planner"}
    (logged,) = events(ctx, "inspection_requested")
    assert logged["trigger"] and logged["unseen_area_m2"] >= 6.0 and logged["unseen_fraction"] >= 0.3
    py_trees.blackboard.Blackboard.set("/r1/inspection_request", None)  # the inspection took it
    robot._pos = body(start, 8)  # 4 m on: too close to the last request
    ctx.clock.now_s = 20.0
    notice.tick_once()
    assert read("inspection_request") is None
    robot._pos = body(start, 12)  # 8 m on: asks again
    ctx.clock.now_s = 25.0
    notice.tick_once()
    assert read("inspection_request") is not None and len(events(ctx, "inspection_requested")) == 2
    py_trees.blackboard.Blackboard.set("/r1/inspection_request", None)
    robot._pos = body(start, 20)  # far enough, but within the check period of that look
    ctx.clock.now_s = 30.0
    notice.tick_once()
    assert read("inspection_request") is None


def test_no_scan_is_requested_where_the_cameras_have_seen_the_wall_or_without_a_payload(tunnel):
    grid, start, _ = tunnel
    mode("explore")
    for payload in (True, False):
        robot = camera_robot(grid, body(start, 4), payload=payload)
        ctx = make_ctx(robot)
        if payload:
            ctx.services[SEEN_SERVICE] = SeenRecord(np.ones(grid.occupancy.shape, bool))  # all seen
        build_tree({"type": "NoticeUnseenWall"}, ctx).tick_once()
        assert read("inspection_request") is None and not events(ctx, "inspection_requested")


def test_a_planner_request_runs_the_same_inspection(tunnel):
    grid, start, _ = tunnel
    robot = camera_robot(grid, body(start, 4))
    ctx = make_ctx(robot)
    mode("explore")
    root = load_tree(TREES / "subtrees" / "inspections.yaml", ctx)
    root.tick_once()
    assert root.status == Status.RUNNING  # the request was taken up at once
    assert events(ctx, "inspection_requested") and events(ctx, "inspection_start")
    for _ in range(2000):
        if step(root, ctx, robot) != Status.RUNNING:
            break
    assert root.status == Status.FAILURE  # done: lower blocks run
    (done,) = events(ctx, "inspection_done")
    assert done["scans_taken"] >= 1 and read("inspection_request") is None
