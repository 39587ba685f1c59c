"""Going to the selected frontier, with the failure rule of Algorithm 3 (no 1 m of progress in
15 s) and, for a distant frontier, the topometric map's A* path first (Section IV-C)."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation
from scipy.spatial import cKDTree

from ...planners.csiro.selection import GoalProgress, uav_frontier_complete
from ...planners.csiro.topometric import frontier_node
from ...planners.geometry import path_length, xyz
from ..base import Param
from ..motion import GoTo, goal_distance
from ..navigation import navigator
from .state import CsiroState, csiro_state


def reachable_near(ctx: Any, robot: Any, point: np.ndarray,
                   fresh: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
    """The path to the node of the robot's navigation graph that it can reach and that lies
    nearest ``point``, and that node's position; None when the robot is off its graph. With
    ``fresh`` the graph is rebuilt first if the map changed since it was built."""
    nav = navigator(ctx, robot)
    plan = nav.from_robot(force=fresh and nav.map_changed())
    reach = _reachable(plan)
    if not len(reach):
        return None
    node = int(reach[np.argmin(np.linalg.norm(plan.graph.positions[reach] - point, axis=1))])
    return plan.path_to(node), plan.graph.positions[node].copy()


def way_lengths(ctx: Any, robot: Any, points: np.ndarray) -> np.ndarray | None:
    """(K,) the length of the way to each of ``points`` (K, 3): along the robot's navigation graph
    to the node it can reach that lies nearest the point, then straight on; None when the robot
    is off its graph."""
    plan = navigator(ctx, robot).from_robot()
    reach = _reachable(plan)
    if not len(reach):
        return None
    gap, k = cKDTree(plan.graph.positions[reach]).query(np.reshape(points, (-1, 3)))
    return plan.distances[reach[k]] + gap


def _reachable(plan: Any) -> np.ndarray:
    """The nodes a plan's shortest-path tree reaches (none without a plan)."""
    return np.zeros(0, dtype=int) if plan is None else np.flatnonzero(np.isfinite(plan.distances))


