"""delve.skills.motion: GoTo and Backtrack, on a small fake robot over a synthetic map."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import OCCUPIED
from delve.skills.motion import Backtrack, GoTo
from delve.skills.navigation import Navigator
from delve.skills.robot import PathStatus
from py_trees.common import Status

from .fakes import FakeRobot, events, make_ctx, run


@pytest.fixture(scope="module")
def tunnel():
    """A 30 m tunnel along x, mapped all along; floor at z = 1 m; start and end floor centres."""
    return syn.straight_tunnel(length_m=30)


def body(p, dx=0.0, dy=0.0):
    return np.asarray(p, float) + np.array([dx, dy, 0.5])


# ----------------------------------------------------------------------------- GoTo


def test_goto_reaches_a_goal_given_as_a_param(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    goal = body(a, 15.0)
    node = GoTo(name="Go", ctx=ctx, goal=goal.tolist(), tolerance_m=0.5)
    assert run(node, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position - goal) <= 0.5
    assert node.get(node.keys["goto_failure"]) is None
    assert events(ctx, "goto")[0]["source"] == "navigator"
    assert events(ctx, "goto_reached")


def test_goto_reads_the_goal_from_the_blackboard(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal_key="waypoint")
    py_trees.blackboard.Blackboard.set("/r1/waypoint", body(a, 10.0, 0.5).tolist())
    assert run(node, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position[:2] - body(a, 10.0, 0.5)[:2]) <= 1.0


def test_goto_fails_with_no_path_for_a_goal_inside_rock(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    rock = body(a, 10.0, 2.1)  # beside the 4 m wide tunnel: its mapped wall
    assert grid.value_at(rock[None])[0] == OCCUPIED
    node = GoTo(name="Go", ctx=ctx, goal=rock.tolist())
    assert run(node, ctx, robot) == Status.FAILURE
    assert node.get(node.keys["goto_failure"]) == "no_path"
    assert robot.paths == []
    assert events(ctx, "goto_failed")[0]["goto_failure"] == "no_path"


def test_goto_fails_with_no_path_for_a_goal_out_of_reach(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 10.0, 8.0).tolist(), planner="gbplanner")  # deep in the rock
    assert run(node, ctx, robot) == Status.FAILURE
    assert node.get(node.keys["goto_failure"]) == "no_path"


def test_goto_without_a_goal_fails(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx)
    assert run(node, ctx, robot) == Status.FAILURE
    assert node.get(node.keys["goto_failure"]) == "no_goal"


@pytest.mark.parametrize("planner", ["navigator", "gbplanner", "navigator_or_gbplanner"])
def test_goto_from_a_pose_off_the_map_is_an_invalid_start(tunnel, planner):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0, 4.5))  # inside the rock, 2.5 m from the tunnel
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 15.0).tolist(), planner=planner)
    assert run(node, ctx, robot) == Status.FAILURE
    assert node.get(node.keys["goto_failure"]) == "invalid_start"


def test_goto_with_the_global_planner(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    goal = body(a, 6.0, 1.0)  # within reach of a direct, collision-checked edge
    node = GoTo(name="Go", ctx=ctx, goal=goal.tolist(), planner="gbplanner")
    assert run(node, ctx, robot) == Status.SUCCESS
    assert events(ctx, "goto")[0]["source"] == "gbplanner2"


@pytest.mark.parametrize("planner, sources", [("navigator", ["navigator"]), ("gbplanner", ["gbplanner2"]),
                                               ("navigator_or_gbplanner", ["navigator"])])
def test_goto_takes_the_first_planner_of_its_order_that_finds_a_path(tunnel, planner, sources):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 6.0, 1.0).tolist(), planner=planner)   # both find one
    assert run(node, ctx, robot) == Status.SUCCESS
    assert [e["source"] for e in events(ctx, "goto")] == sources


@pytest.mark.parametrize("planner, result", [("navigator", "no_path"), ("navigator_or_gbplanner", "gbplanner2")])
def test_goto_falls_back_to_the_global_graph_where_the_navigation_graph_finds_none(tunnel, monkeypatch, planner,
                                                                                   result):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    monkeypatch.setattr(Navigator, "path_to_point", lambda self, point, force=False: (None, float("inf")))
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 6.0, 1.0).tolist(), planner=planner)
    status = run(node, ctx, robot)
    if result == "no_path":
        assert status == Status.FAILURE and node.get(node.keys["goto_failure"]) == "no_path"
        assert "navigation graph" in events(ctx, "goto_failed")[0]["reason"]
    else:
        assert status == Status.SUCCESS and [e["source"] for e in events(ctx, "goto")] == [result]


def test_goto_names_every_planner_it_tried_when_none_finds_a_path(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 10.0, 8.0).tolist(), planner="navigator_or_gbplanner")
    assert run(node, ctx, robot) == Status.FAILURE
    reason = events(ctx, "goto_failed")[0]["reason"]
    assert node.get(node.keys["goto_failure"]) == "no_path"
    assert reason.index("navigation graph") < reason.index("global planner")


def test_goto_replans_after_a_blocked_path_and_gives_up(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    robot.block_at = body(a, 8.0)
    robot.block_radius_m = 2.5  # the whole tunnel's width
    ctx = make_ctx(robot)
    node = GoTo(name="Go", ctx=ctx, goal=body(a, 15.0).tolist(), max_replans=2)
    assert run(node, ctx, robot) == Status.FAILURE
    assert node.get(node.keys["goto_failure"]) == "blocked"
    assert len(robot.paths) == 3


# ------------------------------------------------------------------------ Backtrack


def straight_trail(a, to_m: float) -> list[np.ndarray]:
    return [body(a, x) for x in np.arange(2.0, to_m + 1e-9, 0.5)]


def test_backtrack_goes_back_the_distance_along_the_trail(tunnel):
    grid, a, _ = tunnel
    trail = straight_trail(a, 20.0)
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    node = Backtrack(name="Back", ctx=ctx, distance_m=6.0)
    assert run(node, ctx, robot, dt_s=0.5) == Status.SUCCESS
    assert np.allclose(robot.position, body(a, 14.0), atol=1e-6)
    assert node.get(node.keys["backtracked_m"]) == pytest.approx(6.0, abs=0.01)
    assert events(ctx, "backtrack")[0]["trigger"] is True


def test_backtrack_until_a_blackboard_condition(tunnel):
    grid, a, _ = tunnel
    trail = straight_trail(a, 20.0)
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    node = Backtrack(name="Back", ctx=ctx, distance_m=None, until_key="radio_ok")
    py_trees.blackboard.Blackboard.set("/r1/radio_ok", False)
    for _ in range(5):
        node.tick_once()
        robot.step(1.0)
    assert node.status == Status.RUNNING
    py_trees.blackboard.Blackboard.set("/r1/radio_ok", True)
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert robot.path_status != PathStatus.FOLLOWING and robot.stops >= 1
    assert robot.position[0] == pytest.approx(body(a, 15.0)[0], abs=0.01)


def test_backtrack_fails_when_the_trail_ends_before_the_condition(tunnel):
    grid, a, _ = tunnel
    trail = straight_trail(a, 6.0)
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    node = Backtrack(name="Back", ctx=ctx, distance_m=None, until_key="radio_ok")
    assert run(node, ctx, robot) == Status.FAILURE
    assert np.allclose(robot.position, trail[0])


def test_backtrack_without_a_trail_fails(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    node = Backtrack(name="Back", ctx=ctx)
    assert run(node, ctx, robot) == Status.FAILURE
    assert events(ctx, "backtrack_failed")


def test_backtrack_retries_exactly_as_walked_when_a_loop_cut_is_blocked(tunnel):
    grid, a, _ = tunnel
    # Out along one side of the tunnel and back along the other, 1 m apart: the way
    # back from the end cuts straight across to the start of the first line ...
    out = [body(a, x, -0.5) for x in np.arange(2.0, 8.01, 0.5)]
    back = [body(a, x, 0.5) for x in np.arange(8.0, 1.99, -0.5)]
    trail = out + back
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    node = Backtrack(name="Back", ctx=ctx, distance_m=None, loop_radius_m=1.5)
    # ... which turns out blocked half way across: the rest of the way exactly as walked.
    robot.block_at, robot.block_radius_m = (trail[0] + trail[-1]) / 2, 0.05
    assert run(node, ctx, robot, dt_s=0.25) == Status.SUCCESS
    first, second = robot.paths
    assert np.allclose(first, [trail[0]])
    assert events(ctx, "backtrack_blocked")
    assert np.allclose(second[0], trail[-1]) and len(second) == len(trail)
    assert np.allclose(robot.position, trail[0])
