"""delve.skills.cohort.robot and .lost_link: the COHORT robot side (submaps, calls to the
hub, re-positioning, the lost-link rule) on the fake robot, with a scripted hub."""
from __future__ import annotations

import networkx as nx
import numpy as np
import py_trees
import pytest
from delve.planners.cohort import CohortParams
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import FREE, UNKNOWN
from delve.skills.cohort.lost_link import CohortTimer, ExplorationOver, ReturnToLinkPoint
from delve.skills.cohort.hub import ASSIGNMENT, REQUEST, SUBMAP
from delve.skills.cohort.robot import CallHub, FollowHubPath, SendSubmaps
from delve.skills.gbplanner import SERVICE as GBPLANNER, gbplanner
from delve.skills.robot import PathStatus
from py_trees.common import Status

from ..fakes import FakeRobot, bb, body, events, make_ctx, run


@pytest.fixture(scope="module")
def tunnel():
    """A 40 m tunnel along x, mapped all along; floor at z = 1 m."""
    return syn.straight_tunnel(length_m=40)


@pytest.fixture()
def robot(tunnel):
    grid, a, _ = tunnel
    return FakeRobot(grid, body(a, 3.0))


def ctx_for(robot, **params):
    ctx = make_ctx(robot)
    ctx.services["cohort_params"] = CohortParams(**params)
    return ctx


def sent(robot, kind):
    return [m for m in robot.radio.sent if m.kind == kind]


def tick(node, ctx, robot, seconds: int, dt_s: float = 1.0) -> Status:
    for _ in range(seconds):
        node.tick_once()
        robot.step(dt_s)
        ctx.clock.now_s += dt_s
    return node.status


# ----------------------------------------------------------------------- SendSubmaps


def unknown_voxels(robot, n: int) -> np.ndarray:
    return np.flatnonzero(robot.onboard_map.occupancy.reshape(-1) == UNKNOWN)[:n]


def test_a_submap_is_cut_when_the_window_has_passed(robot):
    ctx = ctx_for(robot, submap_window_s=10.0)
    node = SendSubmaps(name="Send", ctx=ctx)
    robot.onboard_map.take_changes()
    robot.onboard_map.write(unknown_voxels(robot, 5), FREE)
    assert tick(node, ctx, robot, 10) == Status.RUNNING
    assert sent(robot, SUBMAP) == []
    tick(node, ctx, robot, 1)
    (msg,) = sent(robot, SUBMAP)
    data = msg.data
    assert msg.recipient == "base" and data["robot"] == "r1" and data["index"] == 0
    assert len(data["flat"]) == 5 and np.all(data["values"] == FREE)
    assert np.all(np.asarray(data["bbox_min"]) < np.asarray(data["bbox_max"]))
    # The next window without changes sends nothing.
    tick(node, ctx, robot, 12)
    assert len(sent(robot, SUBMAP)) == 1


def test_a_submap_is_cut_when_the_robot_moved_the_displacement(tunnel, robot):
    _, a, _ = tunnel
    ctx = ctx_for(robot, submap_displacement_m=5.0)
    node = SendSubmaps(name="Send", ctx=ctx)
    robot.onboard_map.write(unknown_voxels(robot, 3), FREE)
    robot.follow_path(np.array([body(a, 20.0)]))
    tick(node, ctx, robot, 7)  # 1 m/s: 5 m after 5 s, far short of the 45 s window
    (msg,) = sent(robot, SUBMAP)
    assert msg.data["t_s"] <= 6.0
    traj = msg.data["trajectory"]
    assert traj.shape[1] == 3 and np.linalg.norm(traj[-1] - traj[0]) >= 5.0


def test_the_rest_is_sent_when_the_behaviour_stops(robot):
    ctx = ctx_for(robot)
    node = SendSubmaps(name="Send", ctx=ctx)
    tick(node, ctx, robot, 3)
    robot.onboard_map.write(unknown_voxels(robot, 2), FREE)
    node.stop(Status.SUCCESS)
    (msg,) = sent(robot, SUBMAP)
    assert len(msg.data["flat"]) == 2


# --------------------------------------------------------------------------- CallHub


def answer(robot, request_id, frontier=(30.0, 0.0, 1.5), path=((10.0, 0.0, 1.5), (30.0, 0.0, 1.5))):
    data = {"request_id": request_id, "frontier": None if frontier is None else list(frontier),
            "path": None if path is None else np.asarray(path), "box_min": None, "box_max": None,
            "cluster_size": 0, "reason": "no_frontier" if frontier is None else "assigned"}
    if frontier is not None:
        data["box_min"], data["box_max"] = [0.0, -5.0, 0.0], [60.0, 5.0, 4.0]
    robot.radio.deliver("base", ASSIGNMENT, data)


