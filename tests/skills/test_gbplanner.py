"""delve.skills.gbplanner: Explore, and Home along GBPlanner2's global graph, on a small fake
robot over synthetic maps."""
from __future__ import annotations

import zlib

import numpy as np
import py_trees
import pytest
from delve.executive.errors import DelveError
from delve.executive.tree_loader import build_tree, check_context
from delve.planners.gbplanner2 import Frontier
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.gbplanner2.local_map import LocalMap
from delve.planners.gbplanner2.local_planner import ShrinkingLocalPlanner
from delve.planners.occupancy import FREE, OCCUPIED, Grid
from delve.skills.gbplanner import SERVICE, Explore, gbplanner, parse_bbox, robot_config, stable_seed
from delve.skills.homing import Home
from py_trees.common import Status

from .fakes import FakeRobot, events, make_ctx, run
from .test_motion import body

SMALL = {"max_vertices": 150, "planner": {"num_edges_max": 2500}}


@pytest.fixture(scope="module")
def half_mapped():
    """A 50 m tunnel along x mapped for its first 25 m."""
    return syn.straight_tunnel(length_m=50, mapped_to_m=25)


@pytest.fixture(scope="module")
def mapped():
    """A 24 m tunnel, all mapped: nothing left to explore."""
    return syn.straight_tunnel(length_m=24)


def explore(ctx, **params) -> Explore:
    return Explore(name="Explore", ctx=ctx, **{**SMALL, **params})


def bb(key: str):
    return py_trees.blackboard.Blackboard.get(f"/r1/{key}")


# --------------------------------------------------------------------- configuration


def test_robot_config_takes_the_platform_preset_and_the_robot_limits(half_mapped):
    grid, a, _ = half_mapped
    legged = FakeRobot(grid, body(a, 3.0), endurance_s=1200.0)
    cfg = robot_config(legged)
    assert cfg.robot_type == "legged" and cfg.num_vertices_max == 1000 and cfg.sensor_fov_vertical_deg == 30.0
    assert cfg.max_inclination_deg == 35.0 and cfg.clustering_radius_m == 0.0
    assert cfg.robot_box_size_m[:2] == pytest.approx((0.6, 0.6))  # 0.8 m less a voxel: rounded out, 3 voxels
    aerial = FakeRobot(grid, body(a, 3.0), platform="aerial")
    cfg = robot_config(aerial, {"num_vertices_max": 300})
    assert cfg.robot_type == "aerial" and cfg.num_vertices_max == 300
    assert cfg.clustering_radius_m == 1.0 and cfg.sensor_fov_vertical_deg == 90.0


@pytest.mark.parametrize("voxel_m", [0.2, 0.4])
def test_the_collision_box_keeps_the_robot_clear_of_rock_at_any_voxel_size(voxel_m):
    """A 0.8 m aerial robot in a free voxel whose neighbour is rock would touch it: its
    box must not be free there, on a 0.4 m map as on a 0.2 m one (the box was one 0.4 m
    voxel, and paths hugged the rock)."""
    occ = np.full((9, 9, 9), FREE, np.int8)
    occ[5, :, :] = OCCUPIED
    grid = Grid(occ, np.zeros(3), voxel_m)
    cfg = robot_config(FakeRobot(grid, np.full(3, 4.5 * voxel_m), platform="aerial"))
    local = LocalMap(grid, np.zeros(3), np.full(3, 9 * voxel_m), cfg)
    beside, clear = np.array([[4.5, 4.5, 4.5], [3.5, 4.5, 4.5]]) * voxel_m
    assert not local.is_box_free(beside[None])[0]
    assert local.is_box_free(clear[None])[0]