class FollowFrontierGoal(GoTo):
    """Go to the selected frontier's ``goal`` (written by a Select behaviour) and stay until the
    frontier changes.

    A ground robot's first path is the topometric map's A* path to the frontier (other robots'
    trajectories cross space its own map lacks), re-planned like ``GoTo`` when blocked. Progress
    is watched as Algorithm 3 says: when the closest approach to the goal (the distance still to go
    along the robot's path, whose way to another drift first leads away) improves by less than
    ``progress_m`` in ``progress_window_s`` (1 m, 15 s; counted afresh after an interruption such as
    explore-sync), or the way cannot be planned (on the
    navigation graph rebuilt from the current map), or the robot's own frontier is still
    unchanged ``dwell_s`` after it reached the goal, the goal has failed: a ground robot's
    frontier gets the penalty rho_fail until it is updated and its observer joins the failed
    goals of L; a flying robot blacklists it.

    Reads ``goal`` and ``csiro_goal``. Returns SUCCESS when the frontier is gone (explored), its
    observer moved more than ``reselect_m`` from the goal, it changed while the robot stood at
    the goal (select again), a teammate's frontier's observer was reached (only its owner can
    update it; the place joins the robot's trajectory points, which discount it, equation 14),
    or (flying robot) it came within eta_blacklist of its centre and the frontiers were updated
    from within that radius (``look_due`` asks for that update: the paper's rule alone ends the
    goal before a sweep from there, at 1 Hz, could show what lies beyond) and it is still there
    (complete, and blacklisted; a goal within that radius of the centre is flown to until then,
    not ``tolerance_m`` short);
    RUNNING on the way and while standing at the goal; FAILURE when the goal failed
    (``csiro_goal_failed`` in the log).
    """

    PARAMS = {**{k: v for k, v in GoTo.PARAMS.items() if k != "goal"},
              "reselect_m": Param(float, 2.0, "select again when the frontier's observer moved this far",
                                  exclusive_minimum=0),
              "dwell_s": Param(float, 5.0, "at the goal this long with the frontier unchanged: the goal has failed",
                               minimum=0)}
    INPUT_PORTS = {**GoTo.INPUT_PORTS,
                   "csiro_goal": PortInformation(list, required=False, description="[owner, id] the frontier")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, goal=None, **params)
        self.key: tuple[str, int] | None = None
        self.watch: GoalProgress | None = None
        self.watch_key: tuple[str, int] | None = None
        self.arrived_s: float | None = None
        self.arrived_version: Any = None  # on arrival: the summary's updated_s (own Frontier, flying robot)

    def initialise(self) -> None:
        super().initialise()
        self.arrived_s = self.arrived_version = None
        key = self.read("csiro_goal")
        self.key = None if key is None else (str(key[0]), int(key[1]))
        st = csiro_state(self.ctx)
        if self.watch is None or self.watch_key != self.key:  # the same frontier again: same watch
            self.watch = GoalProgress(np.zeros(3), st.selection)
            self.watch_key = self.key

    def update(self) -> Status:
        if self.key is None:
            self.feedback_message = "no frontier selected"
            return Status.FAILURE
        st, r = csiro_state(self.ctx), self.robot
        if self.goal is None:
            self.goal = self._read_goal()
            if self.goal is not None:
                self.watch.goal = self.goal
        done = self._frontier_done(st)
        if done:
            return self._done(done)
        if self._awaiting_look(st):
            st.look_due = True
            self.feedback_message = "within eta_blacklist of the frontier's centre, waiting for a sweep from here"
            return Status.RUNNING
        to_go = self._to_go()
        if to_go is not None and self.watch.update(self.ctx.clock.now_s, r.position, to_go):
            return self._failed(st, f"closest approach improved less than {self.watch.progress_m:g} m in "
                                    f"{self.watch.window_s:g} s")
        if self.goal is not None and self.reached():
            return self._at_goal(st)
        self.arrived_s = None
        status = super().update()
        if status == Status.FAILURE:
            return self._failed(st, self.feedback_message)
        return Status.RUNNING if status == Status.SUCCESS else status

    def reached(self) -> bool:
        """``GoTo``'s arrival within ``tolerance_m`` of the goal; a flying robot whose goal lies within
        eta_blacklist of its frontier's centre flies on until the frontier is complete (at the goal
        at the latest) rather than standing up to ``tolerance_m`` short of it, out of that radius."""
        if not super().reached():
            return False
        frontier = self._own_frontier() if self.robot.mobility.aerial else None
        return frontier is None or not uav_frontier_complete(frontier, self.goal, csiro_state(self.ctx).selection)

    def _to_go(self) -> float | None:
        """The distance still to go for the progress rule: along the path while the robot follows
        this behaviour's path, the straight line once it is at the goal; None before the first
        path and between re-plans (the straight line would count a way through rock)."""
        r = self.robot
        if self.goal is None:
            return None
        rest = r.remaining_path if self.moving else np.zeros((0, 3))
        if len(rest):
            return path_length(np.vstack([r.position, rest, self.goal]))
        return goal_distance(r, self.goal) if self.reached() else None

    def terminate(self, new_status: Status) -> None:
        """Interrupted while running (explore-sync took over): the progress watch starts afresh
        when the frontier is selected again, as the time away was no lack of progress."""
        if new_status == Status.INVALID and self.status == Status.RUNNING:
            self.watch = None
        super().terminate(new_status)

    def _at_goal(self, st: CsiroState) -> Status:
        """Standing at the goal: done when it is a teammate's frontier or the frontier changed,
        on to a nearer place (flying robot, on arrival), failed after ``dwell_s`` unchanged, else
        RUNNING."""
        self.stop_own_motion()
        self.moving = False
        now, r = self.ctx.clock.now_s, self.robot
        if not r.mobility.aerial and self.key[0] != self.ctx.name:
            st.trajectory.visit(r.position)
            return self._done("reached a teammate's frontier")
        if r.mobility.aerial:     # its own frontier, replaced by a new object when it changes
            version: Any = self._own_frontier()
        else:
            summary = st.summaries.get(self.key)
            version = None if summary is None else summary.updated_s
        if self.arrived_s is None:
            if r.mobility.aerial and self._nearer_place(st):
                status = self.plan()
                return self._failed(st, self.feedback_message) if status == Status.FAILURE else Status.RUNNING
            self.arrived_s, self.arrived_version = now, version
            st.look_due = True
        if (version is not self.arrived_version) if r.mobility.aerial else (version != self.arrived_version):
            return self._done("changed")
        if now - self.arrived_s >= self.p["dwell_s"]:
            return self._failed(st, f"still a frontier {self.p['dwell_s']:g} s after reaching its observer")
        self.feedback_message = "at the goal, waiting for the frontier to change"
        return Status.RUNNING

    def _nearer_place(self, st: CsiroState) -> bool:
        """A flying robot at its goal short of the frontier's centre: whether the navigation
        graph, rebuilt from the current map, reaches at least ``progress_m`` nearer the centre
        (the goal was chosen on a graph up to ``rebuild_period_s`` old); if so it is the new
        goal, watched afresh."""
        frontier = next((f for f in st.frontiers.frontiers if f.id == self.key[1]), None)
        near = None if frontier is None else reachable_near(self.ctx, self.robot, frontier.mean, fresh=True)
        if near is None or (np.linalg.norm(near[1] - frontier.mean) + st.selection.progress_m
                            > np.linalg.norm(self.robot.position - frontier.mean)):
            return False
        self.goal, self.last_end = near[1], None
        self.watch = GoalProgress(self.goal, st.selection)
        return True

    def _own_frontier(self) -> Any:
        """The robot's own frontier of the goal's key, None when it is gone (or a teammate's)."""
        if self.key is None or self.key[0] != self.ctx.name:
            return None
        return next((f for f in csiro_state(self.ctx).frontiers.frontiers if f.id == self.key[1]), None)

    def _done(self, why: str) -> Status:
        self.stop_own_motion()
        self.moving = False
        self.event("csiro_goal_done", key=list(self.key), why=why)
        return Status.SUCCESS

    def _frontier_done(self, st: CsiroState) -> str:
        """Why the goal is over ('' while it is not)."""
        key, r = self.key, self.robot
        if r.mobility.aerial:
            frontier = self._own_frontier()
            if frontier is None:
                return "explored"
            seen_from = st.frontiers.last_viewpoint
            looked = seen_from is not None and uav_frontier_complete(frontier, seen_from, st.selection)
            if not (looked and uav_frontier_complete(frontier, r.position, st.selection)):
                return ""
            st.blacklist.add(frontier)
            return "complete"
        summary = st.summaries.get(key)
        if summary is None:
            return "explored"
        if self.goal is not None and np.linalg.norm(summary.observer[:2] - self.goal[:2]) > self.p["reselect_m"]:
            return "observer moved"
        return ""

    def _awaiting_look(self, st: CsiroState) -> bool:
        """A flying robot within eta_blacklist of its frontier's centre (which ``_frontier_done``
        did not find complete: no update of its frontiers from within that radius yet)."""
        frontier = self._own_frontier() if self.robot.mobility.aerial else None
        return frontier is not None and uav_frontier_complete(frontier, self.robot.position, st.selection)

    def _failed(self, st: CsiroState, why: str) -> Status:
        self.stop_own_motion()
        self.moving = False
        key = self.key
        if self.robot.mobility.aerial:
            if (frontier := self._own_frontier()) is not None:
                st.blacklist.add(frontier)
        elif key in st.summaries:
            st.failed.mark(st.summaries[key])
        self.watch = None
        st.goal = None
        self.feedback_message = why
        self.event("csiro_goal_failed", key=list(key), reason=why, position=xyz(self.robot.position, 2))
        return Status.FAILURE

    def _path(self, grid: Any) -> tuple[np.ndarray | None, str, str, str]:
        """For a goal beyond d_max (a distant frontier, Section IV-C) the topometric map's path
        first (ground robot); else, and then, ``GoTo``'s on the navigation graph (rebuilt from the
        current map when the goal lies beyond the graph it has); where that finds none, the
        topometric path to a nearby goal, else the way to the reachable place nearest the goal
        when it brings the robot nearer by ``progress_m`` at least."""
        st, r = csiro_state(self.ctx), self.robot
        first = self.replans == 0 and not r.mobility.aerial
        far = float(np.linalg.norm(self.goal - r.position)) > st.frontier_params.d_max_m
        if first and far and (path := self._topometric(st)) is not None:
            return path, "topometric", "", ""
        path, source, code, why = super()._path(grid)
        nav = navigator(self.ctx, r)
        if path is None and code == "no_path" and self.replans == 0 and nav.map_changed():
            nav.graph(force=True)   # the graph may be rebuild_period_s old: the goal lies beyond it
            path, source, code, why = super()._path(grid)
        if path is None and code == "no_path" and first and not far:
            topometric = self._topometric(st)
            if topometric is not None:
                return topometric, "topometric", "", ""
        if path is None and code == "no_path":
            near = reachable_near(self.ctx, r, self.goal)
            if near is not None and (np.linalg.norm(near[1] - self.goal) + st.selection.progress_m
                                     <= np.linalg.norm(r.position - self.goal)):
                return near[0], "navigator, nearest reachable", "", ""
        return path, source, code, why

    def _topometric(self, st: CsiroState) -> np.ndarray | None:
        """The waypoints of the topometric map's A* path to the frontier (GoTo appends the goal),
        or None when it has none beyond the robot's and the frontier's nodes."""
        path = st.topometric.path(self.robot.position, frontier_node(self.key))
        return path.points[1:-1] if path is not None and len(path.points) > 2 else None


__all__ = ["FollowFrontierGoal"]
