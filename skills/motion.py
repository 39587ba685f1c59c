"""Motion skills: go to a waypoint, and backtrack along the robot's own traversed path
(the CERBERUS behaviour tree's "Recovery Homing" and its WiFi-safety back-off)."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Access, Status
from scipy.spatial import cKDTree

from ..planners.occupancy import OCCUPIED
from .base import Param, Skill
from .gbplanner import gbplanner, onboard_grid
from .navigation import navigator
from .robot import PathStatus, Robot

#: Codes ``GoTo`` writes to ``goto_failure``.
GOTO_FAILURES = ("no_goal", "no_path", "invalid_start", "blocked", "not_reached", "error")


def _xyz(p: np.ndarray) -> list[float]:
    return [round(float(v), 3) for v in p]


def goal_distance(robot: Robot, goal: np.ndarray) -> float:
    """How far ``robot`` is from ``goal`` (a body-centre position). For a legged robot
    up to its body height of vertical offset is free, so a goal given on the floor
    counts as reached from above it."""
    d = np.asarray(goal, float) - robot.position
    mob = robot.mobility
    if not mob.aerial:
        d[2] = max(0.0, abs(d[2]) - mob.body_height_m)
    return float(np.linalg.norm(d))


class GoTo(Skill):
    """Go to a waypoint: the param ``goal`` [x, y, z], or else the blackboard key
    ``goal_key`` (a body-centre position in metres).

    The path comes from the navigation graph of the onboard map (``planner:
    navigator``) or from GBPlanner2's global graph (``planner: gbplanner``, which falls
    back to the navigation graph when it has no path). A blocked path or an arrival
    short of the goal is re-planned, at most ``max_replans`` times.

    Reads ``goal_key`` (when ``goal`` is null). Writes ``goto_failure``: null while
    going and after arrival, else why it failed: ``no_goal`` (none given or not a
    point), ``no_path`` (no valid path, e.g. the goal lies inside mapped rock or out
    of reach), ``invalid_start`` (the robot is not on its own navigation graph),
    ``blocked`` or ``not_reached`` (re-plans used up), ``error`` (a planner raised).
    Returns RUNNING on the way, SUCCESS within ``tolerance_m`` of the goal, FAILURE as
    said (with a ``goto_failed`` event in the log).
    """

    PARAMS = {
        "goal": Param(list, None, "waypoint [x, y, z] (m); null: read goal_key", nullable=True),
        "goal_key": Param(str, "goal", "blackboard key holding the waypoint [x, y, z]", key=True),
        "planner": Param(str, "navigator", "navigation graph of the onboard map, or GBPlanner2's global graph",
                         choices=("navigator", "gbplanner")),
        "tolerance_m": Param(float, 1.0, "distance to the goal that counts as arrived", exclusive_minimum=0),
        "max_replans": Param(int, 3, "re-plans after a blocked path or an arrival short of the goal", minimum=0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.k_goal = self.key(self.p["goal_key"], Access.READ)
        self.k_failure = self.key("goto_failure")
        self.k_length = self.key("goto_path_length_m")
        self.goal: np.ndarray | None = None
        self.moving = False
        self.replans = 0
        self.last_end: np.ndarray | None = None

    def initialise(self) -> None:
        self.goal, self.moving, self.replans, self.last_end = None, False, 0, None
        self.bb.set(self.k_failure, None)

    def update(self) -> Status:
        r = self.robot
        if self.goal is None:
            self.goal = self._read_goal()
            if self.goal is None:
                return self._fail("no_goal", "no goal [x, y, z] given")
        if goal_distance(r, self.goal) <= self.p["tolerance_m"]:
            if self.moving:
                r.stop()
            self.moving = False
            self.event("goto_reached", goal=_xyz(self.goal))
            return Status.SUCCESS
        if self.moving:
            status = r.path_status
            if status == PathStatus.FOLLOWING:
                return Status.RUNNING
            self.moving = False
            self.replans += 1
            if self.replans > self.p["max_replans"]:
                code = "blocked" if status == PathStatus.BLOCKED else "not_reached"
                return self._fail(code, f"{code} after {self.replans - 1} re-plans "
                                        f"({getattr(r, 'blocked_reason', '') or status})")
        return self._plan()

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.moving and self.ctx.robot is not None:
            self.robot.stop()
        self.moving = False

    def _read_goal(self) -> np.ndarray | None:
        value = self.p["goal"] if self.p["goal"] is not None else self.get(self.k_goal)
        try:
            goal = np.asarray(value, float).reshape(-1)
        except (TypeError, ValueError):
            return None
        return goal if goal.shape == (3,) and np.all(np.isfinite(goal)) else None

    def _plan(self) -> Status:
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
        r.follow_path(path)
        self.moving = True
        length = float(np.linalg.norm(np.diff(np.vstack([r.position, path]), axis=0), axis=1).sum())
        self.bb.set(self.k_length, round(length, 2))
        self.feedback_message = f"goal {length:.0f} m away ({source})"
        self.event("goto", goal=_xyz(goal), source=source, path_length_m=round(length, 1))
        return Status.RUNNING

    def _path(self, grid: Any) -> tuple[np.ndarray | None, str, str, str]:
        """(path, source, failure code, reason)."""
        r, goal = self.robot, self.goal
        why_gb = ""
        if self.p["planner"] == "gbplanner":
            res = gbplanner(self.ctx, r).planner.goto(grid, r.position, goal)
            if res.ok:
                return res.path, "gbplanner2", "", ""
            why_gb = f"global planner: {res.reason}; "
        nav = navigator(self.ctx, r)
        force = self.replans > 0
        if nav.from_robot(force=force) is None:
            return None, "", "invalid_start", why_gb + "the robot is not on its navigation graph"
        path, _ = nav.path_to_point(goal, force=force)
        if path is None:
            return None, "", "no_path", why_gb + "no path on the navigation graph of the onboard map"
        return path, "navigator", "", ""

    def _fail(self, code: str, reason: str) -> Status:
        self.bb.set(self.k_failure, code)
        self.feedback_message = reason
        self.event("goto_failed", goto_failure=code, reason=reason,
                   goal=None if self.goal is None else _xyz(self.goal))
        return Status.FAILURE


def max_jump_dz(robot: Robot) -> float:
    """Largest height change a loop cut of the way back may make: a legged robot's
    highest step (an aerial robot's: unlimited)."""
    mob = robot.mobility
    return float("inf") if mob.aerial else float(mob.max_step_m)


def backtrack_path(trail: np.ndarray, distance_m: float | None = None, loop_radius_m: float = 0.75,
                   max_jump_dz_m: float = float("inf")) -> np.ndarray:
    """The way back along ``trail`` ((N, 3) positions, oldest first), newest first,
    with loops cut out, at most ``distance_m`` long (None: all the way to its start).

    A loop is cut where the trail passes within ``loop_radius_m`` (and within
    ``max_jump_dz_m`` of height) of an older point of itself: the way back jumps to
    the oldest such point, so an earlier back-and-forth (a previous backtrack, a dead
    end, a loop) is not walked again.
    """
    trail = np.asarray(trail, float).reshape(-1, 3)
    if len(trail) == 0:
        return trail
    tree = cKDTree(trail)
    out = [trail[-1]]
    i = len(trail) - 1
    while i > 0:
        near = np.asarray(tree.query_ball_point(trail[i], loop_radius_m), dtype=np.int64)
        near = near[np.abs(trail[near, 2] - trail[i, 2]) <= max_jump_dz_m]
        j = int(near.min()) if len(near) else i - 1
        i = j if j < i - 1 else i - 1
        out.append(trail[i])
    path = np.asarray(out)
    if distance_m is None:
        return path
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= distance_m:
        return path
    k = int(np.searchsorted(cum, distance_m, side="right"))  # path[k] is the first beyond
    t = (distance_m - cum[k - 1]) / max(seg[k - 1], 1e-12)
    return np.vstack([path[:k], path[k - 1] + t * (path[k] - path[k - 1])])


class Backtrack(Skill):
    """Backtrack along the robot's own traversed path (``robot.traversed_path``, loops
    cut out): the CERBERUS tree's "Recovery Homing" and its WiFi-safety back-off.

    Goes back ``distance_m`` (null: to the start of the traversed path) or, with
    ``until_key``, until that blackboard key holds a true value (e.g. ``ping_ok``)
    then stops.

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

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.k_until = self.key(self.p["until_key"], Access.READ) if self.p["until_key"] else None
        self.k_done = self.key("backtracked_m")
        self.path: np.ndarray | None = None
        self.start_distance_m = 0.0

    def initialise(self) -> None:
        self.path = None

    def update(self) -> Status:
        r = self.robot
        if self.k_until is not None and self.get(self.k_until):
            return self._done(Status.SUCCESS, "condition holds")
        if self.path is None:
            return self._start()
        self.bb.set(self.k_done, round(r.distance_m - self.start_distance_m, 2))
        status = r.path_status
        if status == PathStatus.FOLLOWING:
            return Status.RUNNING
        if status == PathStatus.BLOCKED:
            return self._done(Status.FAILURE, f"way back blocked: {getattr(r, 'blocked_reason', '')}")
        if self.k_until is not None:
            return self._done(Status.FAILURE, "the way back ended and the condition still does not hold")
        return self._done(Status.SUCCESS, "back")

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.path is not None and self.ctx.robot is not None:
            self.robot.stop()
        self.path = None

    def _start(self) -> Status:
        r = self.robot
        path = backtrack_path(r.traversed_path, self.p["distance_m"], self.p["loop_radius_m"], max_jump_dz(r))
        # Drop the points the robot is already at.
        k = 0
        while k < len(path) and np.linalg.norm(path[k] - r.position) < 1e-6:
            k += 1
        path = path[k:]
        if len(path) == 0:
            self.feedback_message = "no traversed path to go back along"
            self.event("backtrack_failed", reason=self.feedback_message)
            return Status.FAILURE
        self.path = path
        self.start_distance_m = r.distance_m
        self.bb.set(self.k_done, 0.0)
        r.follow_path(path)
        length = float(np.linalg.norm(np.diff(np.vstack([r.position, path]), axis=0), axis=1).sum())
        self.feedback_message = f"backtracking {length:.1f} m"
        self.event("backtrack", trigger=True, length_m=round(length, 1), to=_xyz(path[-1]),
                   until=self.p["until_key"])
        return Status.RUNNING

    def _done(self, status: Status, reason: str) -> Status:
        r = self.robot
        if self.path is not None and r.path_status == PathStatus.FOLLOWING:
            r.stop()
        self.feedback_message = reason
        self.event("backtrack_done" if status == Status.SUCCESS else "backtrack_failed", reason=reason,
                   backtracked_m=round(r.distance_m - self.start_distance_m, 2) if self.path is not None else 0.0)
        self.path = None
        return status


__all__ = ["GOTO_FAILURES", "Backtrack", "GoTo", "backtrack_path", "goal_distance", "max_jump_dz"]
