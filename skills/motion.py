"""Motion skills: go to a waypoint, and backtrack along the robot's own traversed path
(the CERBERUS behaviour tree's "Recovery Homing" and its WiFi-safety back-off). Both
build on :class:`~.motion_base.PathMotion`; the way back is planned by
:mod:`delve.planners.trail`."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.geometry import path_length, xyz
from ..planners.occupancy import OCCUPIED
from ..planners.trail import TrailWalk
from .base import Param, ParamNamedPort
from .gbplanner import gbplanner, onboard_grid
from .motion_base import PathMotion, trail_jump_check
from .navigation import navigator
from .robot import PathStatus, Robot

#: Codes ``GoTo`` writes to ``goto_failure``.
GOTO_FAILURES = ("no_goal", "no_path", "invalid_start", "blocked", "not_reached", "error")


def goal_distance(robot: Robot, goal: np.ndarray) -> float:
    """How far ``robot`` is from ``goal`` (a body-centre position). For a legged robot
    up to its body height of vertical offset is free, so a goal given on the floor
    counts as reached from above it."""
    d = np.asarray(goal, float) - robot.position
    mob = robot.mobility
    if not mob.aerial:
        d[2] = max(0.0, abs(d[2]) - mob.body_height_m)
    return float(np.linalg.norm(d))


#: ``GoTo``'s ``planner`` choices: the planners each tries, in turn (the ``source`` its
#: ``goto`` event names).
PLANNERS = {"navigator": ("navigator",), "gbplanner": ("gbplanner2", "navigator"),
            "navigator_or_gbplanner": ("navigator", "gbplanner2")}


class GoTo(PathMotion):
    """Go to a waypoint: the param ``goal`` [x, y, z], or else the blackboard key
    ``goal_key`` (a body-centre position in metres).

    The path comes from the navigation graph of the onboard map (``planner:
    navigator``), from GBPlanner2's global graph (``planner: gbplanner``, which falls
    back to the navigation graph when it has no path), or from the navigation graph
    with GBPlanner2's global graph as the fallback (``planner: navigator_or_gbplanner``:
    the known map's shortest way where the graph finds one, else the way the robot
    came). A blocked path or an arrival short of the goal is re-planned, at most
    ``max_replans`` times.

    Reads ``goal_key`` (when ``goal`` is null). Writes ``goto_failure``: null while
    going and after arrival, else why it failed: ``no_goal`` (none given or not a
    point), ``no_path`` (no valid path, e.g. the goal lies inside mapped rock or out
    of reach), ``invalid_start`` (the robot is not on its own navigation graph),
    ``blocked`` or ``not_reached`` (re-plans used up), ``error`` (a planner raised).
    Returns RUNNING on the way, SUCCESS within ``tolerance_m`` of the goal, FAILURE as
    said (with a ``goto_failed`` event in the log).
    """

    PARAMS = {
        "goal": Param(list, None, "waypoint [x, y, z] (m); null: read goal_key", nullable=True, length=3,
                      items=float),
        "goal_key": Param(str, "goal", "blackboard key holding the waypoint [x, y, z]", key=True),
        "planner": Param(str, "navigator", "navigation graph of the onboard map, GBPlanner2's global graph "
                         "(then the navigation graph), or the navigation graph then GBPlanner2's",
                         choices=tuple(PLANNERS)),
        "tolerance_m": Param(float, 1.0, "distance to the goal that counts as arrived", exclusive_minimum=0),
        "max_replans": Param(int, 3, "re-plans after a blocked path or an arrival short of the goal", minimum=0),
    }
    INPUT_PORTS = {"goal": ParamNamedPort(list, required=False, description="waypoint [x, y, z] (m), read when "
                                          "the parameter goal is null", key_param="goal_key")}
    OUTPUT_PORTS = {
        "goto_failure": PortInformation(str | None, description="null while going and after arrival, else why it "
                                        "failed: " + ", ".join(GOTO_FAILURES)),
        "goto_path_length_m": PortInformation(float, description="length of the path last planned (m)"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.goal: np.ndarray | None = None
        self.last_end: np.ndarray | None = None

    def initialise(self) -> None:
        super().initialise()
        self.goal, self.last_end = None, None
        self.write("goto_failure", None)

    def update(self) -> Status:
        if self.goal is None:
            self.goal = self._read_goal()
            if self.goal is None:
                return self._fail("no_goal", "no goal [x, y, z] given")
        return super().update()

    def reached(self) -> bool:
        assert self.goal is not None
        return goal_distance(self.robot, self.goal) <= self.p["tolerance_m"]

    def arrived(self) -> Status:
        assert self.goal is not None
        self.event("goto_reached", goal=xyz(self.goal))
        return Status.SUCCESS

    def give_up(self, status: PathStatus, reason: str) -> Status:
        code = "blocked" if status == PathStatus.BLOCKED else "not_reached"
        return self._fail(code, f"{code} after {self.replans - 1} re-plans ({reason or status})")

    def _read_goal(self) -> np.ndarray | None:
        value = self.p["goal"] if self.p["goal"] is not None else self.read("goal")
        try:
            goal = np.asarray(value, float).reshape(-1)
        except (TypeError, ValueError):
            return None
        return goal if goal.shape == (3,) and np.all(np.isfinite(goal)) else None

    def plan(self) -> Status:
        r, goal = self.robot, self.goal
        assert goal is not None
        grid = onboard_grid(self.ctx, r)
        if grid.value_at(goal[None])[0] == OCCUPIED:
            return self._fail("no_path", "the goal lies inside mapped rock")
        try:
            path, source, code, why = self._path(grid)
        except Exception as err:  # a failed planner call never crashes the tree
            return self._fail("error", f"{type(err).__name__}: {err}")
        if path is None:
            return self._fail(code, why)
        end = path[-1]
        if self.last_end is not None and np.linalg.norm(end - r.position) < 0.5 * self.p["tolerance_m"]:
            # Arrived where the path ends and still short of the goal: nothing nearer is reachable.
            return self._fail("not_reached", f"the nearest reachable point is {goal_distance(r, goal):.1f} m "
                                             "from the goal")
        self.last_end = end
        if grid.value_at(goal[None])[0] != OCCUPIED and np.linalg.norm(end - goal) > 1e-6:
            path = np.vstack([path, goal])
        self.drive(path)
        length = path_length(np.vstack([r.position, path]))
        self.write("goto_path_length_m", round(length, 2))
        self.feedback_message = f"goal {length:.0f} m away ({source})"
        self.event("goto", goal=xyz(goal), source=source, path_length_m=round(length, 1))
        return Status.RUNNING

    def _path(self, grid: Any) -> tuple[np.ndarray | None, str, str, str]:
        """(path, source, failure code, reason): the planners of ``planner`` in turn,
        the first path found; when none finds one, ``invalid_start`` if the robot is
        off its navigation graph, else ``no_path``, with every planner's reason."""
        codes, why = [], ""
        for source in PLANNERS[self.p["planner"]]:
            path, code, reason = self._gbplanner_path(grid) if source == "gbplanner2" else self._navigator_path()
            if path is not None:
                return path, source, "", ""
            codes.append(code)
            why += ("; " if why else "") + reason
        return None, "", "invalid_start" if "invalid_start" in codes else "no_path", why

    def _gbplanner_path(self, grid: Any) -> tuple[np.ndarray | None, str, str]:
        """(path, failure code, reason) on GBPlanner2's global graph."""
        res = gbplanner(self.ctx, self.robot).planner.goto(grid, self.robot.position, self.goal)
        return (res.path, "", "") if res.ok else (None, "no_path", f"global planner: {res.reason}")

    def _navigator_path(self) -> tuple[np.ndarray | None, str, str]:
        """(path, failure code, reason) on the navigation graph of the onboard map."""
        nav = navigator(self.ctx, self.robot)
        force = self.replans > 0
        if nav.from_robot(force=force) is None:
            return None, "invalid_start", "the robot is not on its navigation graph"
        path, _ = nav.path_to_point(self.goal, force=force)
        if path is None:
            return None, "no_path", "no path on the navigation graph of the onboard map"
        return path, "", ""

    def _fail(self, code: str, reason: str) -> Status:
        self.write("goto_failure", code)
        self.feedback_message = reason
        self.event("goto_failed", goto_failure=code, reason=reason,
                   goal=None if self.goal is None else xyz(self.goal))
        return Status.FAILURE