def test_one_planner_per_agent_seeded_from_the_agent_name(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    svc = gbplanner(ctx, robot, {"num_vertices_max": 150})
    assert gbplanner(ctx, robot) is svc and ctx.services[SERVICE] is svc
    assert isinstance(svc.planner.local_planner, ShrinkingLocalPlanner)
    assert stable_seed(3, "anymal") == [3, zlib.crc32(b"anymal")]
    # Other overrides reconfigure the planner and keep its global graph.
    graph = svc.planner.global_planner.graph
    gbplanner(ctx, robot, {"num_vertices_max": 120})
    assert svc.planner.config.num_vertices_max == 120 and svc.planner.global_planner.graph is graph


def test_the_same_seed_and_agent_give_the_same_plan(half_mapped):
    grid, a, _ = half_mapped
    paths = []
    for name in ("r1", "r1"):
        py_trees.blackboard.Blackboard.clear()
        robot = FakeRobot(grid, body(a, 8.0))
        node = explore(make_ctx(robot, name), seed=4)
        node.tick_once()
        paths.append(robot.paths[0])
    assert np.array_equal(paths[0], paths[1])


def test_bad_planner_overrides_fail_when_the_tree_is_built():
    with pytest.raises(DelveError, match="unknown GBPlannerConfig parameter"):
        build_tree({"type": "ExploreGBPlanner2", "planner": {"num_vertice_max": 10}}, check_context())
    with pytest.raises(DelveError, match="max_vertices"):
        build_tree({"type": "ExploreGBPlanner2", "max_vertices": 1}, check_context())


def test_parse_bbox():
    lo, hi = parse_bbox({"min": [0, 0, 0], "max": [10, -5, 3]})
    assert np.allclose(lo, [0, -5, 0]) and np.allclose(hi, [10, 0, 3])
    lo, hi = parse_bbox([[1, 2, 3], [4, 5, 6]])
    assert np.allclose(lo, [1, 2, 3]) and np.allclose(hi, [4, 5, 6])
    assert parse_bbox(None) is None
    with pytest.raises(ValueError):
        parse_bbox({"min": [0, 0]})
    with pytest.raises(ValueError):
        parse_bbox([[0, 0, 0]])


# --------------------------------------------------------------------------- Explore


def test_explore_heads_into_the_unknown_and_writes_the_blackboard(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()
    assert node.status == Status.RUNNING
    (path,) = robot.paths
    assert path[-1][0] > robot.position[0] + 3.0
    assert bb("planner_mode") == "explore" and bb("last_plan_reason") == "ok"
    assert bb("exploration_complete") is False and bb("homing_due") is False
    assert events(ctx, "gbplanner_path")[0]["mode"] == "explore"
    node.tick_once()  # still following: no new plan
    assert len(robot.paths) == 1
    robot.step(100.0)  # arrived: the next tick plans again
    node.tick_once()
    assert len(robot.paths) == 2


def test_explore_succeeds_when_nothing_is_left(mapped):
    grid, a, _ = mapped
    robot = FakeRobot(grid, body(a, 6.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    assert run(node, ctx, robot, ticks=60, dt_s=2.0) == Status.SUCCESS
    assert bb("exploration_complete") is True and bb("last_plan_reason") == "exploration_complete"
    assert events(ctx, "exploration_complete")


def test_explore_hands_over_to_homing_when_the_endurance_is_short(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 14.0), home=body(a, 2.0), endurance_s=40.0)
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert bb("homing_due") is True and bb("planner_mode") == "homing" and bb("last_plan_reason") == "homing_due"
    assert events(ctx, "planner_homing")[0]["trigger"] is True
    # Without the planner's endurance check it keeps exploring.
    py_trees.blackboard.Blackboard.clear()
    ctx = make_ctx(robot)
    node = explore(ctx, endurance_homing=False)
    node.tick_once()
    assert node.status == Status.RUNNING


def test_explore_fails_at_once_on_an_invalid_start(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0, 1.9))  # the robot box overlaps the tunnel wall
    ctx = make_ctx(robot)
    node = explore(ctx, start_shift_m=0.0)
    node.tick_once()
    assert node.status == Status.FAILURE
    assert bb("last_plan_reason") == "invalid_start" and bb("planner_mode") == "none"
    assert events(ctx, "explore_failed")[0]["reason"] == "invalid_start"


def test_explore_starts_from_a_clear_pose_next_to_a_wall(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0, 1.85))  # 0.15 m from the wall: the box touches it
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()
    assert node.status == Status.RUNNING and bb("last_plan_reason") == "ok"
    start = robot.paths[0][0]
    assert start[1] < robot.position[1] and np.linalg.norm(start - robot.position) <= 0.4 + 1e-9


def test_a_planner_error_is_a_failure_with_its_reason(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    svc = gbplanner(ctx, robot, node.overrides)

    def broken(*args, **kwargs):
        raise RuntimeError("the map is corrupt")

    svc.planner.plan = broken
    node.tick_once()
    assert node.status == Status.FAILURE
    assert bb("last_plan_reason") == "error"
    (failed,) = events(ctx, "explore_failed")
    assert "the map is corrupt" in failed["detail"]


def test_explore_retries_a_failed_iteration_then_fails(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx, max_failed_plans=2, retry_period_s=5.0)
    svc = gbplanner(ctx, robot, node.overrides)
    from delve.planners.gbplanner2 import PlanResult

    svc.planner.plan = lambda *args, **kwargs: PlanResult(None, "none", reason="local planner: no way on")
    node.tick_once()
    assert node.status == Status.RUNNING and bb("last_plan_reason") == "no_path"
    ctx.clock.now_s = 2.0
    node.tick_once()
    assert node.status == Status.RUNNING and len(events(ctx, "plan_failed")) == 1  # waiting
    ctx.clock.now_s = 5.0
    node.tick_once()
    assert node.status == Status.FAILURE and len(events(ctx, "plan_failed")) == 2


def test_blocked_paths_leave_rock_on_the_planners_map_then_fail(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx, max_blocked_paths=3, reroute_poses=0)
    svc = gbplanner(ctx, robot, node.overrides)
    statuses = []
    for _ in range(3):
        node.tick_once()
        statuses.append(node.status)
        robot.block_at, robot.block_radius_m = robot.position, 0.5  # every step is refused
        robot.step(1.0)
        robot.block_at = None
    node.tick_once()
    statuses.append(node.status)
    assert statuses == [Status.RUNNING] * 3 + [Status.FAILURE]
    assert bb("last_plan_reason") == "blocked"
    blocked = events(ctx, "explore_path_blocked")
    assert [e["in_a_row"] for e in blocked] == [1, 2, 3]
    assert len(svc.blocked_spots) == 3
    for spot in svc.blocked_spots:  # just ahead of the robot, where it could not go
        assert 1.0 < np.linalg.norm((spot - robot.position)[:2]) < 1.2


def test_a_blocked_path_is_rerouted_on_the_navigation_graph_once(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()
    planned = robot.paths[-1]
    robot.block_at, robot.block_radius_m = robot.position, 0.5
    robot.step(1.0)
    robot.block_at = None
    node.tick_once()  # blocked: the navigation graph's way to the farthest pose it reaches
    assert node.status == Status.RUNNING and len(robot.paths) == 2
    (rerouted,) = events(ctx, "explore_rerouted")
    assert np.linalg.norm(np.array(rerouted["to"]) - planned[-1]) < 2.0
    assert not events(ctx, "explore_path_blocked")
    robot.block_at, robot.block_radius_m = robot.position, 0.5
    robot.step(1.0)  # blocked again: now a blocked path for the planner
    robot.block_at = None
    node.tick_once()
    assert len(events(ctx, "explore_path_blocked")) == 1 and len(events(ctx, "explore_rerouted")) == 1


@pytest.mark.parametrize("halted", [True, False])
def test_a_frontier_halted_on_the_way_to_goes_back_to_the_global_planner(half_mapped, halted):
    """The global planner drops a frontier when it plans the way there (its vertex turns
    "visited"); Explore halted on that way (a COHORT robot's T_C ends) gives it back,
    as after a blocked path. Explore that ends by itself keeps it dropped."""
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()  # plans and follows a path
    assert node.status == Status.RUNNING and node.following
    gp = gbplanner(ctx, robot, node.overrides).planner.global_planner
    far = body(a, 22.0)
    gp.graph.add_node(10**6, pos=far, kind="visited")  # as plan_reposition leaves its target
    node.frontier = Frontier(10**6, far, 100.0, 0)
    node.stop(Status.INVALID if halted else Status.SUCCESS)
    assert (10**6 in gp.frontiers) == halted
    assert gp.graph.nodes[10**6]["kind"] == ("frontier" if halted else "visited")


@pytest.mark.parametrize("halted", [True, False])
def test_the_goal_of_a_local_path_halted_on_the_way_becomes_a_frontier(half_mapped, halted):
    """The local path's goal is no frontier (the robot is going there); Explore halted on
    the way (a COHORT robot called back to a link point) makes it one."""
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0))
    ctx = make_ctx(robot)
    node = explore(ctx)
    node.tick_once()
    assert node.following and bb("planner_mode") == "explore"
    gp = gbplanner(ctx, robot, node.overrides).planner.global_planner
    local, _start = node.local
    goal = local.graph.vertices[local.best_vertex]
    near = lambda: [f for f in gp.frontiers.values() if np.linalg.norm(f.position - goal) < 0.5]  # noqa: E731
    assert not near()
    node.stop(Status.INVALID if halted else Status.SUCCESS)
    assert len(near()) == (1 if halted else 0) and node.local is None


def test_explore_stays_inside_the_exploration_box(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 12.0))
    ctx = make_ctx(robot)
    box = {"min": (a + [-5.0, -5.0, -1.0]).tolist(), "max": (a + [15.0, 5.0, 4.0]).tolist()}
    py_trees.blackboard.Blackboard.set("/r1/exploration_bbox", box)
    node = explore(ctx)
    for _ in range(4):
        node.tick_once()
        robot.step(100.0)
    assert robot.paths
    for path in robot.paths:
        assert path[:, 0].max() <= a[0] + 15.0 + 0.6  # vertices in the box; improvement moves them <= 0.5 m


