"""delve.skills.csiro.selection: the ground robot's choice by reward per unit of topometric
distance (equation 15, Algorithm 3) and the flying robot's by equation 16."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from delve.planners.csiro.frontier_types import Frontier
from delve.planners.csiro.sharing import FrontierSummary
from delve.planners.occupancy import OCCUPIED
from delve.skills.csiro import SelectUavFrontier, SelectUgvFrontier, UpdateFrontiers, csiro_state
from delve.skills.navigation import navigator
from py_trees.common import Status

from ..fakes import FakeRobot, bb, body, events, make_ctx, run
from .conftest import sweep, uav_with_frontiers


def summary(owner: str, fid: int, x: float, reward: float = 10.0) -> FrontierSummary:
    return FrontierSummary(id=fid, owner=owner, mean=np.array([x + 2.0, 6.0, 2.0]), cov=np.eye(3), reward=reward,
                           observer=np.array([x, 6.0, 1.0]), updated_s=0.0)


def ground_robot(tunnel, frontiers_at=(12.0, 40.0)):
    """A robot at x = 10 that walked the tunnel from x = 7 to 45 (its topometric map) and knows
    a frontier of equal reward observed from each x of ``frontiers_at``."""
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    st = csiro_state(ctx)
    for x in np.arange(7.0, 46.0, 1.0):
        st.topometric.add_pose("r1", x, [x, 6.0, 1.5])
    for k, x in enumerate(frontiers_at):
        s = st.summaries[("r1", k)] = summary("r1", k, x)
        st.topometric.attach_frontier(s.key, "r1", x, s.observer + [0, 0, 0.5])
    return robot, ctx, st


def test_ugv_takes_the_highest_reward_per_unit_distance(tunnel):
    robot, ctx, st = ground_robot(tunnel)
    node = SelectUgvFrontier("select", ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert bb("csiro_goal") == ["r1", 0] and st.goal == ("r1", 0)
    assert np.allclose(bb("goal"), [12.0, 6.0, 1.5])                    # the observer, body height added
    assert events(ctx, "csiro_goal_selected")[0]["distance_m"] == 4.0         # 10 -> node 13 -> 12


def test_ugv_skips_a_frontier_another_robot_holds_and_discounts_visited_places(tunnel):
    robot, ctx, st = ground_robot(tunnel)
    st.goals["r2"] = (("r1", 0), np.array([12.0, 6.0, 1.0]))
    node = SelectUgvFrontier("select", ctx)
    node.tick_once()
    assert bb("csiro_goal") == ["r1", 1]
    st.goals.clear()
    node.tick_once()
    assert bb("csiro_goal") == ["r1", 0]
    # r2 has passed the near frontier's observer three times: equation 14 gives it rho^3 of its
    # reward, 0.08 / 4 m against 10 / 31 m for the far one
    st.places["r2"] = np.array([[12.0, 6.0, 1.0]] * 3)
    node.tick_once()
    assert bb("csiro_goal") == ["r1", 1]


def test_ugv_penalises_a_failed_frontier(tunnel):
    robot, ctx, st = ground_robot(tunnel, frontiers_at=(12.0, 20.0))
    node = SelectUgvFrontier("select", ctx)
    node.tick_once()
    assert bb("csiro_goal") == ["r1", 0]
    st.failed.mark(st.summaries[("r1", 0)])
    node.tick_once()
    assert bb("csiro_goal") == ["r1", 1]


def test_no_frontier_waits_then_ends_exploration(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 3.0))
    ctx = make_ctx(robot)
    node = SelectUgvFrontier("select", ctx, wait_s=5.0)
    assert run(node, ctx, robot, ticks=3) == Status.RUNNING
    assert run(node, ctx, robot, ticks=10) == Status.FAILURE
    assert len(events(ctx, "csiro_no_frontier")) == 1 and bb("csiro_goal") is None


def test_uav_flies_for_its_own_frontier_and_skips_blacklisted_ones(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    node = SelectUavFrontier("select", ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS
    first = bb("csiro_goal")
    assert first[0] == "r1" and st.momentum is not None and st.momentum.frontier_id == first[1]
    frontier = next(f for f in st.frontiers.frontiers if f.id == first[1])
    goal = np.asarray(bb("goal"))
    assert np.linalg.norm(goal - frontier.mean) < np.linalg.norm(robot.position - frontier.mean)
    st.blacklist.add(frontier)
    node.tick_once()
    assert node.status == Status.SUCCESS and bb("csiro_goal") != first


def select_beside_a_big_frontier(tunnel, tunnel_points, point, normal, cov_diag):
    """One selection of a flying robot that holds, besides its frontiers, a one-point frontier
    (id 99) at ``point``, the largest and nearest (eq. 16 would take it); the node, context,
    CSIRO state and that frontier, after checking it was blacklisted behind a surface."""
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    big = Frontier(id=99, points=point[None], normals=np.array([normal]), areas=np.array([25.0]),
                   mean=point, cov=np.diag(cov_diag))
    st.frontiers._frontiers[99] = big
    node = SelectUavFrontier("select", ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS and bb("csiro_goal")[1] != 99 and 99 in st.blacklist
    assert events(ctx, "csiro_frontier_behind_surface")[0]["id"] == 99
    return node, ctx, st, big


def test_uav_blacklists_a_frontier_wholly_in_its_blind_cones_behind_mapped_rock(tunnel, tunnel_points):
    grid, a, _ = tunnel
    beyond = a + np.array([18.0, 0.0, 5.0])                  # straight up (blind), through the roof
    assert grid.value_at(a[None] + [[18.0, 0.0, 3.1]])[0] == OCCUPIED
    node, ctx, st, big = select_beside_a_big_frontier(tunnel, tunnel_points, beyond, [0.0, 0.0, 1.0],
                                                      [4.0, 4.0, 0.01])
    inside = a + np.array([18.0, 1.0, 2.5])                   # one of its triangles in the drift: in view
    st.blacklist.clear()
    st.momentum = None                                         # no pull towards the frontier taken instead
    st.frontiers._frontiers[99] = replace(big, points=np.array([beyond, inside]),
                                          normals=np.array([[0, 1.0, 0]] * 2), areas=np.array([20.0, 5.0]))
    node.tick_once()
    assert bb("csiro_goal")[1] == 99 and 99 not in st.blacklist


def test_uav_blacklists_a_frontier_level_with_it_wholly_behind_a_mapped_wall(tunnel, tunnel_points):
    grid, a, _ = tunnel
    behind = a + np.array([19.0, 3.5, 1.5])                    # 1.5 m beyond the wall at y + 2, level with it
    assert grid.value_at(a[None] + [[19.0, 2.1, 1.5]])[0] == OCCUPIED
    select_beside_a_big_frontier(tunnel, tunnel_points, behind, [0.0, 1.0, 0.0], [4.0, 0.01, 4.0])


def test_uav_skips_a_frontier_whose_centre_no_reachable_place_comes_within_eta_blacklist_of(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot, ctx, st = uav_with_frontiers(grid, a, tunnel_points)
    in_rock = a + np.array([19.0, 7.0, 1.5])                  # 5 m beyond the wall at y + 2, level with the robot
    big = Frontier(id=99, points=in_rock[None], normals=np.array([[0.0, 1.0, 0.0]]), areas=np.array([25.0]),
                   mean=in_rock, cov=np.diag([4.0, 0.01, 4.0]))
    st.frontiers._frontiers[99] = big                          # the largest, nearest: eq. 16 would take it
    node = SelectUavFrontier("select", ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS and bb("csiro_goal")[1] != 99
    assert 99 not in st.blacklist                              # skipped, not blacklisted: the map may open
    assert events(ctx, "csiro_frontier_out_of_reach")[0]["id"] == 99
    within = a + np.array([19.0, 3.5, 1.5])                    # 1.5 m beyond the wall: a place within 3 m
    at_wall = a + np.array([19.0, 1.6, 1.5])                   # and part of it in sight, at the wall
    st.momentum = None
    st.frontiers._frontiers[99] = replace(big, points=np.array([within, at_wall]), normals=np.array([[0, 1.0, 0]] * 2),
                                          areas=np.array([20.0, 5.0]), mean=within)
    node.tick_once()
    assert bb("csiro_goal")[1] == 99


def test_uav_searches_an_out_of_reach_frontier_s_version_once_on_a_rebuilt_graph(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, a + np.array([18.0, 0.0, 1.5]), platform="aerial")
    ctx = make_ctx(robot)
    sweep(robot, tunnel_points)
    UpdateFrontiers("update", ctx).tick_once()
    st, nav = csiro_state(ctx), navigator(ctx, robot)
    in_rock = a + np.array([19.0, 7.0, 1.5])                  # 5 m beyond the wall: out of reach
    big = Frontier(id=99, points=in_rock[None], normals=np.array([[0.0, 1.0, 0.0]]), areas=np.array([25.0]),
                   mean=in_rock, cov=np.diag([4.0, 0.01, 4.0]))
    st.frontiers._frontiers[99] = big
    node = SelectUavFrontier("select", ctx)
    node.tick_once()
    builds = nav.builds
    for _ in range(3):                                          # the map changes, the frontier does not
        robot.onboard_map.version += 1
        st.momentum = None                                      # eq. 16 takes 99 first again
        node.tick_once()
        assert node.status == Status.SUCCESS and bb("csiro_goal")[1] != 99
    assert nav.builds == builds                                 # no rebuild for a version already searched
    robot.onboard_map.version += 1
    st.frontiers._frontiers[99] = replace(big, cov=np.diag([4.0, 0.02, 4.0]))   # a new version of it
    st.momentum = None
    node.tick_once()
    assert nav.builds == builds + 1 and bb("csiro_goal")[1] != 99


def test_uav_weighs_a_frontier_by_the_way_there_not_the_line_through_rock(two_drifts):
    robot = FakeRobot(two_drifts, np.array([10.0, 4.0, 2.5]), platform="aerial")
    ctx = make_ctx(robot)
    st = csiro_state(ctx)

    def patch(fid: int, centre: list[float]) -> Frontier:
        c = np.array(centre)
        return Frontier(id=fid, points=c[None], normals=np.array([[1.0, 0.0, 0.0]]), areas=np.array([4.0]),
                        mean=c, cov=np.diag([1.0, 1.0, 0.01]))

    st.frontiers._frontiers = {1: patch(1, [10.0, 12.0, 2.5]),     # 8 m across the rock, ~74 m round
                               2: patch(2, [30.0, 4.0, 2.5])}      # 20 m along the drift
    SelectUavFrontier("select", ctx).tick_once()
    assert bb("csiro_goal") == ["r1", 2]
