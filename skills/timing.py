"""Timers on the simulation clock.

py_trees' own :class:`py_trees.timers.Timer` and :class:`py_trees.decorators.Timeout`
read the wall clock (``time.monotonic``), which is wrong when the simulation runs
faster (or slower) than real time. These read the agent's clock, ``ctx.clock.now_s``,
instead; trees name them ``Timer`` and ``Timeout``.
"""
from __future__ import annotations

import math
from typing import Any

import py_trees
from py_trees.common import Status

from .base import REQUIRED, AgentContext, Param, Skill

__all__ = ["Timeout", "Timer"]


def _check_duration(duration_s: Any) -> float:
    problem = Param(float, minimum=0.0).problem(duration_s)
    if problem is None and math.isinf(duration_s):
        problem = "must be finite"
    if problem is not None:
        raise ValueError(f"duration_s {problem}")
    return float(duration_s)


class Timer(Skill):
    """Wait for a span of simulation time.

    The finish time is set when the behaviour is entered (``initialise``), so a timer
    that is interrupted and ticked again starts over.

    Reads: the agent's clock (``ctx.clock.now_s``); no blackboard keys.
    Writes: nothing.

    Returns:
        RUNNING while less than ``duration_s`` of sim time has passed since it was
        entered; SUCCESS once ``duration_s`` has passed (at once when it is 0).
        Never FAILURE.
    """

    AGENT = None
    PARAMS = {
        "duration_s": Param(float, REQUIRED, doc="sim time to wait, in seconds", minimum=0.0),
    }

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.duration_s = _check_duration(self.p["duration_s"])
        self.finish_s = math.inf

    def initialise(self) -> None:
        self.finish_s = self.ctx.clock.now_s + self.duration_s

    def update(self) -> Status:
        remaining_s = self.finish_s - self.ctx.clock.now_s
        if remaining_s <= 0.0:
            self.feedback_message = f"{self.duration_s:g} s elapsed"
            return Status.SUCCESS
        self.feedback_message = f"{remaining_s:.3g} s to go"
        return Status.RUNNING


class Timeout(py_trees.decorators.Decorator):
    """Run a child/subtree for at most ``duration_s`` of simulation time.

    The clock starts when the decorator is entered (``initialise``). While the child
    runs, its status is reflected; once it has been RUNNING for ``duration_s`` of sim
    time the decorator stops it (status INVALID), logs a ``timeout`` event and fails.

    Reads: the agent's clock (``ctx.clock.now_s``); no blackboard keys.
    Writes: nothing; logs ``timeout`` (agent, node, duration_s) when it fires.

    Returns:
        FAILURE when the child is still RUNNING ``duration_s`` after entry (the child
        is stopped); otherwise the child's status: RUNNING while it runs, SUCCESS or
        FAILURE when it finishes in time.
    """

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour, ctx: AgentContext, duration_s: float):
        super().__init__(name=name, child=child)
        self.ctx = ctx
        self.duration_s = _check_duration(duration_s)
        self.finish_s = math.inf

    def initialise(self) -> None:
        self.finish_s = self.ctx.clock.now_s + self.duration_s
        self.feedback_message = ""

    def update(self) -> Status:
        child_status = self.decorated.status
        if child_status != Status.RUNNING:
            self.feedback_message = "child finished before the timeout"
            return child_status
        remaining_s = self.finish_s - self.ctx.clock.now_s
        if remaining_s <= 0.0:
            self.feedback_message = f"timed out after {self.duration_s:g} s"
            self.decorated.stop(Status.INVALID)
            self.ctx.log("timeout", agent=self.ctx.name, node=self.name, duration_s=self.duration_s)
            return Status.FAILURE
        self.feedback_message = f"{remaining_s:.3g} s left"
        return Status.RUNNING
