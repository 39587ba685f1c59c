"""delve.skills.csiro.follow: FollowFrontierGoal goes along the topometric map, stays until
the frontier changes, and applies the failure rule (no 1 m of progress in 15 s)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import py_trees
from delve.skills.csiro import FollowFrontierGoal, SelectUavFrontier, SelectUgvFrontier, UpdateFrontiers, \
    csiro_state
from py_trees.common import Status

from ..fakes import FakeRobot, events, make_ctx, run
from .conftest import sweep
from .test_selection import ground_robot


def selected(tunnel, frontiers_at=(40.0,)):
    robot, ctx, st = ground_robot(tunnel, frontiers_at)
    SelectUgvFrontier("select", ctx).tick_once()
    return robot, ctx, st, FollowFrontierGoal("follow", ctx)


def test_goes_along_the_topometric_map_then_waits_and_fails_without_progress(tunnel):
    robot, ctx, st, node = selected(tunnel)
    run(node, ctx, robot, ticks=5)
    first = robot.paths[0]
    assert np.allclose(first[:-1, 1], 6.0) and np.allclose(np.diff(first[:-1, 0]), 3.0)   # the map's nodes
    assert np.allclose(first[-1], [40.0, 6.0, 1.5])
    assert run(node, ctx, robot, ticks=60) == Status.FAILURE        # ~30 s there, then dwell_s standing
    assert np.linalg.norm(robot.position - [40.0, 6.0, 1.5]) <= 1.0 + 1e-9       # within tolerance_m
    assert st.failed.penalised(st.summaries[("r1", 0)]) and st.goal is None
    failed = events(ctx, "csiro_goal_failed")[0]
    assert failed["key"] == ["r1", 0] and failed["reason"].startswith("still a frontier 5 s after")


def test_a_stuck_robot_fails_its_goal_after_the_progress_window(tunnel):
    robot, ctx, st, node = selected(tunnel)
    robot.jam(100.0)
    assert run(node, ctx, robot, ticks=14) == Status.RUNNING
    assert run(node, ctx, robot, ticks=3) == Status.FAILURE
    assert st.failed.penalised(st.summaries[("r1", 0)])
    assert events(ctx, "csiro_goal_failed")[0]["reason"].startswith("closest approach improved less than 1 m")


def test_explored_frontier_ends_the_goal(tunnel):
    robot, ctx, st, node = selected(tunnel)
    assert run(node, ctx, robot, ticks=5) == Status.RUNNING
    del st.summaries[("r1", 0)]
    assert run(node, ctx, robot, ticks=2) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "explored"
    assert robot.stops >= 1


def test_uav_completes_a_frontier_within_the_blacklist_radius(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, a + np.array([18.0, 0.0, 1.5]), platform="aerial")
    ctx = make_ctx(robot)
    sweep(robot, tunnel_points)
    UpdateFrontiers("update", ctx).tick_once()
    SelectUavFrontier("select", ctx).tick_once()
    st = csiro_state(ctx)
    key = py_trees.blackboard.Blackboard.storage["/r1/csiro_goal"]
    node = FollowFrontierGoal("follow", ctx, tolerance_m=0.5)
    assert run(node, ctx, robot, ticks=40) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete" and key[1] in st.blacklist


def test_an_observer_beyond_the_onboard_map_s_graph_is_approached_as_near_as_it_reaches(tunnel):
    robot, ctx, st, node = selected(tunnel, frontiers_at=(12.0,))
    goal = np.array([12.0, 30.0, 1.5])                    # beyond the tunnel's wall: no path to it
    st.summaries[("r1", 0)] = replace(st.summaries[("r1", 0)], observer=goal - [0.0, 0.0, 0.5])
    st.topometric.detach_frontier(("r1", 0))                # no topometric path either
    py_trees.blackboard.Blackboard.set("/r1/goal", goal.tolist())
    node = FollowFrontierGoal("follow", ctx, max_replans=0)
    run(node, ctx, robot, ticks=3)
    assert robot.paths and "nearest reachable" in events(ctx, "goto")[0]["source"]
    end = robot.paths[0][-2]                              # GoTo appends the goal itself
    assert abs(end[0] - 12.0) < 1.0 and end[1] > 6.5     # the tunnel's side nearest the goal
