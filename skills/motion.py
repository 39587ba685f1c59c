"""Motion skills: go to a waypoint, and backtrack along the robot's own traversed path
(the CERBERUS behaviour tree's "Recovery Homing" and its WiFi-safety back-off)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from py_trees.common import Access, Status
from scipy.spatial import cKDTree

from ..planners.occupancy import FREE, OCCUPIED, Grid
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
                self.stop_own_motion()
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
            self.stop_own_motion()
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
        self.follow(path)
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


def jump_check(robot: Robot) -> Callable[[np.ndarray, np.ndarray], bool]:
    """Whether the robot can go straight from one point of its trail to another, on
    its onboard map: an aerial robot through known free voxels; a legged robot over
    mapped ground, every point of the segment with rock at most ``body_height_m +
    max_step_m`` below the body and the ground's height varying by at most
    ``max_step_m`` (so a loop cut never crosses a trench or a ledge)."""
    m = robot.onboard_map
    grid = Grid(m.occupancy, m.origin, m.voxel_size_m)
    vs = grid.voxel_size_m
    mob = robot.mobility

    def ok(a: np.ndarray, b: np.ndarray) -> bool:
        n = int(np.ceil(np.linalg.norm(b - a) / (0.5 * vs))) + 1
        pts = a + (b - a) * np.linspace(0.0, 1.0, n)[:, None]
        if mob.aerial:
            return bool(np.all(grid.value_at(pts) == FREE))
        if np.any(grid.value_at(pts) == OCCUPIED):
            return False
        depth = np.arange(0.0, mob.body_height_m + mob.max_step_m + vs, vs)
        col = pts[:, None, :] - np.stack([np.zeros_like(depth), np.zeros_like(depth), depth], axis=1)[None]
        rock = grid.value_at(col.reshape(-1, 3)).reshape(n, len(depth)) == OCCUPIED
        if not np.all(rock.any(axis=1)):
            return False
        ground = pts[:, 2] - depth[rock.argmax(axis=1)]
        return bool(ground.max() - ground.min() <= mob.max_step_m + vs)

    return ok


def _cut(path: np.ndarray, distance_m: float | None) -> np.ndarray:
    """The first ``distance_m`` of ``path`` (all of it for None)."""
    if distance_m is None or len(path) < 2:
        return path
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= distance_m:
        return path
    k = int(np.searchsorted(cum, distance_m, side="right"))  # path[k] is the first beyond
    t = (distance_m - cum[k - 1]) / max(seg[k - 1], 1e-12)
    return np.vstack([path[:k], path[k - 1] + t * (path[k] - path[k - 1])])


@dataclass
class TrailWalk:
    """A way back along a snapshot of the traversed path: ``indices`` into ``trail``
    (oldest first), newest first, loops cut out; ``path`` is at most ``distance_m``."""

    trail: np.ndarray
    indices: np.ndarray
    distance_m: float | None = None

    @classmethod
    def plan(cls, trail: np.ndarray, distance_m: float | None = None, loop_radius_m: float = 0.75,
             can_jump: Callable[[np.ndarray, np.ndarray], bool] | None = None) -> TrailWalk:
        """Walk back from the newest point; where the trail passes within
        ``loop_radius_m`` of an older point of itself (and ``can_jump`` allows going
        straight there), jump to the oldest such point, so an earlier back-and-forth
        (a previous backtrack, a dead end, a loop) is not walked again."""
        trail = np.asarray(trail, float).reshape(-1, 3)
        if len(trail) == 0:
            return cls(trail, np.zeros(0, np.int64), distance_m)
        tree = cKDTree(trail) if loop_radius_m > 0 else None
        out = [len(trail) - 1]
        i = len(trail) - 1
        while i > 0:
            nxt = i - 1
            if tree is not None:
                for j in sorted(tree.query_ball_point(trail[i], loop_radius_m)):
                    if j >= i - 1:
                        break
                    if can_jump is None or can_jump(trail[i], trail[j]):
                        nxt = j
                        break
            i = nxt
            out.append(i)
        return cls(trail, np.asarray(out, np.int64), distance_m)

    @property
    def path(self) -> np.ndarray:
        return _cut(self.trail[self.indices], self.distance_m)

    def exact_rest(self, position: np.ndarray, covered_m: float = 0.0) -> np.ndarray:
        """The rest of the way from ``position`` exactly as walked, no loop cut: back
        to the start of the leg of this walk nearest to ``position``, then along every
        older point of the trail (at most ``distance_m - covered_m``)."""
        pts = self.trail[self.indices]
        if len(pts) == 0:
            return pts
        k = 0
        if len(pts) > 1:
            a, b = pts[:-1], pts[1:]
            ab = b - a
            t = np.clip(np.einsum("ij,ij->i", position - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12),
                        0.0, 1.0)
            k = int(np.argmin(np.linalg.norm(a + t[:, None] * ab - position, axis=1)))
        rest = self.trail[self.indices[k]::-1]
        left = None if self.distance_m is None else max(self.distance_m - covered_m, 0.0)
        return _cut(np.vstack([position, rest]), left)[1:]


def backtrack_path(trail: np.ndarray, distance_m: float | None = None, loop_radius_m: float = 0.75,
                   can_jump: Callable[[np.ndarray, np.ndarray], bool] | None = None) -> np.ndarray:
    """The way back along ``trail`` ((N, 3) positions, oldest first), newest first,
    with loops cut out (see :meth:`TrailWalk.plan`), at most ``distance_m`` long (None:
    all the way to its start)."""
    return TrailWalk.plan(trail, distance_m, loop_radius_m, can_jump).path


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
        self.walk: TrailWalk | None = None
        self.start_distance_m = 0.0
        self.exact = False

    def initialise(self) -> None:
        self.path, self.walk, self.exact = None, None, False

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
            reason = getattr(r, "blocked_reason", "")
            if not self.exact:
                # A loop cut did not work out: the rest of the way exactly as walked.
                self.event("backtrack_blocked", reason=reason)
                return self._start(exact=True)
            return self._done(Status.FAILURE, f"way back blocked: {reason}")
        if self.k_until is not None:
            return self._done(Status.FAILURE, "the way back ended and the condition still does not hold")
        return self._done(Status.SUCCESS, "back")

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.path is not None and self.ctx.robot is not None:
            self.stop_own_motion()
        self.path = None

    def _start(self, exact: bool = False) -> Status:
        r = self.robot
        if exact and self.walk is not None:
            self.exact = True
            path = self.walk.exact_rest(r.position, r.distance_m - self.start_distance_m)
        else:
            self.start_distance_m = r.distance_m
            self.walk = TrailWalk.plan(r.traversed_path, self.p["distance_m"], self.p["loop_radius_m"], jump_check(r))
            path = self.walk.path
        # Drop the points the robot is already at.
        k = 0
        while k < len(path) and np.linalg.norm(path[k] - r.position) < 1e-6:
            k += 1
        path = path[k:]
        if len(path) == 0:
            if exact and self.k_until is None:
                return self._done(Status.SUCCESS, "back")
            return self._done(Status.FAILURE, "no traversed path to go back along")
        self.path = path
        if not exact:
            self.bb.set(self.k_done, 0.0)
        self.follow(path)
        length = float(np.linalg.norm(np.diff(np.vstack([r.position, path]), axis=0), axis=1).sum())
        self.feedback_message = f"backtracking {length:.1f} m"
        self.event("backtrack", trigger=not exact, length_m=round(length, 1), to=_xyz(path[-1]),
                   until=self.p["until_key"], exact=exact)
        return Status.RUNNING

    def _done(self, status: Status, reason: str) -> Status:
        r = self.robot
        if self.path is not None and r.path_status == PathStatus.FOLLOWING:
            self.stop_own_motion()
        self.feedback_message = reason
        self.event("backtrack_done" if status == Status.SUCCESS else "backtrack_failed", reason=reason,
                   backtracked_m=round(r.distance_m - self.start_distance_m, 2))
        self.path, self.walk = None, None
        return status


__all__ = ["GOTO_FAILURES", "Backtrack", "GoTo", "TrailWalk", "backtrack_path", "goal_distance", "jump_check"]