class Backtrack(PathMotion):
    """Backtrack along the robot's own traversed path (``robot.traversed_path``, loops
    cut out): the CERBERUS tree's "Recovery Homing" and its WiFi-safety back-off.

    Goes back ``distance_m`` (null: to the start of the traversed path) or, with
    ``until_key``, until that blackboard key holds a true value (e.g. ``ping_ok``)
    then stops. Where a loop cut turns out blocked, the rest of the way is walked
    exactly as the robot came (one re-plan).

    Reads ``until_key`` (when set). Writes ``backtracked_m`` (distance covered).
    Returns RUNNING while moving; SUCCESS when the condition holds, or (without
    ``until_key``) at the end of the way back; FAILURE when the robot has no
    traversed path to go back along, its way back is blocked, or (with
    ``until_key``) the way back ended with the condition still false.
    """

    PARAMS = {
        "distance_m": Param(float, 10.0, "how far back to go; null: all the way", exclusive_minimum=0, nullable=True),
        "until_key": Param(str, None, "stop as soon as this blackboard key holds a true value", key=True,
                           nullable=True),
        "loop_radius_m": Param(float, 0.75, "the way back skips loops of the trail that come this close",
                               exclusive_minimum=0),
    }
    INPUT_PORTS = {"until": ParamNamedPort(Any, required=False, description="stop once it holds a true value",
                                           key_param="until_key")}
    OUTPUT_PORTS = {"backtracked_m": PortInformation(float, description="distance gone back so far (m)")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.walk: TrailWalk | None = None
        self.start_distance_m = 0.0

    @property
    def until_key(self) -> str | None:
        """The full key of ``until_key``; None when it is null."""
        return self.keys.get("until")

    @property
    def max_replans(self) -> int:
        """One re-plan: the rest of the way exactly as walked, after a blocked loop cut."""
        return 1

    def initialise(self) -> None:
        super().initialise()
        self.walk = None

    def reached(self) -> bool:
        return self.until_key is not None and bool(self.read("until"))

    def arrived(self) -> Status:
        return self._done(Status.SUCCESS, "condition holds")

    def progress(self) -> None:
        self.write("backtracked_m", round(self.robot.distance_m - self.start_distance_m, 2))

    def path_ended(self, status: PathStatus) -> Status | None:
        if status == PathStatus.BLOCKED:
            if self.replans <= self.max_replans:
                # A loop cut did not work out: the rest of the way exactly as walked.
                self.event("backtrack_blocked", reason=self.robot.blocked_reason)
            return None
        if self.until_key is not None:
            return self._done(Status.FAILURE, "the way back ended and the condition still does not hold")
        return self._done(Status.SUCCESS, "back")

    def give_up(self, status: PathStatus, reason: str) -> Status:
        return self._done(Status.FAILURE, f"way back blocked: {reason}")

    def plan(self) -> Status:
        r = self.robot
        exact = self.replans > 0
        if exact and self.walk is not None:
            path = self.walk.exact_rest(r.position, r.distance_m - self.start_distance_m)
        else:
            self.start_distance_m = r.distance_m
            self.walk = TrailWalk.plan(r.traversed_path, self.p["distance_m"], self.p["loop_radius_m"],
                                       trail_jump_check(r))
            path = self.walk.path
        # Drop the points the robot is already at.
        k = 0
        while k < len(path) and np.linalg.norm(path[k] - r.position) < 1e-6:
            k += 1
        path = path[k:]
        if len(path) == 0:
            if exact and self.until_key is None:
                return self._done(Status.SUCCESS, "back")
            return self._done(Status.FAILURE, "no traversed path to go back along")
        if not exact:
            self.write("backtracked_m", 0.0)
        self.drive(path)
        length = path_length(np.vstack([r.position, path]))
        self.feedback_message = f"backtracking {length:.1f} m"
        self.event("backtrack", trigger=not exact, length_m=round(length, 1), to=xyz(path[-1]),
                   until=self.p["until_key"], exact=exact)
        return Status.RUNNING

    def _done(self, status: Status, reason: str) -> Status:
        r = self.robot
        self.feedback_message = reason
        self.event("backtrack_done" if status == Status.SUCCESS else "backtrack_failed", reason=reason,
                   backtracked_m=round(r.distance_m - self.start_distance_m, 2))
        self.walk = None
        return status


__all__ = ["GOTO_FAILURES", "PLANNERS", "Backtrack", "GoTo", "goal_distance"]
