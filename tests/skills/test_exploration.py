"""delve.skills.exploration: ExploreFrontiers (nearest-frontier exploration) on the fake
robot. The fake's map changes only when a test writes to it, so a frontier visited stays
a frontier unless the test maps what lies beyond it."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from py_trees.common import Status

from .fakes import FakeRobot, bb, body, build, events, make_ctx, run


@pytest.fixture(scope="module")
def half_mapped():
    """A 50 m tunnel mapped for its first 25 m: one frontier, at x = a + 24 m."""
    return syn.straight_tunnel(length_m=50, mapped_to_m=25)


@pytest.fixture(scope="module")
def middle_mapped():
    """A 50 m tunnel open at both ends, mapped from 15 m to 35 m: a frontier at each end
    of the mapped part (x = a + 14 m and a + 34 m)."""
    return syn.straight_tunnel(length_m=50, mapped_from_m=15, mapped_to_m=35, closed_start=False)


def kinds(ctx) -> list[str]:
    return [e for e, _ in ctx.events]


def test_explore_heads_for_the_frontier_and_writes_the_blackboard(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    explore.tick_once()
    assert explore.status == Status.RUNNING
    (path,) = robot.paths
    assert np.allclose(path[-1], bb("frontier_goal"))
    # Back from the frontier (the end of the mapped part, floor to roof), where the
    # LiDAR, 15 degrees up, sees its top voxels (2.9 m above the floor), not under it;
    # within the 12 m a goal may lie from its frontier.
    top, back = a[2] + 2.9 - path[-1][2], a[0] + 23.9 - path[-1][0]
    assert top <= back * np.tan(np.radians(15)) + 0.1 and 8.0 <= back <= 12.0
    assert bb("frontiers_left") == 1
    (goal,) = events(ctx, "frontier_goal")
    assert goal["at"][0] == pytest.approx(a[0] + 24.0, abs=1.0) and goal["clusters"] == 1
    assert goal["path_length_m"] == pytest.approx(path[-1][0] - robot.position[0], abs=1.0)
    for _ in range(3):  # on its way: no new command
        robot.step(1.0)
        ctx.clock.now_s += 1.0
        explore.tick_once()
    assert explore.status == Status.RUNNING and len(robot.paths) == 1


def test_the_nearest_frontier_first_then_the_next(middle_mapped):
    grid, a, _ = middle_mapped
    robot = FakeRobot(grid, body(a, 30.0))  # 16 m from one frontier, 4 m from the other
    robot.view_up_deg = 90.0  # goals beside the frontiers (a 15 degree view stands back 9 m from both)
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    explore.tick_once()
    assert bb("frontiers_left") == 2
    assert run(explore, ctx, robot, ticks=300) == Status.SUCCESS
    goals = [e["at"][0] for e in events(ctx, "frontier_goal")]
    assert goals == [pytest.approx(a[0] + 34.0, abs=1.0), pytest.approx(a[0] + 14.0, abs=1.0)]


def test_on_a_map_that_never_changes_every_frontier_is_visited_then_exploration_completes(middle_mapped):
    grid, a, _ = middle_mapped
    robot = FakeRobot(grid, body(a, 25.0))
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    assert run(explore, ctx, robot, ticks=300) == Status.SUCCESS
    assert kinds(ctx) == ["frontier_goal", "frontier_blacklisted"] * 2 + ["exploration_complete"]
    assert {e["reason"] for e in events(ctx, "frontier_blacklisted")} == {"still a frontier after a visit"}
    assert bb("frontiers_left") == 0
    assert events(ctx, "exploration_complete")[0]["blacklisted_voxels"] > 0
    goals = sorted(e["at"][0] for e in events(ctx, "frontier_goal"))  # both ends visited
    assert goals == [pytest.approx(a[0] + 14.0, abs=1.0), pytest.approx(a[0] + 34.0, abs=1.0)]


@pytest.mark.parametrize("text", ["type: ExploreNearestFrontier",
                                  "type: ExploreNearestFrontier\nmin_cluster_voxels: 100000"])
def test_nothing_to_explore_succeeds_at_once(half_mapped, text):
    """A tunnel mapped all along (closed at both ends), or frontiers all too small."""
    grid, a, _ = syn.straight_tunnel(length_m=24) if text == "type: ExploreNearestFrontier" else half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    explore = build(text, ctx)
    explore.tick_once()
    assert explore.status == Status.SUCCESS
    assert robot.paths == [] and bb("frontiers_left") == 0
    assert kinds(ctx) == ["exploration_complete"]


def test_a_frontier_explored_on_the_way_is_left_without_blacklisting(half_mapped):
    grid, a, _ = half_mapped
    whole, _, _ = syn.straight_tunnel(length_m=50)  # the same tunnel, mapped to its far end
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier\ncheck_period_s: 2.0", ctx)
    goal = None
    statuses = []
    for t in range(6):
        ctx.clock.now_s = float(t)
        explore.tick_once()
        statuses.append(explore.status)
        goal = goal if goal is not None else np.array(bb("frontier_goal"))
        if explore.status != Status.RUNNING:
            break
        if t == 2:  # just after a check, the LiDAR sees the rest of the tunnel
            robot.onboard_map.write(np.arange(whole.occupancy.size), whole.occupancy.reshape(-1))
        robot.step(1.0)
    # Checked at 0, 2 and 4 s: the frontier is gone at the check at 4 s.
    assert statuses == [Status.RUNNING] * 4 + [Status.SUCCESS]
    assert robot.stops == 1 and robot.path_status.value == "idle"  # stopped on the way ...
    assert robot.position[0] < goal[0] - 5.0                       # ... well short of the goal
    assert not events(ctx, "frontier_blacklisted") and kinds(ctx)[-1] == "exploration_complete"


def test_a_blocked_path_blacklists_its_frontier(middle_mapped):
    grid, a, _ = middle_mapped
    robot = FakeRobot(grid, body(a, 26.0))  # 8 m from one frontier, 12 m from the other
    robot.view_up_deg = 90.0  # a sensor that sees the top of a frontier from beside it
    robot.block_at, robot.block_radius_m = body(a, 29.0), 1.0  # rock on the way to the nearest
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    for _ in range(5):
        explore.tick_once()
        robot.step(1.0)
        ctx.clock.now_s += 1.0
    robot.block_at = None
    (blacklisted,) = events(ctx, "frontier_blacklisted")
    assert blacklisted["reason"] == "path blocked: rock in the way"
    assert blacklisted["at"][0] == pytest.approx(a[0] + 34.0, abs=1.0)
    assert run(explore, ctx, robot, ticks=300) == Status.SUCCESS
    goals = [e["at"][0] for e in events(ctx, "frontier_goal")]
    assert len(goals) == 2 and goals[1] == pytest.approx(a[0] + 14.0, abs=1.0)  # never the blocked one again


def test_dwells_at_a_goal_before_judging_it(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier\ndwell_s: 5.0", ctx)
    arrived_s = judged_s = None
    for _ in range(60):
        explore.tick_once()
        if arrived_s is None and robot.path_status.value == "arrived":
            arrived_s = ctx.clock.now_s
        if judged_s is None and events(ctx, "frontier_blacklisted"):
            judged_s = ctx.clock.now_s
        if explore.status != Status.RUNNING:
            break
        robot.step(1.0)
        ctx.clock.now_s += 1.0
    assert judged_s - arrived_s == pytest.approx(5.0)
    assert explore.status == Status.SUCCESS and len(robot.paths) == 1


def test_a_robot_off_its_navigation_graph_fails(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 10.0, 4.5))  # inside the rock beside the tunnel
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    explore.tick_once()
    assert explore.status == Status.FAILURE and robot.paths == []
    assert events(ctx, "explore_failed")[0]["reason"] == "robot is not on its navigation graph"


def test_interrupted_it_stops_its_own_motion_and_plans_afresh(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    explore = build("type: ExploreNearestFrontier", ctx)
    explore.tick_once()
    robot.step(3.0)
    explore.stop(Status.INVALID)  # say, the endurance is low
    assert robot.stops == 1 and robot.path_status.value == "idle"
    explore.tick_once()
    assert explore.status == Status.RUNNING and len(robot.paths) == 2
    assert not events(ctx, "frontier_blacklisted")  # an interruption is no verdict on the frontier


def test_sorted_contains_answers_as_isin():
    from delve.skills.exploration import _sorted_contains
    rng = np.random.default_rng(0)
    for n in (0, 1, 50):
        values = np.unique(rng.integers(0, 200, n))
        query = rng.integers(-5, 210, 300)
        np.testing.assert_array_equal(_sorted_contains(values, query), np.isin(query, values))