def test_out_of_reach_the_call_fails_without_a_request(robot):
    ctx = ctx_for(robot)
    robot.radio.link_up = False
    node = CallHub(name="Call", ctx=ctx, ping_attempts=3)
    node.tick_once()
    assert node.status == Status.FAILURE
    assert len(robot.radio.pings) == 3 and sent(robot, REQUEST) == []
    assert events(ctx, "cohort_call")[0]["reached"] is False
    assert bb("cohort_link_points") is None


def test_a_lost_ping_is_tried_again(robot):
    ctx = ctx_for(robot)
    robot.radio.ping_results.extend([False, True])
    node = CallHub(name="Call", ctx=ctx, ping_attempts=3)
    node.tick_once()
    assert node.status == Status.RUNNING and len(sent(robot, REQUEST)) == 1


def test_the_call_waits_for_the_matching_assignment_and_writes_it(robot):
    ctx = ctx_for(robot)
    node = CallHub(name="Call", ctx=ctx)
    node.tick_once()
    (req,) = sent(robot, REQUEST)
    assert req.data["robot"] == "r1" and req.data["request_id"] == 1
    assert bb("cohort_link_points") == [list(np.round(robot.position, 2))]
    node.tick_once()
    assert node.status == Status.RUNNING
    answer(robot, request_id=7)  # someone else's or an old answer
    node.tick_once()
    assert node.status == Status.RUNNING
    answer(robot, request_id=1)
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert bb("cohort_goal") == [30.0, 0.0, 1.5]
    assert bb("cohort_path") == [[10.0, 0.0, 1.5], [30.0, 0.0, 1.5]]
    assert bb("exploration_bbox") == {"min": [0.0, -5.0, 0.0], "max": [60.0, 5.0, 4.0]}
    assert events(ctx, "cohort_assignment_received")[0]["request_id"] == 1


def test_no_frontier_lifts_the_box(robot):
    ctx = ctx_for(robot)
    py_trees.blackboard.Blackboard.set("/r1/exploration_bbox", {"min": [0, 0, 0], "max": [1, 1, 1]})
    node = CallHub(name="Call", ctx=ctx)
    node.tick_once()
    answer(robot, request_id=1, frontier=None, path=None)
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert bb("cohort_goal") is None and bb("cohort_path") is None and bb("exploration_bbox") is None


@pytest.mark.parametrize("reason", ["explored", "no_frontier"])
def test_the_hubs_word_that_all_is_explored_is_written(robot, reason):
    ctx = ctx_for(robot)
    node = CallHub(name="Call", ctx=ctx)
    node.tick_once()
    robot.radio.deliver("base", ASSIGNMENT, {"request_id": 1, "frontier": None, "path": None, "box_min": None,
                                             "box_max": None, "cluster_size": 0, "reason": reason})
    node.tick_once()
    assert node.status == Status.SUCCESS and bb("cohort_goal") is None
    assert bb("cohort_explored") is (reason == "explored")


def test_no_answer_in_time_fails_and_the_next_call_asks_again(robot):
    ctx = ctx_for(robot)
    node = CallHub(name="Call", ctx=ctx, answer_timeout_s=5.0)
    assert tick(node, ctx, robot, 6) == Status.FAILURE
    assert events(ctx, "cohort_call_unanswered")
    answer(robot, request_id=1)  # too late: dropped by the next call
    node.tick_once()
    assert node.status == Status.RUNNING and sent(robot, REQUEST)[-1].data["request_id"] == 2
    assert len(bb("cohort_link_points")) == 1  # the same place


@pytest.mark.parametrize("link_up", [False, True])
def test_a_failed_call_leaves_nothing_to_follow_and_keeps_the_box(robot, link_up):
    """Out of reach, or unanswered: the goal of an earlier answer is not followed again
    (the cycle reads a goal as a frontier just given), the box stays for the lost-link rule."""
    ctx = ctx_for(robot)
    box = {"min": [0.0, -5.0, 0.0], "max": [60.0, 5.0, 4.0]}
    py_trees.blackboard.Blackboard.set("/r1/cohort_goal", [30.0, 0.0, 1.5])
    py_trees.blackboard.Blackboard.set("/r1/exploration_bbox", box)
    robot.radio.link_up = link_up
    node = CallHub(name="Call", ctx=ctx, answer_timeout_s=5.0)
    assert tick(node, ctx, robot, 6) == Status.FAILURE
    assert bb("cohort_goal") is None and bb("exploration_bbox") == box


# --------------------------------------------------------------------- FollowHubPath


