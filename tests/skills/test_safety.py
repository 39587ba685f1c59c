"""delve.skills.safety: the watchdog (RobotStuck), the homing timer (BudgetElapsed) and
Ping, alone and in the shipped watchdog and WiFi-safety subtrees, on the fake robot and
the sim clock."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from py_trees.common import Status

from .fakes import FakeRobot, bb, body, build, events, make_ctx

STUCK = """
type: RobotStuck
stuck_time_s: 20.0
min_motion_m: 0.3
"""


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=40)


def tick_for(node, ctx, robot, seconds: float, dt_s: float = 1.0) -> list[Status]:
    """Tick ``node`` every ``dt_s`` of sim time for ``seconds``, stepping the robot in between."""
    statuses = []
    for _ in range(round(seconds / dt_s)):
        node.tick_once()
        statuses.append(node.status)
        robot.step(dt_s)
        ctx.clock.now_s += dt_s
    return statuses


def firsts(statuses: list[Status], status: Status) -> list[int]:
    return [i for i, s in enumerate(statuses) if s == status]


# ----------------------------------------------------------------------- RobotStuck


def test_the_watchdog_fires_after_stuck_time_of_following_without_motion(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    robot.follow_path([body(a, 20.0)])
    robot.jam(1000.0)
    statuses = tick_for(stuck, ctx, robot, 45.0)
    # Ticked at 0, 1, ... s: stuck for 20 s at t = 20 s; then it watches afresh from 21 s.
    assert firsts(statuses, Status.SUCCESS) == [20, 41]
    (first, _) = events(ctx, "watchdog")
    assert first["trigger"] is True and first["node"] == "RobotStuck"
    assert np.allclose(first["position"], robot.position, atol=0.01)
    assert robot.paths and robot.stops == 0  # a condition: it neither stops nor moves the robot


def test_the_watchdog_counts_sim_time_not_ticks(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    robot.follow_path([body(a, 20.0)])
    robot.jam(1000.0)
    for _ in range(500):  # many ticks at one sim time
        stuck.tick_once()
        assert stuck.status == Status.FAILURE
    ctx.clock.now_s = 19.9
    stuck.tick_once()
    assert stuck.status == Status.FAILURE
    ctx.clock.now_s = 20.0
    stuck.tick_once()
    assert stuck.status == Status.SUCCESS


def test_no_watchdog_without_a_motion_command(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    assert set(tick_for(stuck, ctx, robot, 60.0)) == {Status.FAILURE}  # idle
    robot.follow_path([body(a, 8.0)])
    assert set(tick_for(stuck, ctx, robot, 60.0)) == {Status.FAILURE}  # walks there, then has arrived
    assert not events(ctx, "watchdog")


def test_a_robot_that_walks_is_not_stuck(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 2.0))
    ctx = make_ctx(robot)
    stuck = build(STUCK.replace("20.0", "5.0"), ctx)
    robot.follow_path([body(a, 30.0)])
    assert set(tick_for(stuck, ctx, robot, 25.0)) == {Status.FAILURE}


def test_going_away_and_back_is_motion(tunnel):
    grid, a, _ = tunnel
    start = body(a, 5.0)
    robot = FakeRobot(grid, start)
    robot.mobility.speed_mps = 0.5
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    robot.follow_path([body(a, 7.0), start] * 8)  # 2 m out and back every 8 s, for 64 s
    statuses = tick_for(stuck, ctx, robot, 56.0)
    assert np.linalg.norm(robot.position - start) < 0.3  # where it was, as often in the last 20 s
    assert set(statuses) == {Status.FAILURE}


def test_creeping_less_than_min_motion_in_stuck_time_is_stuck(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    robot.mobility.speed_mps = 0.01  # 0.2 m in 20 s
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    robot.follow_path([body(a, 20.0)])
    statuses = tick_for(stuck, ctx, robot, 21.0)
    assert firsts(statuses, Status.SUCCESS) == [20]
    robot.mobility.speed_mps = 0.02  # 0.4 m in 20 s: slow, but moving
    assert Status.SUCCESS not in tick_for(stuck, ctx, robot, 60.0)


def test_a_new_motion_command_after_a_pause_restarts_the_watch(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    stuck = build(STUCK, ctx)
    robot.follow_path([body(a, 20.0)])
    robot.jam(1000.0)
    assert set(tick_for(stuck, ctx, robot, 15.0)) == {Status.FAILURE}
    robot.stop()
    assert tick_for(stuck, ctx, robot, 1.0) == [Status.FAILURE]
    robot.follow_path([body(a, 20.0)])
    statuses = tick_for(stuck, ctx, robot, 25.0)
    assert firsts(statuses, Status.SUCCESS) == [20]  # 20 s after the new command, not 20 s after the first


def test_the_watchdog_subtree_backtracks_a_stuck_robot(tunnel):
    """trees/subtrees/watchdog.yaml: stuck for 20 s -> Recovery Homing, 5 m back along
    the traversed path; FAILURE when idle or done, so lower-priority blocks run."""
    grid, a, _ = tunnel
    trail = [body(a, x) for x in np.arange(2.0, 20.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    watchdog = build("include: subtrees/watchdog.yaml", ctx)
    robot.follow_path([body(a, 30.0)])
    robot.jam(25.0)
    statuses = tick_for(watchdog, ctx, robot, 20.0)
    assert set(statuses) == {Status.FAILURE} and len(robot.paths) == 1
    statuses = tick_for(watchdog, ctx, robot, 60.0)
    assert statuses[0] == Status.RUNNING and len(robot.paths) == 2  # backing off from t = 20 s
    assert events(ctx, "watchdog")[0]["trigger"] is True
    done = firsts(statuses, Status.FAILURE)[0]  # back 5 m, 5 s after the jam ended at 25 s
    assert set(statuses[:done]) == {Status.RUNNING} and done == pytest.approx(10, abs=1)
    assert np.allclose(robot.position, body(a, 15.0), atol=0.01)
    assert robot.path_status.value != "following"


# -------------------------------------------------------------------- BudgetElapsed


def set_budget(budget_s, start_s):
    py_trees.blackboard.Blackboard.set("/r1/time_budget_s", budget_s)
    py_trees.blackboard.Blackboard.set("/r1/budget_start_s", start_s)


def test_the_homing_timer_waits_for_a_budget(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a, 5.0)))
    timer = build("type: BudgetElapsed", ctx)
    ctx.clock.now_s = 1e6
    timer.tick_once()
    assert timer.status == Status.FAILURE  # never set
    set_budget(None, None)
    timer.tick_once()
    assert timer.status == Status.FAILURE  # explore in range: no budget
    set_budget(100.0, None)
    timer.tick_once()
    assert timer.status == Status.FAILURE
    assert not events(ctx, "homing_timer")


def test_the_homing_timer_fires_once_the_budget_has_elapsed(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a, 5.0)))
    timer = build("type: BudgetElapsed", ctx)
    set_budget(100.0, 50.0)
    statuses = []
    for now in (50.0, 149.9, 150.0, 151.0, 500.0):
        ctx.clock.now_s = now
        timer.tick_once()
        statuses.append(timer.status)
    assert statuses == [Status.FAILURE, Status.FAILURE] + [Status.SUCCESS] * 3
    (fired,) = events(ctx, "homing_timer")  # one trigger, however often it is ticked after
    assert fired["trigger"] is True and fired["budget_s"] == 100.0
    # A new budget (a new explore command) starts it again.
    set_budget(30.0, 500.0)
    timer.tick_once()
    assert timer.status == Status.FAILURE
    ctx.clock.now_s = 530.0
    timer.tick_once()
    assert timer.status == Status.SUCCESS and len(events(ctx, "homing_timer")) == 2


# ----------------------------------------------------------------------------- Ping


def ping_node(ctx, text="type: Ping"):
    node = build(text, ctx)
    node.setup()
    return node


def test_ping_starts_optimistic(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a, 5.0)))
    ping_node(ctx)
    assert bb("ping_ok") is True and bb("failed_pings") == 0


def test_ping_pings_the_base_every_period_on_the_sim_clock(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    ping = ping_node(ctx, "type: Ping\nperiod_s: 2.0")
    statuses = tick_for(ping, ctx, robot, 10.5, dt_s=0.5)
    assert set(statuses) == {Status.RUNNING}  # a background task
    assert robot.radio.pings == [(t, "base") for t in (0.0, 2.0, 4.0, 6.0, 8.0, 10.0)]


def test_ping_counts_consecutive_failures(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    ping = ping_node(ctx, "type: Ping\nperiod_s: 1.0\ntarget: relay")
    robot.radio.ping_results.extend([True, False, False, False, True, False])
    seen = []
    for _ in range(6):
        ping.tick_once()
        seen.append((bb("ping_ok"), bb("failed_pings")))
        ctx.clock.now_s += 1.0
    assert seen == [(True, 0), (False, 1), (False, 2), (False, 3), (True, 0), (False, 1)]
    assert {target for _, target in robot.radio.pings} == {"relay"}


def test_ping_notes_where_the_first_of_the_failed_pings_was_made(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    ping = ping_node(ctx, "type: Ping\nperiod_s: 1.0")
    robot.radio.ping_results.extend([True, False, False, True])
    seen = []
    for x in (5.0, 6.0, 7.0, 8.0):
        robot._pos = body(a, x)
        ping.tick_once()
        seen.append(bb("link_lost_at"))
        ctx.clock.now_s += 1.0
    assert seen[0] is None and seen[3] is None
    assert seen[1] == seen[2] == pytest.approx(list(body(a, 6.0)), abs=0.01)


def test_ping_with_the_radio_down(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    ping = ping_node(ctx)
    robot.radio.link_up = False
    tick_for(ping, ctx, robot, 10.0)  # pings at 0, 2, 4, 6, 8 s
    assert bb("ping_ok") is False and bb("failed_pings") == 5
    robot.radio.link_up = True
    tick_for(ping, ctx, robot, 2.0)
    assert bb("ping_ok") is True and bb("failed_pings") == 0


def test_wifi_safety_backs_off_until_the_base_answers(tunnel):
    """trees/subtrees/wifi_safety.yaml beside Ping: three failed pings with no time
    budget -> backtrack along the traversed path until a ping gets through."""
    grid, a, _ = tunnel
    trail = [body(a, x) for x in np.arange(2.0, 30.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    root = build("""
