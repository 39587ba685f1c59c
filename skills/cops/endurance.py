"""Leaving the plan for home: a COPS robot whose endurance barely covers the way home
(the onboard ``EnduranceLow`` check of every robot), or that could not make a move
of the plan (``TransitionFailed?``), leaves the plan (``LeavePlan``), goes to the
base location (``TransitToBase``; ``Home`` where the network has no route) and tells
the base station there (``GreetBase``)."""
from __future__ import annotations

import math

from py_trees.common import Status

from ..base import Param
from .base import CopsSkill, network_view


class LeavePlan(CopsSkill):
    """Leave the plan for home: mark the robot gone home in its knowledge
    (``gone_home``, carried with its information: partners stop waiting for its
    messages, and the base station plans without it) and stop its motion.

    Reads/writes ``cops``. Logs ``cops_left_plan`` (cycle, part, step, the location
    it leaves from, and the ``reason``: ``endurance``, or ``transition failed: ...``
    when a move of the plan failed). Returns SUCCESS.
    """

    def update(self) -> Status:
        st = self.state
        st.knowledge.gone_home[self.ctx.name] = self.ctx.clock.now_s
        view = network_view(self.ctx)
        reason = f"transition failed: {st.transition_failed}" if st.transition_failed else "endurance"
        self.event("cops_left_plan", cycle=st.cycle, part=st.part, step=st.step,
                   at=view.location() if view is not None else None, reason=reason)
        if self.ctx.robot is not None:
            self.robot.stop()
        return Status.SUCCESS


class TransitToBase(CopsSkill):
    """Go to the base location (service ``base_location``; in it, to the robot's own
    start pose) through the NetworkView's routes.

    Reads ``cops``; drives the robot. Returns RUNNING on the way, SUCCESS there,
    FAILURE without a route (logged ``cops_transition_failed``)."""

    def initialise(self) -> None:
        self.reset_drive()

    def update(self) -> Status:
        moving = self.drive_to(self.ctx.services["base_location"], arrive=True)
        return Status.SUCCESS if moving is None else moving

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()


class GreetBase(CopsSkill):
    """Back home: greet the leader ``greetings`` times, every ``greet_period_s``, with
    everything the robot holds (what it mapped on its way home and that it left the
    plan), then SUCCESS. RUNNING in between.

    Reads ``cops`` (and adds what the robot mapped since its last message)."""

    PARAMS = {**CopsSkill.PARAMS,
              "greetings": Param(int, 3, "how many greetings (the radio may drop some)", minimum=1),
              "greet_period_s": Param(float, 5.0, "time between greetings", exclusive_minimum=0),
              "leader": Param(str, "base", "the agent to greet (the planner at the base)")}

    def initialise(self) -> None:
        self._sent = 0
        self._last = -math.inf

    def update(self) -> Status:
        now = self.ctx.clock.now_s
        if now - self._last >= self.p["greet_period_s"]:
            if self._sent >= self.p["greetings"]:
                return Status.SUCCESS
            self._last = now
            self._sent += 1
            self.greet_home(self.state)
        return Status.RUNNING
