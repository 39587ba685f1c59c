"""delve.skills.navigation: the agent's shared Navigator (navigation graph of the onboard
map, shortest paths from the robot), on the fake robot over synthetic maps."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import OCCUPIED, UNKNOWN
from delve.skills.navigation import Navigator, Plan, navigator

from .fakes import FakeRobot, body, make_ctx


@pytest.fixture(scope="module")
def tunnel():
    """A 30 m tunnel along x, mapped all along; floor at z = 1 m."""
    return syn.straight_tunnel(length_m=30)


def robot_at(tunnel, dx, dy=0.0, **kwargs):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, dx, dy), **kwargs)
    return robot, make_ctx(robot)


def path_length(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def test_one_navigator_per_agent_kept_in_its_services(tunnel):
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    assert isinstance(nav, Navigator) and ctx.services["navigator"] is nav
    assert navigator(ctx, robot) is nav
    other_robot, other_ctx = robot_at(tunnel, 3.0)
    assert navigator(other_ctx, other_robot) is not nav


def test_path_to_a_point_along_the_tunnel(tunnel):
    grid, a, _ = tunnel
    robot, ctx = robot_at(tunnel, 3.0)
    goal = body(a, 15.0)
    path, length = navigator(ctx, robot).path_to_point(goal)
    assert length == pytest.approx(12.0, abs=0.5)
    assert path_length(path) == pytest.approx(length, abs=1e-6)
    assert np.linalg.norm(path[0] - robot.position) <= 1.0      # from the robot's node ...
    assert np.linalg.norm(path[-1] - goal) <= 1.0               # ... to the goal's
    assert np.all(grid.value_at(path) != OCCUPIED)              # through free space only
    assert np.allclose(path[:, 2], body(a, 0.0)[2])             # a legged body over the floor


def test_no_path_to_a_point_in_the_rock_or_off_the_map(tunnel):
    grid, a, _ = tunnel
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    assert nav.path_to_point(body(a, 10.0, 8.0)) == (None, float("inf"))   # deep in the rock
    assert nav.path_to_point(body(a, 100.0)) == (None, float("inf"))       # beyond the map


def test_a_robot_off_its_graph_has_no_plan_after_one_rebuild(tunnel):
    robot, ctx = robot_at(tunnel, 10.0, 4.5)  # inside the rock, 2.5 m from the tunnel
    nav = navigator(ctx, robot)
    assert nav.from_robot() is None
    assert nav.builds == 2  # the cached graph, then a fresh one in case the robot walked off the old
    assert nav.path_to_point(robot.position + np.array([5.0, 0.0, 0.0])) == (None, float("inf"))


def test_plan_from_the_robot_is_a_shortest_path_tree(tunnel):
    robot, ctx = robot_at(tunnel, 3.0)
    plan = navigator(ctx, robot).from_robot()
    assert isinstance(plan, Plan)
    assert np.linalg.norm(plan.graph.positions[plan.source] - robot.position) <= 1.0
    assert plan.distances[plan.source] == 0.0
    far = int(np.nanargmax(np.where(np.isfinite(plan.distances), plan.distances, np.nan)))
    path = plan.path_to(far)
    assert np.allclose(path[0], plan.graph.positions[plan.source])
    assert np.allclose(path[-1], plan.graph.positions[far])
    assert path_length(path) == pytest.approx(plan.distances[far], rel=1e-9)
    assert plan.distances[far] > 20.0  # the far end of the tunnel


def test_the_plan_is_kept_while_the_robot_stays_and_renewed_when_it_moves(tunnel):
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    plan = nav.from_robot()
    assert nav.from_robot() is plan
    robot.follow_path([robot.position + np.array([6.0, 0.0, 0.0])])
    robot.step(10.0)
    moved = nav.from_robot()
    assert moved is not plan and moved.source != plan.source
    assert np.linalg.norm(moved.graph.positions[moved.source] - robot.position) <= 1.0


def wall_at(tunnel, x_m: float) -> np.ndarray:
    """A mask of the mapped voxels of a 0.4 m slab across the tunnel at ``x_m`` along it."""
    grid, a, _ = tunnel
    wall = np.zeros(grid.occupancy.shape, bool)
    i = int((body(a, x_m)[0] - grid.origin[0]) / grid.voxel_size_m)
    wall[i:i + 2] = grid.occupancy[i:i + 2] != UNKNOWN
    return wall


def test_the_graph_is_kept_while_the_map_is_the_same(tunnel):
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    graph = nav.graph()
    assert nav.builds == 1 and not nav.map_changed()
    ctx.clock.now_s = 30.0
    assert nav.graph() is graph and nav.builds == 1  # old, but the map is the same


def test_a_map_change_is_seen_at_once_by_a_graph_as_old_as_the_rebuild_period(tunnel):
    grid, a, _ = tunnel
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    graph = nav.graph()
    ctx.clock.now_s = nav.rebuild_period_s
    robot.onboard_map.write(wall_at(tunnel, 15.0), OCCUPIED)
    assert nav.graph() is not graph and nav.builds == 2
    assert nav.path_to_point(body(a, 20.0)) == (None, float("inf"))


def test_a_young_graph_waits_for_the_rebuild_period_after_a_map_change(tunnel):
    grid, a, _ = tunnel
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    ctx.clock.now_s = 30.0
    graph = nav.graph()  # built at 30 s
    robot.onboard_map.write(wall_at(tunnel, 15.0), OCCUPIED)  # rock across the tunnel
    assert nav.map_changed()
    ctx.clock.now_s = 30.0 + nav.rebuild_period_s - 0.1
    assert nav.graph() is graph and nav.builds == 1  # not rebuilt within rebuild_period_s of sim time
    assert np.isfinite(nav.path_to_point(body(a, 20.0))[1])  # so its paths still go through the rock
    ctx.clock.now_s = 30.0 + nav.rebuild_period_s
    assert nav.graph() is not graph and nav.builds == 2 and not nav.map_changed()
    assert nav.path_to_point(body(a, 20.0)) == (None, float("inf"))


def test_a_forced_rebuild_sees_a_change_at_once(tunnel):
    grid, a, _ = tunnel
    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    assert np.isfinite(nav.path_to_point(body(a, 20.0))[1])
    robot.onboard_map.write(wall_at(tunnel, 15.0), OCCUPIED)
    assert np.isfinite(nav.path_to_point(body(a, 20.0))[1])  # cached
    assert nav.path_to_point(body(a, 20.0), force=True) == (None, float("inf"))
    assert nav.builds == 2


def test_aerial_robots_plan_in_the_whole_free_volume(tunnel):
    legged, legged_ctx = robot_at(tunnel, 3.0)
    aerial, aerial_ctx = robot_at(tunnel, 3.0, platform="aerial")
    walk = navigator(legged_ctx, legged).graph().positions
    fly = navigator(aerial_ctx, aerial).graph().positions
    assert np.ptp(walk[:, 2]) == pytest.approx(0.0)  # one body height over the flat floor
    assert np.ptp(fly[:, 2]) > 1.0                     # every height between floor and roof


def test_the_frontier_voxels_follow_the_map_changes(tunnel):
    from delve.planners.frontier import frontier_voxels

    robot, ctx = robot_at(tunnel, 3.0)
    nav = navigator(ctx, robot)
    before = nav.frontier_voxels()
    assert np.array_equal(before, frontier_voxels(nav.grid()))
    robot.onboard_map.write(wall_at(tunnel, 15.0) | wall_at(tunnel, 15.4), UNKNOWN)  # 0.8 m of the tunnel forgotten
    after = nav.frontier_voxels()
    assert np.array_equal(after, frontier_voxels(nav.grid())) and len(after) > len(before)