type: Parallel
policy: success_on_selected
selected: [WiFi safety]
children:
  - type: Ping
    period_s: 2.0
  - include: subtrees/wifi_safety.yaml
""", ctx)
    root.setup_with_descendants()
    py_trees.blackboard.Blackboard.set("/r1/time_budget_s", None)
    py_trees.blackboard.Blackboard.set("/r1/mode", "explore")
    robot.radio.link_up = False
    statuses = tick_for(root, ctx, robot, 4.0)
    assert robot.paths == []  # two failed pings (0 s, 2 s): not yet
    statuses = tick_for(root, ctx, robot, 1.0)  # the third at 4 s: back off
    assert statuses == [Status.RUNNING] and len(robot.paths) == 1
    assert bb("failed_pings") == 3
    statuses = tick_for(root, ctx, robot, 5.0)
    assert set(statuses) == {Status.RUNNING} and len(robot.paths) == 1
    robot.radio.link_up = True  # at 10 s; the next ping, at 10 s, gets through
    statuses = tick_for(root, ctx, robot, 4.0)
    assert statuses[0] == Status.FAILURE  # backed off, done: lower-priority blocks run
    assert robot.path_status.value != "following"
    assert robot.position[0] == pytest.approx(body(a, 24.0)[0], abs=0.01)  # 6 s at 1 m/s
    assert events(ctx, "backtrack")


def test_wifi_safety_keeps_out_of_the_way_with_a_time_budget(tunnel):
    grid, a, _ = tunnel
    trail = [body(a, x) for x in np.arange(2.0, 30.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    root = build("""
