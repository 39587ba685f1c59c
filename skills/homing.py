"""Endurance and homing skills: whether it is time to go home, and going home."""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.geometry import path_length
from ..planners.trail import TrailWalk
from .base import Param, Skill
from .gbplanner import gbplanner, onboard_grid
from .motion_base import PathMotion, trail_jump_check
from .navigation import navigator
from .robot import PathStatus


class EnduranceLow(Skill):
    """Whether the remaining endurance barely covers the way home.

    The way home is the shortest path on the onboard map from the robot to its home
    (its straight-line length times ``detour_factor`` while no path is known). It is
    re-planned at most every ``check_period_s``, and only when the reserve could have
    run out: the way home grows by at most the distance walked, so the reserve
    shrinks by at most ``1 + safety_factor`` seconds per second.

    Writes: ``time_to_home_s``. Returns SUCCESS when
    ``endurance <= safety_factor * time_to_home + margin_s``, else FAILURE.
    """

    PARAMS = {
        "safety_factor": Param(float, 1.2, "multiplies the time the way home takes", minimum=1.0),
        "margin_s": Param(float, 60.0, "reserve kept on top", minimum=0),
        "check_period_s": Param(float, 5.0, "how often the way home is re-planned", exclusive_minimum=0),
        "detour_factor": Param(float, 1.5, "straight line to path length when no path is known", minimum=1.0),
    }
    OUTPUT_PORTS = {"time_to_home_s": PortInformation(float, description="time the way home takes (s), as last "
                                                                          "planned")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.next_check_s = -float("inf")
        self.time_to_home_s = 0.0

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        sf = self.p["safety_factor"]
        if now >= self.next_check_s:
            _, length = navigator(self.ctx, r).path_to_point(r.home)
            if not np.isfinite(length):
                length = float(np.linalg.norm(r.position - r.home)) * self.p["detour_factor"]
            self.time_to_home_s = length / r.mobility.speed_mps
            self.write("time_to_home_s", round(self.time_to_home_s, 2))
            reserve = r.endurance_remaining_s - (sf * self.time_to_home_s + self.p["margin_s"])
            self.next_check_s = now + max(self.p["check_period_s"], reserve / (1 + sf))
        needed = sf * self.time_to_home_s + self.p["margin_s"]
        if r.endurance_remaining_s <= needed:
            self.feedback_message = f"{r.endurance_remaining_s:.0f} s left, home takes {self.time_to_home_s:.0f} s"
            self.event("endurance_low", trigger=True, endurance_s=round(r.endurance_remaining_s, 1),
                       time_to_home_s=round(self.time_to_home_s, 1))
            return Status.SUCCESS
        return Status.FAILURE


class Home(PathMotion):
    """Go home along the way ``path_source`` gives, re-planned when blocked or short.

    ``path_source: gbplanner2`` (the CERBERUS homing): along GBPlanner2's global graph
    (the planner's homing path); when it has no path, or its path turned out blocked,
    along the navigation graph of the onboard map; and when that fails too, back
    along the robot's own traversed path (loops cut out), which it has walked before,
    then exactly as walked. A blocked path moves on to the next of these; an arrival
    short of home starts again from the first.
    ``path_source: navigator``: the shortest path on the navigation graph of the
    onboard map, re-planned on the current map each time; straight for home where the
    graph has none.

    Writes: ``returned_home`` (True on arrival), ``planner_mode`` (``homing``).
    Returns: RUNNING on the way; SUCCESS within ``tolerance_m`` of home; FAILURE when
    no path home is found, or after ``max_replans`` re-plans (blocked paths, or
    arrivals short of home).
    """

    #: Where the way home comes from, by ``path_source``: the sources in the order they
    #: are tried, and whether the robot heads straight for home when none has a path
    #: (else FAILURE). ``traversed_path`` has its loops cut out, ``traversed_path_exact``
    #: is exactly as walked.
    PATH_SOURCES: ClassVar[dict[str, tuple[tuple[str, ...], bool]]] = {
        "gbplanner2": (("gbplanner2", "navigator", "traversed_path", "traversed_path_exact"), False),
        "navigator": (("navigator",), True),
    }

    PARAMS = {
        "path_source": Param(str, "gbplanner2", "where the way home comes from: GBPlanner2's global graph (with "
                             "the navigation graph and the traversed path as fall-backs), or the navigation graph "
                             "of the onboard map", choices=tuple(PATH_SOURCES)),
        "tolerance_m": Param(float, 1.0, "distance to home that counts as home", exclusive_minimum=0),
        "max_replans": Param(int, 5, "re-plans allowed after a blocked path or an arrival short of home", minimum=0),
    }

    OUTPUT_PORTS = {
        "returned_home": PortInformation(bool, description="True once home"),
        "planner_mode": PortInformation(str, description="``homing`` once a way home is planned"),
    }

    #: Former YAML names of this behaviour, and the parameters each stands for.
    ALIASES: ClassVar[dict[str, dict[str, Any]]] = {"ReturnHome": {"path_source": "navigator"}}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.sources, self.straight_home = self.PATH_SOURCES[self.p["path_source"]]
        self.first_source = 0
        self.source = 0
        self.walk: TrailWalk | None = None

    def initialise(self) -> None:
        super().initialise()
        self.first_source, self.source, self.walk = 0, 0, None

    def reached(self) -> bool:
        r = self.robot
        return bool(np.linalg.norm(r.position - r.home) <= self.p["tolerance_m"])

    def arrived(self) -> Status:
        self.write("returned_home", True)
        self.event("home_reached", endurance_s=round(self.robot.endurance_remaining_s, 1))
        return Status.SUCCESS

    def path_ended(self, status: PathStatus) -> Status | None:
        # A blocked path: the next source; an arrival short of home: from the top.
        self.first_source = (self.source + 1) % len(self.sources) if status == PathStatus.BLOCKED else 0
        if status == PathStatus.BLOCKED:
            self.event("homing_path_blocked", source=self.sources[self.source], reason=self.robot.blocked_reason)
        return None

    def give_up(self, status: PathStatus, reason: str) -> Status:
        return self._fail(f"not home after {self.replans - 1} re-plans ({reason or status})")

    def plan(self) -> Status:
        r = self.robot
        path = None
        for k in range(len(self.sources)):
            self.source = (self.first_source + k) % len(self.sources)
            try:
                path = self._path(self.sources[self.source])
            except Exception as err:  # a failed planner call never crashes the tree
                self.event("homing_planner_error", source=self.sources[self.source],
                           reason=f"{type(err).__name__}: {err}")
                path = None
            if path is not None and len(path):
                break
        source = self.sources[self.source]
        if path is None or not len(path):
            if not self.straight_home:
                return self._fail("no path home")
            path, source = np.array([r.home]), "straight"  # the last stretch: straight to the start pose
        if not source.startswith("traversed_path"):
            self.walk = None
        path = np.vstack([path, r.home])
        self.drive(path)
        self.write("planner_mode", "homing")
        length = path_length(np.vstack([r.position, path]))
        self.feedback_message = f"home is {length:.0f} m away ({source})"
        self.event("homing", source=source, path_length_m=round(length, 1))
        return Status.RUNNING

    def _path(self, source: str) -> np.ndarray | None:
        r = self.robot
        if source == "gbplanner2":
            res = gbplanner(self.ctx, r).planner.home(onboard_grid(self.ctx, r), r.position)
            return res.path if res.ok else None
        if source == "navigator":
            path, _ = navigator(self.ctx, r).path_to_point(r.home, force=True)
            return path
        trail = r.traversed_path
        if len(trail) == 0 or np.linalg.norm(trail[0] - r.home) > self.p["tolerance_m"]:
            return None  # a traversed path that does not start at home does not lead there
        if source == "traversed_path":
            self.walk = TrailWalk.plan(trail, None, can_jump=trail_jump_check(r))
            return self.walk.path
        if self.walk is not None:
            # The loop-cut way back was blocked: the rest of it exactly as walked.
            return self.walk.exact_rest(r.position)
        return TrailWalk.plan(trail, None, loop_radius_m=0.0).path

    def _fail(self, reason: str) -> Status:
        self.feedback_message = reason
        self.event("homing_failed", reason=reason)
        return Status.FAILURE


class EndSortie(Skill):
    """Home after homing: the mission ends, or only the sortie does.

    The CERBERUS supervisor sent robots on short budgeted sorties and re-tasked them
    when they came back, so homing ends a sortie; it ends the mission when the
    supervisor called the robot home, when no supervisor ever tasked it, or when
    GBPlanner2 sent it home because its endurance barely covered the way.
    Reads ``end_at_home`` (written by ProcessOperatorCommands; True when unset) and
    ``homing_due`` (written by ExploreGBPlanner2). Returns SUCCESS when either is
    True (the mission is over). Otherwise writes ``mode``
    idle and clears ``time_budget_s`` and ``budget_start_s``, logs ``sortie_ended``
    and returns FAILURE, so that the tree's lower blocks run (the last one waits for
    the next command).
    """

    INPUT_PORTS = {
        "end_at_home": PortInformation(bool, required=False, default_value=True,
                                       description="True: homing ends the mission"),
        "homing_due": PortInformation(bool, required=False, default_value=False,
                                      description="True: the endurance called the robot home"),
    }
    OUTPUT_PORTS = {
        "mode": PortInformation(str, description="``idle`` after a sortie"),
        "time_budget_s": PortInformation(float | None, description="cleared after a sortie"),
        "budget_start_s": PortInformation(float | None, description="cleared after a sortie"),
    }

    def update(self) -> Status:
        if self.read("end_at_home", True) or self.read("homing_due", False):
            self.feedback_message = "home: the mission is over"
            return Status.SUCCESS
        self.write("mode", "idle")
        self.write("time_budget_s", None)
        self.write("budget_start_s", None)
        self.feedback_message = "home from a sortie: waiting for commands"
        self.event("sortie_ended", endurance_s=round(self.robot.endurance_remaining_s, 1))
        return Status.FAILURE


__all__ = ["EndSortie", "EnduranceLow", "Home"]
