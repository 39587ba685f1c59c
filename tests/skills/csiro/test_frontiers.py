"""delve.skills.csiro.frontiers: UpdateFrontiers keeps the robot's frontiers, their observers,
its trajectory and topometric map up to date from its LiDAR sweeps."""
from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
from delve.planners.csiro.topometric import frontier_node
from delve.skills.csiro import UpdateFrontiers, csiro_state
from py_trees.common import Status

from ..fakes import FakeRobot, bb, body, events, make_ctx
from .conftest import sweep


def test_a_tunnel_gives_frontiers_at_both_ends_of_the_view_with_observers_on_the_floor(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 18.0))
    ctx = make_ctx(robot)
    node = UpdateFrontiers("update", ctx)
    sweep(robot, tunnel_points)
    node.tick_once()
    assert node.status == Status.RUNNING
    st = csiro_state(ctx)
    assert bb("csiro_frontier_count") >= 2
    summaries = st.own_summaries("r1")
    assert len(summaries) == 2
    x = robot.position[0]
    assert sorted(np.sign(s.mean[0] - x) for s in summaries) == [-1.0, 1.0]       # one each way
    for s in summaries:
        assert abs(s.observer[2] - 1.0) < 0.3                                         # a floor point
        assert abs(s.observer[0] - x) < abs(s.mean[0] - x)                           # towards the frontier
        assert s.reward > 0
        assert frontier_node(s.key) in st.topometric.graph                            # hung off the map
    assert st.topometric.last_node("r1") == ("r1", 0)
    assert len(st.trajectory) == 1
    assert st.frontier_params.elevation_max_deg == robot.view_up_deg


def test_frontiers_ahead_move_on_as_the_robot_drives(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 10.0))
    ctx = make_ctx(robot)
    node = UpdateFrontiers("update", ctx)
    for k in range(6):                               # 2 m steps along the tunnel
        robot._pos = body(a, 10.0 + 2 * k)
        sweep(robot, tunnel_points, range_m=12.0)
        node.tick_once()
        ctx.clock.now_s += 2.0
    st = csiro_state(ctx)
    ahead = max(st.own_summaries("r1"), key=lambda s: s.mean[0])
    assert ahead.mean[0] > robot.position[0] + 5.0
    assert len(st.topometric.trajectory_nodes()) == 3                    # at x + 0, 4, 8: 3 m apart at least
    assert events(ctx, "csiro_frontiers")


def test_too_few_points_is_no_error_said_once_and_tried_again_at_the_next_sweep(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    node = UpdateFrontiers("update", ctx)
    node.tick_once()                                     # no sweep yet: nothing to update from
    assert not events(ctx, "csiro_no_view")
    for _ in range(3):                                   # standing still, a sweep of two points each second
        robot.lidar_scans.append(SimpleNamespace(sensor=robot.position, points=tunnel_points[:2]))
        node.tick_once()
        ctx.clock.now_s += 1.0
    assert node.status == Status.RUNNING and bb("csiro_frontier_count") == 0
    assert len(events(ctx, "csiro_no_view")) == 1
    sweep(robot, tunnel_points)                          # a real sweep, still standing: tried again
    node.tick_once()
    assert bb("csiro_frontier_count") >= 2


def test_a_flying_robot_keeps_frontiers_but_plans_no_observers(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, a + np.array([18.0, 0.0, 1.5]), platform="aerial")
    ctx = make_ctx(robot)
    node = UpdateFrontiers("update", ctx)
    sweep(robot, tunnel_points)
    node.tick_once()
    st = csiro_state(ctx)
    assert len(st.frontiers.frontiers) >= 2 and not st.summaries
    assert not st.topometric.trajectory_nodes()


def test_at_its_goal_the_robot_looks_again_and_an_unchanged_frontier_gets_a_better_observer(tunnel,
                                                                                             tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 18.0))
    ctx = make_ctx(robot)
    node = UpdateFrontiers("update", ctx)
    sweep(robot, tunnel_points)
    node.tick_once()
    st = csiro_state(ctx)
    key, good = next((s.key, s) for s in st.own_summaries("r1"))
    st.summaries[key] = replace(good, observer=good.observer - [20.0, 0, 0], reward=0.01)   # from a poor view
    calls, kept = [], st.frontiers.frontiers
    update = st.frontiers.update                                  # the view changes nothing of the frontiers
    st.frontiers.update = lambda *args: calls.append(args[0]) or replace(update(*args), frontiers=kept,
                                                                         new_ids=(), removed_ids=())
    ctx.clock.now_s += 1.0
    sweep(robot, tunnel_points)
    node.tick_once()                                              # standing still: no update due
    assert not calls
    st.look_due = True                                            # FollowFrontierGoal reached its goal
    sweep(robot, tunnel_points)
    node.tick_once()
    assert calls and not st.look_due
    better = st.summaries[key]
    assert better.reward > 0.01 and better.updated_s == good.updated_s   # no update of the frontier itself
    assert np.linalg.norm(better.observer - good.observer) < 1.0