type: Parallel
policy: success_on_selected
selected: [WiFi safety]
children:
  - type: Ping
  - include: subtrees/wifi_safety.yaml
""", ctx)
    root.setup_with_descendants()
    py_trees.blackboard.Blackboard.set("/r1/mode", "explore")
    py_trees.blackboard.Blackboard.set("/r1/time_budget_s", 600.0)  # out of range on purpose
    robot.radio.link_up = False
    assert set(tick_for(root, ctx, robot, 20.0)) == {Status.FAILURE}
    assert bb("failed_pings") == 10 and robot.paths == []


def test_wifi_safety_stops_backing_off_when_the_supervisor_cancels(tunnel):
    """The guard is checked at every tick: a task other than exploring (cancel: idle)
    stops the back-off at once, and no back-off starts while the robot is not exploring."""
    grid, a, _ = tunnel
    trail = [body(a, x) for x in np.arange(2.0, 30.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], trail=trail)
    ctx = make_ctx(robot)
    root = build("""
type: Parallel
policy: success_on_selected
selected: [WiFi safety]
children:
  - type: Ping
  - include: subtrees/wifi_safety.yaml
""", ctx)
    root.setup_with_descendants()
    py_trees.blackboard.Blackboard.set("/r1/time_budget_s", None)
    py_trees.blackboard.Blackboard.set("/r1/mode", "explore")
    robot.radio.link_up = False
    tick_for(root, ctx, robot, 6.0)
    assert len(robot.paths) == 1 and robot.path_status.value == "following"
    py_trees.blackboard.Blackboard.set("/r1/mode", "idle")
    assert tick_for(root, ctx, robot, 1.0) == [Status.FAILURE]
    assert robot.path_status.value != "following"
    assert set(tick_for(root, ctx, robot, 10.0)) == {Status.FAILURE} and len(robot.paths) == 1


# ------------------------------------------------------------------ RememberLinkLoss


def test_the_robot_remembers_where_it_lost_the_link_once_per_place(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 20.0))
    ctx = make_ctx(robot)
    node = build("type: RememberLinkLoss\nmerge_radius_m: 2.0", ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS
    (first,) = bb("link_loss_points")
    assert first == pytest.approx(list(body(a, 20.0)), abs=0.01)
    robot._pos = body(a, 21.0)  # the same edge again: nothing new
    node.tick_once()
    robot._pos = body(a, 30.0)
    node.tick_once()
    assert len(bb("link_loss_points")) == 2
    assert [e["new"] for e in events(ctx, "link_loss")] == [True, False, True]


def test_the_robot_remembers_where_the_first_ping_failed_when_it_knows(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 24.0))
    ctx = make_ctx(robot)
    node = build("type: RememberLinkLoss", ctx)
    py_trees.blackboard.Blackboard.set(node.keys["link_lost_at"], list(body(a, 20.0)))
    node.tick_once()
    assert bb("link_loss_points")[0] == pytest.approx(list(body(a, 20.0)), abs=0.01)
