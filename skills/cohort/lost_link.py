"""COHORT's timing and its lost-link rule on the robot (Kulkarni et al. 2022, section
IV-B): explore T_C seconds between calls to the hub; when a call finds no link, explore
T_C^e seconds more unless the box is explored, then go back to the last point that
offered a link, and further back point by point if that one offers none either."""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.geometry import xyz
from ..base import Param, Skill
from ..motion import GoTo
from .robot import cohort_params, linked, record_transit

#: What ``CohortTimer`` waits for: T_C or T_C^e (fields of CohortParams).
SPANS = ("period_s", "extra_explore_s")


class CohortTimer(Skill):
    """Wait T_C (``span: period_s``: the exploration between two calls to the hub) or
    T_C^e (``span: extra_explore_s``: the exploration a robot out of reach does before
    it backtracks) of sim time, as ``cohort_params`` gives them. Runs beside the
    exploration in a Parallel that ends when either does.

    Returns RUNNING until the span has passed since it was entered, then SUCCESS.
    """

    AGENT = None
    PARAMS = {"span": Param(str, "period_s", "which COHORT time: T_C (period_s) or T_C^e (extra_explore_s)",
                            choices=SPANS)}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.end_s = float("inf")

    def initialise(self) -> None:
        span = float(getattr(cohort_params(self.ctx), self.p["span"]))
        self.end_s = self.ctx.clock.now_s + span
        if self.p["span"] == "extra_explore_s":
            self.event("cohort_extra_exploration", duration_s=span)

    def update(self) -> Status:
        left = self.end_s - self.ctx.clock.now_s
        if left <= 1e-9:
            return Status.SUCCESS
        self.feedback_message = f"{left:.0f} s to go"
        return Status.RUNNING


class ExplorationOver(Skill):
    """Whether this robot's exploration is over: GBPlanner2 decided that homing is due,
    or it found nothing left to explore with no box around it (a box explored is not
    the end: the hub gives the next one), or the hub answered that its common map has
    no frontier left (the team explored its world).

    With ``after_box: false`` GBPlanner2's "nothing left" does not count: at the start
    of a cycle it may be a box's end, and the box was just lifted.

    Reads ``homing_due``, ``exploration_complete``, ``exploration_bbox`` and
    ``cohort_explored``. Returns SUCCESS when over (logging ``exploration_over`` with
    why), else FAILURE.
    """

    AGENT = None
    PARAMS = {"after_box": Param(bool, True, "GBPlanner2's 'nothing left' with no box counts as over")}
    INPUT_PORTS = {
        "homing_due": PortInformation(bool, required=False, description="GBPlanner2 calls for homing"),
        "exploration_complete": PortInformation(bool, required=False, description="GBPlanner2 found nothing left"),
        "exploration_bbox": PortInformation(dict | None, required=False, description="the box explored; null: none"),
        "cohort_explored": PortInformation(bool, required=False, description="the hub's common map has no frontier "
                                           "left"),
    }

    def update(self) -> Status:
        if self.read("homing_due"):
            why = "homing due"
        elif self.read("cohort_explored"):
            why = "the hub's common map has no frontier left"
        elif self.p["after_box"] and self.read("exploration_complete") and self.read("exploration_bbox") is None:
            why = "nothing left to explore, no box"
        else:
            return Status.FAILURE
        self.feedback_message = why
        self.event("exploration_over", why=why)
        return Status.SUCCESS


class ReturnToLinkPoint(GoTo):
    """The lost-link rule's way back: go to the last point that offered a link to the
    hub (``cohort_link_points``, written by ``CallHub``; the robot's home comes before
    the first), ping the hub there, and when it does not answer (or the point cannot be
    reached) go on to the point before, and so on. On the way it pings the hub every
    ``ping_every_s``: the way back is for the link, so an answer ends it where the
    robot is (the paper names the point, not what the robot does when the link comes
    back sooner).

    The way back follows GBPlanner2's global graph (``planner: gbplanner``): the
    navigation graph of the onboard map keeps more room around an aerial robot than
    GBPlanner2's box and found no way through squeezes the robot had flown through
    (the robot then gave up exploring). The way flown is added to GBPlanner2's global
    graph as ``FollowHubPath`` adds its own. Reads ``cohort_link_points``; writes
    ``goto_failure`` as ``GoTo``. Logs ``cohort_backtrack`` when it sets out,
    ``cohort_link_point`` at each point reached (linked or not) and
    ``cohort_link_regained`` where a ping on the way was answered. Returns RUNNING on
    the way; SUCCESS where the hub answers; FAILURE when no point offers a link.
    """

    PARAMS = {**{k: v for k, v in GoTo.PARAMS.items() if k not in ("goal", "goal_key")},
              "planner": replace(GoTo.PARAMS["planner"], default="gbplanner"),
              "ping_attempts": Param(int, 3, "pings tried at a point before it counts as without link", minimum=1),
              "ping_every_s": Param(float, 2.0, "on the way, one ping this often; an answer ends the way back",
                                    exclusive_minimum=0),
              "graph_spacing_m": Param(float, 2.0, "the way flown joins GBPlanner2's global graph a vertex this "
                                       "far apart", exclusive_minimum=0)}
    INPUT_PORTS = {"cohort_link_points": PortInformation(list, required=False, default_value=[],
                                                         description="[x, y, z] points that offered a link to the "
                                                         "hub, oldest first")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, goal=None, **params)
        self.points: list[np.ndarray] = []
        self.next_ping_s = float("inf")

    def initialise(self) -> None:
        super().initialise()
        self.next_ping_s = self.ctx.clock.now_s + self.p["ping_every_s"]
        r = self.robot
        self.points = [r.home.copy(), *(np.asarray(p, float) for p in self.read("cohort_link_points") or [])]
        self.goal = self.points.pop()
        self.event("cohort_backtrack", to=xyz(self.goal, 2), points_left=len(self.points),
                   position=xyz(r.position, 2))

    def _read_goal(self) -> np.ndarray | None:
        return self.goal

    def update(self) -> Status:
        status = super().update()
        record_transit(self.ctx, self.robot, self.p["graph_spacing_m"])
        return status

    def reached(self) -> bool:
        """At the link point, or the hub answered this tick's ping on the way."""
        if super().reached():
            return True
        if self.ctx.clock.now_s < self.next_ping_s:
            return False
        self.next_ping_s = self.ctx.clock.now_s + self.p["ping_every_s"]
        return linked(self.robot.radio, 1)

    def arrived(self) -> Status:
        if not super().reached():   # short of the point: a ping on the way was answered
            self.event("cohort_link_regained", at=xyz(self.robot.position, 2), to=xyz(self.goal, 2))
            return Status.SUCCESS
        ok = linked(self.robot.radio, self.p["ping_attempts"])
        self.event("cohort_link_point", at=xyz(self.goal, 2), linked=ok)
        return Status.SUCCESS if ok else self._next("no link there")

    def _fail(self, code: str, reason: str) -> Status:
        return self._next(reason) if self.points else super()._fail(code, reason)

    def _next(self, why: str) -> Status:
        """Go on to the link point before this one; FAILURE when none is left."""
        if not self.points:
            return super()._fail("not_reached", "no link point offers a link")
        self.goal, self.last_end, self.replans, self.moving = self.points.pop(), None, 0, False
        self.feedback_message = f"{why}: on to {xyz(self.goal, 1)}"
        return Status.RUNNING


__all__ = ["SPANS", "CohortTimer", "ExplorationOver", "ReturnToLinkPoint"]