def test_follow_hub_path_drives_the_hubs_path_first(tunnel, robot):
    _, a, _ = tunnel
    ctx = ctx_for(robot)
    hub_path = [body(a, 10.0, 1.0).tolist(), body(a, 20.0).tolist()]
    py_trees.blackboard.Blackboard.set("/r1/cohort_path", hub_path)
    py_trees.blackboard.Blackboard.set("/r1/cohort_goal", hub_path[-1])
    node = FollowHubPath(name="Go", ctx=ctx)
    assert run(node, ctx, robot) == Status.SUCCESS
    assert np.allclose(robot.paths[0][: len(hub_path)], hub_path)
    assert events(ctx, "goto")[0]["source"] == "cohort"


@pytest.mark.parametrize("planner", [True, False])
def test_the_way_flown_joins_gbplanner2s_global_graph(tunnel, robot, planner):
    """From home to 20 m along the hub's path, a chain of visited vertices every
    graph_spacing_m joins GBPlanner2's graph (none is made for an agent without one)."""
    _, a, _ = tunnel
    ctx = ctx_for(robot)
    if planner:
        gbplanner(ctx, robot)
    hub_path = [body(a, 10.0).tolist(), body(a, 20.0).tolist()]
    py_trees.blackboard.Blackboard.set("/r1/cohort_path", hub_path)
    py_trees.blackboard.Blackboard.set("/r1/cohort_goal", hub_path[-1])
    assert run(FollowHubPath(name="Go", ctx=ctx, graph_spacing_m=2.5), ctx, robot) == Status.SUCCESS
    if not planner:
        assert GBPLANNER not in ctx.services
        return
    gp = ctx.services[GBPLANNER].planner.global_planner
    end = gp.robot_vertex
    assert np.linalg.norm(gp.position_of(end) - robot.position) < 2.5
    hops = nx.shortest_path(gp.graph, gp.home_vertex, end)
    steps = np.linalg.norm(np.diff([gp.position_of(v) for v in hops], axis=0), axis=1)
    assert len(hops) >= 6 and steps.max() < 2.5 + 1.0


def test_follow_hub_path_without_a_goal_succeeds_at_once(robot):
    ctx = ctx_for(robot)
    py_trees.blackboard.Blackboard.set("/r1/cohort_goal", None)
    node = FollowHubPath(name="Go", ctx=ctx)
    node.tick_once()
    assert node.status == Status.SUCCESS and robot.paths == []


# ------------------------------------------------------------------ timing, the end


@pytest.mark.parametrize("span, seconds", [("period_s", 8.0), ("extra_explore_s", 3.0)])
def test_cohort_timer_waits_the_span_of_the_teams_params(robot, span, seconds):
    ctx = ctx_for(robot, period_s=8.0, extra_explore_s=3.0)
    node = CohortTimer(name="T", ctx=ctx, span=span)
    assert tick(node, ctx, robot, int(seconds)) == Status.RUNNING
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert bool(events(ctx, "cohort_extra_exploration")) == (span == "extra_explore_s")


@pytest.mark.parametrize("homing, complete, box, explored, over", [
    (True, False, {"min": [0, 0, 0], "max": [1, 1, 1]}, False, True),
    (False, True, None, False, True),
    (False, True, {"min": [0, 0, 0], "max": [1, 1, 1]}, False, False),  # a box explored: ask the hub
    (False, False, None, False, False),
    (False, False, {"min": [0, 0, 0], "max": [1, 1, 1]}, True, True),  # the hub: nothing left
])
def test_exploration_over(robot, homing, complete, box, explored, over):
    ctx = ctx_for(robot)
    for key, value in (("homing_due", homing), ("exploration_complete", complete), ("exploration_bbox", box),
                       ("cohort_explored", explored)):
        py_trees.blackboard.Blackboard.set(f"/r1/{key}", value)
    node = ExplorationOver(name="Over?", ctx=ctx)
    node.tick_once()
    assert node.status == (Status.SUCCESS if over else Status.FAILURE)
    assert len(events(ctx, "exploration_over")) == over
    start = ExplorationOver(name="Over yet?", ctx=ctx, after_box=False)   # a box's end does not count
    start.tick_once()
    assert start.status == (Status.SUCCESS if homing or explored else Status.FAILURE)


# ----------------------------------------------------------------- ReturnToLinkPoint


def returning(tunnel, from_m: float, points_m: list[float], **params):
    """A robot ``from_m`` along the tunnel with link points at ``points_m``, its link
    down, and its ReturnToLinkPoint (``params``); returns the robot, its ctx and the node."""
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, from_m), home=body(a, 1.0))
    ctx = ctx_for(robot)
    py_trees.blackboard.Blackboard.set("/r1/cohort_link_points", [body(a, x).tolist() for x in points_m])
    robot.radio.link_up = False
    return robot, ctx, ReturnToLinkPoint(name="Back", ctx=ctx, tolerance_m=0.5, **params)


