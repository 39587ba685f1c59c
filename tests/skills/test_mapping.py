"""delve.skills.mapping: ShareMap (a robot sends what it mapped) and MergeMaps (the base
station merges it), over the fake robot's radio into a simulator voxel map."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN
from delve.sim.voxel_map import VoxelMap
from delve.skills.base import AgentContext
from delve.skills.mapping import MAP_DELTA
from py_trees.common import Status

from .fakes import Clock, FakeRadio, FakeRobot, body, build, events, make_ctx


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=20)


@pytest.fixture()
def robot(tunnel):
    grid, a, _ = tunnel
    return FakeRobot(grid, body(a, 3.0))


def base_station(grid):
    """The base station's agent: its radio and its (empty) map of the robots' world."""
    log: list = []
    base_map = VoxelMap(grid.occupancy.shape, grid.origin, grid.voxel_size_m)
    ctx = AgentContext(name="base", namespace="/base", clock=Clock(),
                       log=lambda event, **fields: log.append((event, fields)),
                       services={"radio": FakeRadio("base"), "map": base_map})
    ctx.events = log  # type: ignore[attr-defined]
    return ctx


def carry(robot, base_ctx) -> None:
    """The link carries the robot's outbox to the base station."""
    for msg in robot.radio.flush():
        base_ctx.services["radio"].deliver(msg.sender, msg.kind, msg.data, msg.sent_s)


def mapped(grid, part: int, parts: int = 12) -> np.ndarray:
    """Flat indices of the ``part``-th of ``parts`` runs of the grid's known voxels."""
    return np.array_split(np.flatnonzero(grid.occupancy.reshape(-1) != UNKNOWN), parts)[part]


# -------------------------------------------------------------------------- ShareMap


def test_share_map_sends_the_changes_at_once_then_every_period(tunnel, robot):
    grid, _, _ = tunnel
    ctx = make_ctx(robot)
    share = build("type: ShareMap\nperiod_s: 5.0", ctx)
    changes = {}
    for t in range(12):
        ctx.clock.now_s = float(t)
        flat = mapped(grid, t)
        robot.onboard_map.write(flat, OCCUPIED)  # a scan each second
        changes[t] = flat
        share.tick_once()
        assert share.status == Status.RUNNING  # a background task
    sent = robot.radio.sent
    assert [m.sent_s for m in sent] == [0.0, 5.0, 10.0]
    assert {m.recipient for m in sent} == {"base"} and {m.kind for m in sent} == {MAP_DELTA}
    # Each message carries what changed since the one before: nothing twice, nothing lost.
    assert np.array_equal(sent[0].data["flat"], changes[0])
    assert np.array_equal(sent[1].data["flat"], np.sort(np.concatenate([changes[t] for t in range(1, 6)])))
    assert np.array_equal(sent[2].data["flat"], np.sort(np.concatenate([changes[t] for t in range(6, 11)])))
    assert all(np.all(m.data["values"] == OCCUPIED) for m in sent)


def test_share_map_sends_nothing_when_nothing_changed(robot):
    ctx = make_ctx(robot)
    share = build("type: ShareMap\nperiod_s: 1.0", ctx)
    for t in range(5):
        ctx.clock.now_s = float(t)
        share.tick_once()
    share.stop(Status.INVALID)
    assert robot.radio.sent == []


def test_share_map_sends_the_last_changes_when_stopped(tunnel, robot):
    grid, _, _ = tunnel
    ctx = make_ctx(robot)
    share = build("type: ShareMap\nperiod_s: 5.0\nrecipient: relay", ctx)
    share.tick_once()
    ctx.clock.now_s = 2.0
    robot.onboard_map.write(mapped(grid, 0), FREE)
    share.tick_once()
    assert robot.radio.sent == []  # not yet time
    share.stop(Status.INVALID)  # the mission ends (or the tree moves on)
    (last,) = robot.radio.sent
    assert last.recipient == "relay" and np.array_equal(last.data["flat"], mapped(grid, 0))


def test_share_map_keeps_sending_while_the_link_is_down(tunnel, robot):
    """Messages wait in the radio's outbox: the skill does not hold back or drop changes."""
    grid, _, _ = tunnel
    ctx = make_ctx(robot)
    robot.radio.link_up = False
    share = build("type: ShareMap\nperiod_s: 1.0", ctx)
    for t in range(3):
        ctx.clock.now_s = float(t)
        robot.onboard_map.write(mapped(grid, t), FREE)
        share.tick_once()
    assert robot.radio.pending == 3


# ------------------------------------------------------------------------- MergeMaps


def test_the_base_map_becomes_the_robots_map(tunnel, robot):
    grid, _, _ = tunnel
    ctx = make_ctx(robot)
    base = base_station(grid)
    share = build("type: ShareMap\nperiod_s: 5.0", ctx)
    merge = build("type: MergeMaps", base)
    known = np.flatnonzero(grid.occupancy.reshape(-1) != UNKNOWN)
    halves = np.array_split(known, 2)
    for t, part in enumerate(halves):  # the robot maps its world in two scans
        ctx.clock.now_s = base.clock.now_s = 5.0 * t
        robot.onboard_map.write(part, UNKNOWN)  # changed ...
        robot.onboard_map.write(part, grid.occupancy.reshape(-1)[part])  # ... to what the robot saw
        share.tick_once()
        carry(robot, base)
        merge.tick_once()
        assert merge.status == Status.RUNNING
    assert np.array_equal(base.services["map"].occupancy, grid.occupancy)
    assert base.events == []  # map deltas are merged, not logged


def test_the_base_map_merges_two_robots(tunnel):
    grid, a, _ = tunnel
    base = base_station(grid)
    merge = build("type: MergeMaps", base)
    first = np.concatenate([mapped(grid, 0, 3), mapped(grid, 1, 3)])
    second = np.concatenate([mapped(grid, 1, 3), mapped(grid, 2, 4)])  # some overlap, some never seen
    for name, flat in (("r1", first), ("r2", second)):
        robot = FakeRobot(grid, body(a, 3.0))
        robot.radio.name = name
        robot.onboard_map.write(flat, grid.occupancy.reshape(-1)[flat])
        build("type: ShareMap", make_ctx(robot, name)).tick_once()
        carry(robot, base)
    merge.tick_once()
    merged = base.services["map"].occupancy.reshape(-1)
    both = np.union1d(first, second)
    assert np.array_equal(merged[both], grid.occupancy.reshape(-1)[both])
    assert np.all(np.delete(merged, both) == UNKNOWN)


def test_other_messages_are_logged_for_the_supervisor(tunnel):
    grid, _, _ = tunnel
    base = base_station(grid)
    merge = build("type: MergeMaps", base)
    radio = base.services["radio"]
    radio.deliver("r1", "goal_unreachable", {"goal": [1, 2, 3], "reason": "no_path"}, sent_s=7.5)
    radio.deliver("r2", MAP_DELTA, {"flat": np.array([0]), "values": np.array([FREE], np.int8)})
    merge.tick_once()
    assert merge.status == Status.RUNNING
    (logged,) = events(base, "base_received")
    assert logged == {"agent": "base", "node": "MergeMaps", "sender": "r1", "kind": "goal_unreachable",
                      "data": {"goal": [1, 2, 3], "reason": "no_path"}, "sent_s": 7.5}
    assert base.services["map"].occupancy.reshape(-1)[0] == FREE
