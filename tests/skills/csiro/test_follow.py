"""delve.skills.csiro.follow: FollowFrontierGoal goes along the topometric map, stays until
the frontier changes, and applies the failure rule (no 1 m of progress in 15 s)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import py_trees
from delve.planners.csiro.frontier_types import Frontier
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN
from delve.skills.csiro import FollowFrontierGoal, SelectUavFrontier, SelectUgvFrontier, UpdateFrontiers, csiro_state
from delve.skills.csiro.follow import reachable_near, way_lengths
from delve.skills.navigation import navigator
from py_trees.common import Status

from ..fakes import FakeRobot, bb, events, make_ctx, run
from .conftest import sweep, uav_with_frontiers
from .test_selection import ground_robot, summary


def fly(node, ctx, robot, points=None, ticks: int = 40) -> Status:
    """``run`` with the look ``node`` asks for (``look_due``) taken on the next tick: a sweep of
    ``points`` from where the robot is through ``UpdateFrontiers``, or with ``points`` None a
    frontier update that sees nothing new (the frontiers stay as they are)."""
    update, st = UpdateFrontiers("update", ctx), csiro_state(ctx)
    for _ in range(ticks):
        if st.look_due and points is None:
            st.frontiers.update(ctx.clock.now_s, robot.position, np.zeros((0, 3)))
            st.look_due = False
        elif st.look_due:
            sweep(robot, points)
            update.tick_once()
        node.tick_once()
        if node.status != Status.RUNNING:
            return node.status
        robot.step(1.0)
        ctx.clock.now_s += 1.0
    return node.status


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


def test_a_way_that_first_leads_away_from_a_distant_frontier_is_progress(tunnel):
    robot, ctx, st = ground_robot(tunnel, ())                 # r1 walked from x = 7 to 45
    for x in np.arange(45.0, 24.0, -1.0):
        node = st.topometric.add_pose("r2", 100.0 - x, [x, 7.5, 1.5])   # r2 from x = 45 back to 25
        if x == 45.0:
            st.topometric.connect(st.topometric.last_node("r1"), node)
    robot._pos = np.array([35.0, 6.0, 1.5])                   # the only way to x = 25 leads by x = 45
    s = st.summaries[("r1", 0)] = summary("r1", 0, 25.0)
    st.topometric.attach_frontier(s.key, "r2", 75.0, np.array([25.0, 7.5, 1.5]))
    SelectUgvFrontier("select", ctx).tick_once()
    node = FollowFrontierGoal("follow", ctx)
    assert run(node, ctx, robot, ticks=25) == Status.RUNNING  # 10 m away from it, then back towards it
    assert max(p[0] for p in robot.trail) >= 44.5 and robot.position[0] < 35.0
    assert not events(ctx, "csiro_goal_failed")


def test_time_away_while_interrupted_is_no_lack_of_progress(tunnel):
    robot, ctx, st, node = selected(tunnel)
    robot.jam(10.0)
    assert run(node, ctx, robot, ticks=10) == Status.RUNNING   # stuck 10 s: within the 15 s window
    node.stop(Status.INVALID)                                  # explore-sync takes over ...
    ctx.clock.now_s += 120.0                                   # ... and gives the robot back later
    SelectUgvFrontier("select", ctx).tick_once()
    assert run(node, ctx, robot, ticks=3) == Status.RUNNING and not events(ctx, "csiro_goal_failed")


def test_explored_frontier_ends_the_goal(tunnel):
    robot, ctx, st, node = selected(tunnel)
    assert run(node, ctx, robot, ticks=5) == Status.RUNNING
    del st.summaries[("r1", 0)]
    assert run(node, ctx, robot, ticks=2) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "explored"
    assert robot.stops >= 1


def test_uav_completes_a_frontier_within_the_blacklist_radius(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    SelectUavFrontier("select", ctx).tick_once()
    key = py_trees.blackboard.Blackboard.storage["/r1/csiro_goal"]
    node = FollowFrontierGoal("follow", ctx, tolerance_m=0.5)
    assert fly(node, ctx, robot) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete" and key[1] in st.blacklist


def test_a_uav_within_eta_blacklist_of_its_frontier_completes_it_only_after_a_look_from_there(
        tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    SelectUavFrontier("select", ctx).tick_once()
    key = bb("csiro_goal")
    node = FollowFrontierGoal("follow", ctx, tolerance_m=0.5)
    assert run(node, ctx, robot, ticks=40) == Status.RUNNING              # no sweep: it waits
    centre = next(f for f in st.frontiers.frontiers if f.id == key[1]).mean
    assert np.linalg.norm(robot.position - centre) <= 3.0 and st.look_due
    assert node.feedback_message.startswith("within eta_blacklist") and not events(ctx, "csiro_goal_done")
    assert fly(node, ctx, robot, ticks=2) == Status.SUCCESS                 # the look leaves it as it was
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete" and key[1] in st.blacklist


def test_a_frontier_that_a_look_from_within_eta_blacklist_moves_on_is_not_complete(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    SelectUavFrontier("select", ctx).tick_once()
    key = bb("csiro_goal")
    node = FollowFrontierGoal("follow", ctx, tolerance_m=0.5)
    for _ in range(20):                                         # on until the tick that takes a look
        looking = st.look_due
        assert fly(node, ctx, robot, tunnel_points, ticks=1) == Status.RUNNING
        if looking:
            break
    ahead = next(f for f in st.frontiers.frontiers if f.id == key[1])
    assert looking and np.linalg.norm(ahead.mean - robot.position) > 3.0      # it moved on down the tunnel
    assert key[1] not in st.blacklist and not events(ctx, "csiro_goal_done")


def test_a_uav_flies_on_to_a_place_within_eta_blacklist_of_the_centre_rather_than_stop_short(
        tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)          # at x = a + 18, mid-drift
    centre = a + [28.0, 4.0, 1.5]                               # in the rock 2 m beyond the wall, ahead
    place = reachable_near(ctx, robot, centre)[1]
    assert 2.0 < np.linalg.norm(place - centre) < 3.0           # 1 m short of that place is out of 3 m
    at_wall = a + [28.0, 1.6, 1.5]                              # the part of it in sight, at the wall
    st.frontiers._frontiers = {99: Frontier(id=99, points=np.array([centre, at_wall]),
                                            normals=np.array([[0.0, 1.0, 0.0]] * 2), areas=np.array([20.0, 5.0]),
                                            mean=centre, cov=np.diag([4.0, 0.01, 4.0]))}
    SelectUavFrontier("select", ctx).tick_once()
    assert bb("csiro_goal") == ["r1", 99] and np.allclose(bb("goal"), place)
    assert fly(FollowFrontierGoal("follow", ctx, tolerance_m=1.0), ctx, robot) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete" and not events(ctx, "csiro_goal_failed")


def test_a_completed_uav_frontier_stays_blacklisted_until_it_is_updated(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    select = SelectUavFrontier("select", ctx)
    select.tick_once()
    key = py_trees.blackboard.Blackboard.storage["/r1/csiro_goal"]
    assert fly(FollowFrontierGoal("follow", ctx, tolerance_m=0.5), ctx, robot) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete"
    f = next(f for f in st.frontiers.frontiers if f.id == key[1])
    st.frontiers.discard([g.id for g in st.frontiers.frontiers if g.id != key[1]])   # only this one is left
    away = (robot.position - f.mean) * [1.0, 1.0, 0.0]
    robot._pos = robot.position + 2.0 * away / np.linalg.norm(away)        # back out of eta_blacklist of it
    assert np.linalg.norm(robot.position - f.mean) > 3.0
    st.momentum = None
    select.tick_once()
    assert select.status != Status.SUCCESS                        # complete, and unchanged: not again
    on = -1.5 * away / np.linalg.norm(away)                      # Algorithm 2 updated it, 1.5 m on, same id
    st.frontiers._frontiers[key[1]] = replace(f, mean=f.mean + on, points=f.points + on)
    select.tick_once()
    assert select.status == Status.SUCCESS and py_trees.blackboard.Blackboard.storage["/r1/csiro_goal"] == key


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


def test_a_teammate_s_frontier_is_done_on_reaching_its_observer_and_the_place_joins_the_trajectory(tunnel):
    robot, ctx, st = ground_robot(tunnel, ())
    for x in np.arange(7.0, 46.0, 1.0):
        node = st.topometric.add_pose("r2", x, [x, 6.5, 1.5])
        if node is not None:
            st.topometric.connect(node, ("r1", node[1]))          # r2 walked beside r1
    s = st.summaries[("r2", 0)] = summary("r2", 0, 12.0)
    st.topometric.attach_frontier(s.key, "r2", 12.0, s.observer + [0, 0, 0.5])
    SelectUgvFrontier("select", ctx).tick_once()
    before = len(st.trajectory)
    assert run(FollowFrontierGoal("follow", ctx), ctx, robot, ticks=30) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "reached a teammate's frontier"
    assert not events(ctx, "csiro_goal_failed")                  # only r2 could have changed it
    assert len(st.trajectory) == before + 1
    assert np.linalg.norm(st.trajectory.points()[-1] - [12.0, 6.0, 1.5]) <= 1.0


def test_an_own_frontier_that_changes_while_the_robot_stands_there_is_done(tunnel):
    robot, ctx, st, node = selected(tunnel, frontiers_at=(12.0,))
    for _ in range(20):
        run(node, ctx, robot, ticks=1)
        if node.feedback_message.startswith("at the goal"):
            break
    assert node.status == Status.RUNNING and node.feedback_message.startswith("at the goal")
    st.summaries[("r1", 0)] = replace(st.summaries[("r1", 0)], updated_s=ctx.clock.now_s)   # part of it seen
    assert run(node, ctx, robot, ticks=2) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "changed" and not events(ctx, "csiro_goal_failed")


def test_an_observer_beyond_a_stale_navigation_graph_is_planned_on_the_graph_rebuilt(tunnel):
    grid, a, _ = tunnel
    robot, ctx, st, _ = selected(tunnel, frontiers_at=(30.0,))
    st.topometric.detach_frontier(("r1", 0))                # no topometric path: the navigation graph's
    wall = np.zeros(grid.shape, bool)
    wall[grid.to_index(np.array([[a[0] + 20.0, a[1], a[2]]]))[0, 0], :, :] = True
    free = grid.occupancy == FREE
    robot.onboard_map.write(wall & free, OCCUPIED)              # the drift blocked when the graph is built
    navigator(ctx, robot).graph()
    robot.onboard_map.write(wall & free, FREE)                  # then seen open, seconds later
    assert run(FollowFrontierGoal("follow", ctx, max_replans=0), ctx, robot, ticks=2) == Status.RUNNING
    assert events(ctx, "goto")[0]["source"] == "navigator" and not events(ctx, "csiro_goal_failed")


def test_a_uav_short_of_its_frontier_on_a_stale_graph_goes_on_to_the_place_the_rebuilt_graph_reaches(
        tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    wall = np.zeros(grid.shape, bool)
    wall[grid.to_index(np.array([a + [13.0, 0.0, 0.0]]))[0, 0], :, :] = True      # behind the robot
    free = grid.occupancy == FREE
    robot.onboard_map.write(wall & free, UNKNOWN)               # the graph is built with a gap in the map
    behind = min(st.frontiers.frontiers, key=lambda f: f.mean[0])
    centre = behind.mean
    assert centre[0] < a[0] + 11.0                              # the frontier behind, beyond the wall's place
    stale = reachable_near(ctx, robot, centre)[1]               # the goal selected on that graph
    py_trees.blackboard.Blackboard.storage["/r1/csiro_goal"] = ["r1", behind.id]
    py_trees.blackboard.Blackboard.storage["/r1/goal"] = stale.tolist()
    robot.onboard_map.write(wall & free, FREE)                  # then seen open
    first = np.array(py_trees.blackboard.Blackboard.storage["/r1/goal"])
    assert first[0] > a[0] + 13.0                               # the stale graph's nearest place
    node = FollowFrontierGoal("follow", ctx, tolerance_m=0.5)
    assert fly(node, ctx, robot) == Status.SUCCESS
    assert events(ctx, "csiro_goal_done")[0]["why"] == "complete" and not events(ctx, "csiro_goal_failed")
    assert len(events(ctx, "goto")) >= 2 and events(ctx, "goto")[-1]["goal"][0] < first[0] - 1.0


def test_a_goal_within_d_max_takes_the_navigation_graph_not_the_topometric_detour(tunnel):
    robot, ctx, st, node = selected(tunnel, frontiers_at=(8.0,))   # 2 m from the robot at x = 10 ...
    st.topometric.detach_frontier(("r1", 0))
    st.topometric.attach_frontier(("r1", 0), "r1", 45.0, np.array([8.0, 6.0, 1.5]))   # ... hung off x = 43
    run(node, ctx, robot, ticks=1)
    assert events(ctx, "goto")[0]["source"] == "navigator"


def test_reaching_the_goal_asks_for_a_look_from_there(tunnel):
    robot, ctx, st, node = selected(tunnel, frontiers_at=(12.0,))
    assert not st.look_due
    for _ in range(20):
        run(node, ctx, robot, ticks=1)
        if node.feedback_message.startswith("at the goal"):
            break
    assert st.look_due


def test_the_way_to_a_point_goes_round_by_the_drifts_not_through_the_rock(two_drifts):
    robot = FakeRobot(two_drifts, np.array([10.0, 4.0, 2.5]), platform="aerial")
    ways = way_lengths(make_ctx(robot), robot, np.array([[30.0, 4.0, 2.5], [10.0, 12.0, 2.5], [10.0, 7.0, 2.5]]))
    assert 20.0 <= ways[0] < 22.0                                 # along the drift
    assert 70.0 <= ways[1] < 85.0                                 # 8 m away in line: round by x = 45
    assert 2.5 < ways[2] < 5.0                                    # in the rock: to the wall, then straight on