def test_return_goes_back_point_by_point_until_one_offers_a_link(tunnel):
    _, a, _ = tunnel
    points = [body(a, 8.0).tolist(), body(a, 20.0).tolist()]
    robot, ctx, node = returning(tunnel, 30.0, [8.0, 20.0], ping_every_s=1000.0)  # pings at points only
    assert tick(node, ctx, robot, 15) == Status.RUNNING
    reached = events(ctx, "cohort_link_point")
    assert len(reached) == 1 and reached[0]["linked"] is False and reached[0]["at"] == list(np.round(points[1], 2))
    robot.radio.link_up = True
    assert run(node, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position - points[0]) <= 0.5
    assert events(ctx, "cohort_backtrack")[0]["to"] == list(np.round(points[1], 2))


def test_return_ends_where_a_ping_on_the_way_is_answered(tunnel):
    _, a, _ = tunnel
    robot, ctx, node = returning(tunnel, 30.0, [5.0], ping_every_s=2.0)
    assert tick(node, ctx, robot, 6) == Status.RUNNING
    assert [t for t, _ in robot.radio.pings] == [2.0, 4.0]   # one ping every 2 s, none answered
    robot.radio.link_up = True
    assert run(node, ctx, robot) == Status.SUCCESS
    (regained,) = events(ctx, "cohort_link_regained")
    assert regained["at"] == list(np.round(robot.position, 2)) and regained["to"] == list(np.round(body(a, 5.0), 2))
    assert body(a, 5.0)[0] + 5.0 < robot.position[0] < body(a, 30.0)[0]   # on the way, well short of the point
    assert not events(ctx, "cohort_link_point") and robot.path_status != PathStatus.FOLLOWING


def test_return_follows_gbplanner2s_global_graph_and_the_navigation_graph_where_it_has_none(tunnel):
    _, a, _ = tunnel
    robot, ctx, node = returning(tunnel, 9.0, [5.0], ping_every_s=1000.0)   # a direct edge of the global graph
    robot.radio.link_up = True
    assert run(node, ctx, robot) == Status.SUCCESS
    assert [e["source"] for e in events(ctx, "goto")] == ["gbplanner2"]
    robot, ctx, node = returning(tunnel, 30.0, [5.0], ping_every_s=1000.0)   # beyond the global graph's reach
    robot.radio.link_up = True
    assert run(node, ctx, robot) == Status.SUCCESS
    assert [e["source"] for e in events(ctx, "goto")] == ["navigator"]


def test_return_ends_at_home_and_fails_when_no_point_links(tunnel):
    robot, ctx, node = returning(tunnel, 20.0, [10.0])
    assert run(node, ctx, robot) == Status.FAILURE
    assert np.linalg.norm(robot.position - robot.home) <= 0.5
    assert [e["linked"] for e in events(ctx, "cohort_link_point")] == [False, False]
    assert bb("goto_failure") == "not_reached" and events(ctx, "goto_failed")


def test_request_ids_count_per_agent_across_call_nodes(robot):
    ctx = ctx_for(robot)
    first, second = CallHub(name="Call", ctx=ctx), CallHub(name="Call again", ctx=ctx)
    first.tick_once()
    second.tick_once()
    assert [m.data["request_id"] for m in sent(robot, REQUEST)] == [1, 2]


def test_a_link_point_near_the_last_replaces_it(tunnel, robot):
    _, a, _ = tunnel
    ctx = ctx_for(robot)
    node = CallHub(name="Call", ctx=ctx, link_point_spacing_m=2.0, answer_timeout_s=1.0)
    for x in (3.0, 4.0, 10.0):
        robot._pos = body(a, x)
        node.tick_once()
        ctx.clock.now_s += 2.0
        node.tick_once()  # unanswered: FAILURE, the next tick calls again
    assert [p[0] for p in bb("cohort_link_points")] == pytest.approx([body(a, 4.0)[0], body(a, 10.0)[0]])


@pytest.mark.parametrize("explored, repeated", [(True, True), (False, False)])
def test_the_same_target_again_after_its_box_was_explored_counts_as_none(robot, explored, repeated):
    ctx = ctx_for(robot)
    py_trees.blackboard.Blackboard.set("/r1/cohort_target", [31.0, 0.0, 1.5])
    py_trees.blackboard.Blackboard.set("/r1/exploration_complete", explored)
    node = CallHub(name="Call", ctx=ctx, repeat_radius_m=4.0)
    node.tick_once()
    answer(robot, request_id=1)  # the frontier at [30, 0, 1.5]
    node.tick_once()
    assert node.status == Status.SUCCESS
    assert (bb("cohort_goal") is None) == repeated and (bb("exploration_bbox") is None) == repeated
    assert events(ctx, "cohort_assignment_received")[0]["reason"] == ("repeated" if repeated else "assigned")
