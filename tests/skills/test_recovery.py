"""delve.skills.recovery: ResetLocalMap and NotifySupervisor, alone and in the shipped
navigation-goals subtree (no path -> tell the supervisor; invalid start -> reset the
local map and reissue), on the fake robot."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import UNKNOWN
from delve.skills.operator import GOAL_UNREACHABLE
from py_trees.common import Status

from .fakes import FakeRobot, bb, body, build, events, make_ctx


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=30)


def value_at(robot, point) -> int:
    m = robot.onboard_map
    i, j, k = ((np.asarray(point) - m.origin) // m.voxel_size_m).astype(int)
    return int(m.occupancy[i, j, k])


# --------------------------------------------------------------------- ResetLocalMap


@pytest.mark.parametrize("text, radius_m", [("type: ResetLocalMap", 2.5),
                                            ("type: ResetLocalMap\nradius_m: 1.0", 1.0)])
def test_reset_local_map_forgets_the_map_around_the_robot(tunnel, text, radius_m):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0))
    ctx = make_ctx(robot)
    version = robot.onboard_map.version
    reset = build(text, ctx)
    reset.tick_once()
    assert reset.status == Status.SUCCESS
    assert robot.map_resets == [radius_m]
    assert robot.onboard_map.version > version
    assert value_at(robot, robot.position) == UNKNOWN
    assert value_at(robot, body(a, 15.0)) != UNKNOWN  # the rest of the map is kept
    (logged,) = events(ctx, "local_map_reset")
    assert logged["trigger"] is True and logged["radius_m"] == radius_m


# ------------------------------------------------------------------ NotifySupervisor


def test_notify_supervisor_sends_the_goal_and_the_reason(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0))
    ctx = make_ctx(robot)
    ctx.clock.now_s = 12.0
    py_trees.blackboard.Blackboard.set("/r1/goal", [40.0, 6.0, 1.5])
    py_trees.blackboard.Blackboard.set("/r1/goto_failure", "no_path")
    notify = build("type: NotifySupervisor", ctx)
    notify.tick_once()
    assert notify.status == Status.SUCCESS
    (msg,) = robot.radio.sent
    assert (msg.recipient, msg.kind, msg.data, msg.sent_s) == (
        "base", GOAL_UNREACHABLE, {"goal": [40.0, 6.0, 1.5], "reason": "no_path"}, 12.0)
    (logged,) = events(ctx, "supervisor_notified")
    assert logged["trigger"] is True and logged["goal"] == [40.0, 6.0, 1.5] and logged["reason"] == "no_path"


def test_notify_supervisor_with_the_radio_down_leaves_the_message_waiting(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0))
    robot.radio.link_up = False
    ctx = make_ctx(robot)
    notify = build("type: NotifySupervisor", ctx)
    notify.tick_once()
    assert notify.status == Status.SUCCESS  # it never waits for the link
    assert robot.radio.pending == 1
    assert robot.radio.sent[0].data == {"goal": None, "reason": None}  # nothing on the blackboard


# -------------------------------------------------------- the navigation-goals subtree


def navigation_goals(robot, goal) -> tuple:
    ctx = make_ctx(robot)
    subtree = build("include: subtrees/navigation_goals.yaml", ctx)
    py_trees.blackboard.Blackboard.set("/r1/mode", "goto")
    py_trees.blackboard.Blackboard.set("/r1/goal", list(goal))
    return ctx, subtree


def tick_until_done(subtree, ctx, robot, ticks: int = 200) -> Status:
    for _ in range(ticks):
        subtree.tick_once()
        if subtree.status != Status.RUNNING:
            break
        robot.step(1.0)
        ctx.clock.now_s += 1.0
    return subtree.status


def test_a_reachable_goal_is_reached_and_the_robot_waits(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx, subtree = navigation_goals(robot, body(a, 15.0))
    assert tick_until_done(subtree, ctx, robot) == Status.FAILURE  # done: lower-priority blocks run
    assert np.linalg.norm(robot.position - body(a, 15.0)) <= 1.0
    assert bb("mode") == "idle" and robot.radio.sent == [] and robot.map_resets == []


def test_a_goal_with_no_path_is_reported_to_the_supervisor(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    rock = body(a, 10.0, 8.0)  # deep in the rock beside the tunnel
    ctx, subtree = navigation_goals(robot, rock)
    assert tick_until_done(subtree, ctx, robot) == Status.FAILURE
    (msg,) = robot.radio.sent
    assert msg.kind == GOAL_UNREACHABLE and msg.data == {"goal": rock.tolist(), "reason": "no_path"}
    assert robot.map_resets == []  # a goal out of reach is no reason to forget the map
    assert bb("mode") == "idle"


def test_an_invalid_start_resets_the_local_map_and_reissues_before_giving_up(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0, 4.5))  # odometry drift: the robot is in the rock on its map
    ctx, subtree = navigation_goals(robot, body(a, 15.0))
    resets_at = []
    for _ in range(60):
        subtree.tick_once()
        if len(robot.map_resets) > len(resets_at):
            resets_at.append(ctx.clock.now_s)
        if subtree.status != Status.RUNNING:
            break
        robot.step(1.0)
        ctx.clock.now_s += 1.0
    assert subtree.status == Status.FAILURE
    # Three attempts, each followed by a reset and 2 s (sim time) for the map to refill.
    assert robot.map_resets == [2.5] * 3
    gaps = np.diff(resets_at)
    assert len(gaps) == 2 and np.all((gaps >= 2.0) & (gaps <= 3.0))  # the 2 s, then one tick to reissue
    (msg,) = robot.radio.sent
    assert msg.data["reason"] == "invalid_start"
    assert bb("mode") == "idle"
