"""Planner faults: GBPlanner2 raises, or takes long, on a robot.

The seam is the agent's planner service (``ctx.services["gbplanner"]``, the one
GBPlanner2 that ``ExploreGBPlanner2``, ``Home``, ``GoTo`` and ``Relocate`` of a robot
share): the fault wraps that planner's ``plan``, and the wrapper passes every call
through once the fault has ended (so overlapping faults nest). Skills see a planner
that raises (``ExploreGBPlanner2`` logs ``explore_failed`` with the error and fails)
or a plan that arrives late (the robot stands while the planner "thinks"), and never
learn that a simulator exists. The service is made by the robot's first plan; a
fault that starts before it takes hold as soon as it exists.
"""
from __future__ import annotations

from abc import abstractmethod

from typing import TYPE_CHECKING, Any, Callable

from ...skills.base import Param
from ...skills.gbplanner import SERVICE, Explore
from ..errors import DelveError
from .base import OPTIONAL, Fault, FaultContext, Target

if TYPE_CHECKING:
    from ..runner import Mission
    from ..yamlio import YamlDict


class InjectedPlannerError(RuntimeError):
    """What a planner raises under a ``planner_error`` fault."""


class _PlannerFault(Fault):
    """A fault that wraps the robot's GBPlanner2 ``plan`` while it lasts. Without
    ``duration_s`` it hits the next plan only."""

    DURATION = OPTIONAL

    def __init__(self, *args: Any, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self._planner: Any = None
        self.holds = False
        self.hits = 0

    @classmethod
    def check(cls, item: "YamlDict", target: Target, ctx: FaultContext) -> None:
        if not any(issubclass(t, Explore) for t in ctx.tree_types.get(target.names[0], ())):
            raise DelveError(f"fault {cls.KIND!r}: robot {target.names[0]!r} does not plan with GBPlanner2 "
                             f"(its tree has no ExploreGBPlanner2)", ctx.path, item.key_line("robot"))

    def start(self, mission: "Mission") -> dict[str, Any]:
        self.step(mission, mission.clock.now_s)
        return {}

    def step(self, mission: "Mission", now_s: float) -> None:
        if self._planner is not None or self.hits:
            return
        svc = mission.agents[self.robot].ctx.services.get(SERVICE)
        if svc is not None:
            self._planner, self.holds = svc.planner, True
            inner = self._planner.plan
            faulty = self._wrap(inner, mission)
            self._planner.plan = lambda *args, **kwargs: (faulty if self.holds else inner)(*args, **kwargs)

    def _hit(self) -> None:
        """Count a plan the fault hit; a fault without an end lets go after the first."""
        self.hits += 1
        if self.duration_s is None:
            self._release()

    def _release(self) -> None:
        """From now on the wrapper passes every call through."""
        self.holds = False

    def end(self, mission: "Mission") -> dict[str, Any]:
        self._release()
        return {"plans_hit": self.hits}

    @abstractmethod
    def _wrap(self, plan: Callable[..., Any], mission: "Mission") -> Callable[..., Any]:
        """The planner's ``plan`` as this fault makes it behave."""


class PlannerError(_PlannerFault):
    """The robot's GBPlanner2 raises on its next plan (on every plan until
    ``duration_s`` has passed, when given); ``ExploreGBPlanner2`` fails with the
    error (``explore_failed``, reason ``error``) and the tree takes over."""

    KIND = "planner_error"

    def _wrap(self, plan: Callable[..., Any], mission: "Mission") -> Callable[..., Any]:
        def failing_plan(*args: Any, **kwargs: Any) -> Any:
            self._hit()
            raise InjectedPlannerError(f"planner fault injected at {self.at_s:g} s")
        return failing_plan


class PlannerSlow(_PlannerFault):
    """The robot's GBPlanner2 takes ``delay_s`` of sim time over its next plan (every
    plan until ``duration_s`` has passed, when given): the path comes that late, and
    the robot stands meanwhile."""

    KIND = "planner_slow"
    PARAMS = {"delay_s": Param(float, 30.0, "sim time one plan takes", exclusive_minimum=0.0, maximum=1e5)}

    def _wrap(self, plan: Callable[..., Any], mission: "Mission") -> Callable[..., Any]:
        robot = mission.robots[self.robot]

        def slow_plan(*args: Any, **kwargs: Any) -> Any:
            res = plan(*args, **kwargs)
            if getattr(res, "ok", False):
                self._hit()
                # The path is followed once the planner is done: the robot stands until then.
                robot.jam(self.p["delay_s"])
                mission.log("planner_delayed", robot=self.robot, delay_s=self.p["delay_s"])
            return res
        return slow_plan
