"""delve.skills.csiro.explore_sync: out of contact for the sync time -> back into radio range ->
uplink -> back to the region being explored."""
from __future__ import annotations

import numpy as np
from delve.skills.csiro import CONFIG_SERVICE, CsiroConfig, ReturnToComms, ReturnToRegion, SyncDue, Uplink, \
    csiro_state
from py_trees.common import Status

from delve.skills.navigation import navigator

from ..fakes import FakeRobot, bb, body, events, make_ctx, run


def walked(tunnel, sync_s: float = 30.0):
    """A robot that walked the tunnel from x = 7 to 40 (its topometric map), with the link to
    the base station up to x = 15 only."""
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 0.0))
    ctx = make_ctx(robot)
    ctx.services[CONFIG_SERVICE] = CsiroConfig(explore_sync_s=sync_s)
    st = csiro_state(ctx)
    due = SyncDue("due", ctx)
    for k, x in enumerate(np.arange(7.0, 40.5, 1.0)):
        robot._pos = np.array([x, 6.0, 1.5])
        robot.radio.link_up = x <= 15.0
        st.topometric.add_pose("r1", float(k), robot.position)
        due.tick_once()
        ctx.clock.now_s += 1.0
    return robot, ctx, st, due


def test_sync_is_due_after_the_set_time_out_of_contact(tunnel):
    robot, ctx, st, due = walked(tunnel, sync_s=30.0)
    assert due.status == Status.FAILURE and bb("csiro_out_of_contact_s") == 25.0
    assert np.allclose(st.contact, [15.0, 6.0, 1.5])
    for _ in range(6):
        due.tick_once()
        ctx.clock.now_s += 1.0
    assert due.status == Status.SUCCESS
    assert np.allclose(st.region, [40.0, 6.0, 1.5])
    assert events(ctx, "csiro_sync_due")[0]["last_contact"] == [15.0, 6.0, 1.5]


class LinkWithin:
    """The fake radio's link: up while the robot is at x <= ``x_max``."""

    def __init__(self, robot, x_max: float):
        self.robot, self.x_max = robot, x_max

    def __call__(self, other: str) -> bool:
        return bool(self.robot.position[0] <= self.x_max)


def test_back_into_range_uplink_and_back_to_the_region(tunnel):
    robot, ctx, st, due = walked(tunnel, sync_s=20.0)
    due.tick_once()
    assert due.status == Status.SUCCESS
    robot.radio.linked_to = LinkWithin(robot, 15.0)
    back = ReturnToComms("back", ctx)
    assert run(back, ctx, robot, ticks=60) == Status.SUCCESS
    assert 14.0 <= robot.position[0] <= 15.0                      # stopped as soon as the link came back
    first = robot.paths[0]
    assert np.allclose(first[:, 1], 6.0) and first[-1][0] <= 16.0   # along its own trajectory
    robot.radio.send("base", "map_delta", {})                        # queued out of range
    up = Uplink("uplink", ctx, min_wait_s=6.0)
    assert run(up, ctx, robot, ticks=8) == Status.RUNNING           # the outbox has not drained
    robot.radio.flush()
    assert run(up, ctx, robot, ticks=3) == Status.SUCCESS
    assert events(ctx, "csiro_sync")[0]["pending"] == 0
    region = ReturnToRegion("region", ctx)
    assert run(region, ctx, robot, ticks=60) == Status.SUCCESS
    assert np.linalg.norm(robot.position - [40.0, 6.0, 1.5]) <= 3.0
    assert events(ctx, "csiro_region_reached")[0]["region"] == [40.0, 6.0, 1.5]
    assert st.region is None
    due.tick_once()
    assert due.status == Status.FAILURE                               # the clock started again at the sync


def test_a_blocked_way_back_is_planned_again_on_the_navigation_graph(tunnel):
    """The topometric map's straight steps between trajectory nodes can cut through rock
    (a junction's corner): a re-plan goes by the onboard map's navigation graph, towards home."""
    robot, ctx, st, due = walked(tunnel, sync_s=20.0)
    due.tick_once()
    robot.radio.linked_to = LinkWithin(robot, 15.0)
    robot.block_at = np.array([33.0, 6.0, 1.5])
    back = ReturnToComms("back", ctx)
    run(back, ctx, robot, ticks=12)
    topometric, again = robot.paths[0], robot.paths[1]
    assert np.all(np.diff(topometric[:, 0]) < -0.9)                  # 1 m steps between trajectory nodes
    steps = np.linalg.norm(np.diff(again, axis=0), axis=1)
    assert steps.max() < 0.5                                         # voxel to voxel on the graph
    assert np.linalg.norm(again[-1] - robot.home) < navigator(ctx, robot).snap_radii_m[-1]


def test_a_way_back_that_fails_is_tried_again_after_the_sync_time(tunnel):
    robot, ctx, st, due = walked(tunnel, sync_s=20.0)
    due.tick_once()
    robot.radio.linked_to = LinkWithin(robot, 15.0)
    robot.block_at = np.array([33.0, 6.0, 1.5])                      # no way back at all
    back = ReturnToComms("back", ctx, max_replans=1)
    assert run(back, ctx, robot, ticks=30) == Status.FAILURE
    assert len(events(ctx, "csiro_return_failed")) == 1
    due.tick_once()
    assert due.status == Status.FAILURE                               # explores on meanwhile
    ctx.clock.now_s += 20.0
    due.tick_once()
    assert due.status == Status.SUCCESS


def test_return_to_region_without_a_region_is_done_at_once(tunnel):
    robot, ctx, st, _ = walked(tunnel)
    st.region = None
    node = ReturnToRegion("region", ctx)
    assert run(node, ctx, robot, ticks=1) == Status.SUCCESS and not robot.paths
