"""delve.skills.timing: Timer and Timeout on the simulation clock."""
from __future__ import annotations

import time

import py_trees
import pytest
from delve.skills.base import AgentContext
from delve.skills.timing import Timeout, Timer
from py_trees.common import Status


class Clock:
    """A sim clock stub: tests set ``now_s``."""

    def __init__(self, now_s: float = 0.0):
        self.now_s = now_s


@pytest.fixture()
def ctx():
    py_trees.blackboard.Blackboard.clear()
    events = []
    context = AgentContext(
        name="r1", namespace="/r1", clock=Clock(), log=lambda event, **fields: events.append((event, fields))
    )
    context.events = events
    yield context
    py_trees.blackboard.Blackboard.clear()


def tick(node, at_s, ctx):
    ctx.clock.now_s = at_s
    node.tick_once()
    return node.status


def test_timer_runs_until_sim_time_passes(ctx):
    timer = Timer(name="Wait", ctx=ctx, duration_s=10.0)
    ctx.clock.now_s = 100.0
    assert tick(timer, 100.0, ctx) == Status.RUNNING
    assert tick(timer, 109.9, ctx) == Status.RUNNING
    assert tick(timer, 110.0, ctx) == Status.SUCCESS


def test_timer_ignores_the_wall_clock(ctx):
    timer = Timer(name="Wait", ctx=ctx, duration_s=0.01)
    tick(timer, 0.0, ctx)
    time.sleep(0.03)
    assert tick(timer, 0.0, ctx) == Status.RUNNING


def test_timer_restarts_when_entered_again(ctx):
    timer = Timer(name="Wait", ctx=ctx, duration_s=5)
    tick(timer, 0.0, ctx)
    assert tick(timer, 5.0, ctx) == Status.SUCCESS
    assert tick(timer, 6.0, ctx) == Status.RUNNING  # re-entered: finishes at 11 s
    assert tick(timer, 10.9, ctx) == Status.RUNNING
    assert tick(timer, 11.0, ctx) == Status.SUCCESS


def test_zero_duration_succeeds_at_once(ctx):
    assert tick(Timer(name="Now", ctx=ctx, duration_s=0), 3.0, ctx) == Status.SUCCESS


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), "5", True])
def test_timer_rejects_bad_durations(ctx, bad):
    with pytest.raises(ValueError, match="duration_s"):
        Timer(name="Bad", ctx=ctx, duration_s=bad)
    with pytest.raises(ValueError, match="duration_s"):
        Timeout(name="Bad", child=py_trees.behaviours.Running(name="r"), ctx=ctx, duration_s=bad)


def test_timeout_fails_and_stops_a_child_that_runs_too_long(ctx):
    child = py_trees.behaviours.Running(name="Forever")
    timeout = Timeout(name="Limit", child=child, ctx=ctx, duration_s=5.0)
    assert tick(timeout, 0.0, ctx) == Status.RUNNING
    assert tick(timeout, 4.9, ctx) == Status.RUNNING and child.status == Status.RUNNING
    assert tick(timeout, 5.0, ctx) == Status.FAILURE
    assert child.status == Status.INVALID
    assert ctx.events == [("timeout", {"agent": "r1", "node": "Limit", "duration_s": 5.0})]


def test_timeout_reflects_a_child_that_finishes_in_time(ctx):
    child = Timer(name="Short", ctx=ctx, duration_s=2.0)
    timeout = Timeout(name="Limit", child=child, ctx=ctx, duration_s=5.0)
    assert tick(timeout, 0.0, ctx) == Status.RUNNING
    assert tick(timeout, 2.0, ctx) == Status.SUCCESS
    failing = Timeout(name="L2", child=py_trees.behaviours.Failure(name="f"), ctx=ctx, duration_s=5.0)
    assert tick(failing, 0.0, ctx) == Status.FAILURE
    assert ctx.events == []


def test_timeout_clock_restarts_on_entry(ctx):
    child = py_trees.behaviours.Running(name="Forever")
    timeout = Timeout(name="Limit", child=child, ctx=ctx, duration_s=3.0)
    tick(timeout, 0.0, ctx)
    assert tick(timeout, 3.0, ctx) == Status.FAILURE
    assert tick(timeout, 10.0, ctx) == Status.RUNNING  # entered again at 10 s
    assert tick(timeout, 12.9, ctx) == Status.RUNNING
    assert tick(timeout, 13.0, ctx) == Status.FAILURE


def test_timeout_interrupted_by_a_parent_stops_the_child(ctx):
    child = py_trees.behaviours.Running(name="Forever")
    timeout = Timeout(name="Limit", child=child, ctx=ctx, duration_s=3.0)
    tick(timeout, 0.0, ctx)
    timeout.stop(Status.INVALID)
    assert child.status == Status.INVALID


def test_timer_in_a_tree_with_py_trees_machinery(ctx):
    root = py_trees.composites.Sequence(name="Root", memory=True)
    root.add_children([Timer(name="A", ctx=ctx, duration_s=1), Timer(name="B", ctx=ctx, duration_s=1)])
    tree = py_trees.trees.BehaviourTree(root)
    statuses = []
    for step in range(5):
        ctx.clock.now_s = step * 0.5
        tree.tick()
        statuses.append(root.status)
    # A: 0 -> 1 s; B entered at 1 s -> 2 s
    assert statuses == [Status.RUNNING, Status.RUNNING, Status.RUNNING, Status.RUNNING, Status.SUCCESS]