# ------------------------------------------------------------------------------ Home


def test_home_follows_the_global_graph_home(half_mapped):
    grid, a, _ = half_mapped
    home = body(a, 2.0)
    robot = FakeRobot(grid, home, home=home)
    ctx = make_ctx(robot)
    node = explore(ctx)
    for _ in range(3):  # explore a little: the global graph grows from home
        node.tick_once()
        robot.step(100.0)
    assert np.linalg.norm(robot.position - home) > 3.0
    homing = Home(name="Home", ctx=ctx)
    assert run(homing, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position - home) <= 1.0
    assert bb("returned_home") is True
    assert events(ctx, "homing")[0]["source"] == "gbplanner2"
    assert events(ctx, "home_reached")


def test_home_falls_back_to_the_navigation_graph(half_mapped):
    grid, a, _ = half_mapped
    home = body(a, 2.0)
    robot = FakeRobot(grid, body(a, 20.0), home=home)  # the global graph knows only home, 18 m away
    ctx = make_ctx(robot)
    homing = Home(name="Home", ctx=ctx)
    assert run(homing, ctx, robot) == Status.SUCCESS
    assert events(ctx, "homing")[0]["source"] == "navigator"


def test_home_falls_back_to_the_traversed_path_when_blocked(half_mapped):
    grid, a, _ = half_mapped
    home = body(a, 2.0)
    trail = [body(a, x) for x in np.arange(2.0, 20.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], home=home, trail=trail)
    ctx = make_ctx(robot)
    homing = Home(name="Home", ctx=ctx)
    homing.tick_once()  # the global graph knows only home, 18 m away: the navigation graph's path
    robot.block_at, robot.block_radius_m = robot.position + np.array([-0.5, 0.0, 0.0]), 0.1
    robot.step(1.0)
    robot.block_at = None
    assert robot.path_status.value == "blocked"
    assert run(homing, ctx, robot) == Status.SUCCESS
    assert [e["source"] for e in events(ctx, "homing")] == ["navigator", "traversed_path"]
    assert events(ctx, "homing_path_blocked")[0]["source"] == "navigator"


def test_home_fails_without_any_path_home():
    grid, a, _ = syn.straight_tunnel(length_m=30)
    # Home far above the map, and a traversed path that does not start there.
    robot = FakeRobot(grid, body(a, 15.0), home=body(a, 2.0) + np.array([0.0, 0.0, 30.0]))
    ctx = make_ctx(robot)
    homing = Home(name="Home", ctx=ctx)
    homing.tick_once()
    assert homing.status == Status.FAILURE
    assert events(ctx, "homing_failed")[0]["reason"] == "no path home"
