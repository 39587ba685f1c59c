"""GBPlanner2 as one object per robot: the local planner inside the global one.

Each :meth:`GBPlanner.plan` call is one planning iteration of the paper's bifurcated
architecture (Figure 2 of the GBPlanner2 paper; Figure 10 of the CERBERUS paper):

1. the robot's position joins the global graph;
2. with a remaining endurance given, homing is checked first: when the endurance
   barely covers the way home plus the reserve, the path home is returned;
3. the local planner (Algorithm 1) runs; its path and frontiers grow the global graph;
4. when the local gain stayed low for ``low_gain_iterations_max`` iterations, or the
   local planner found no path, the robot is repositioned to the best frontier; with
   no frontier left either, the exploration is complete (no path,
   ``exploration_complete``: the caller decides, e.g. to go home);
5. otherwise the local path is returned.

:meth:`GBPlanner.home` and :meth:`GBPlanner.goto` give the paths the supervisor or a
behaviour tree asks for (homing, a goal point). A call that cannot give a path returns
a :class:`PlanResult` with ``path=None`` and a reason.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..occupancy import Grid
from .config import GBPlannerConfig
from .global_planner import GlobalPlanner, GlobalPlanResult, HomingCheck
from .link_loss import LinkLoss
from .local_planner import LocalPlanner, LocalPlanResult

#: Modes of a :class:`PlanResult`.
MODES = ("explore", "reposition", "homing", "goal", "none")


@dataclass
class PlanResult:
    """The path to command and why.

    ``mode``: ``explore`` (local path), ``reposition`` (to a frontier), ``homing``,
    ``goal``, or ``none`` (no path; ``reason`` says why; ``exploration_complete`` when
    neither the local graph nor any frontier has gain left).
    """

    path: np.ndarray | None
    mode: str
    gain: float = 0.0
    reason: str = ""
    local: LocalPlanResult | None = None
    global_result: GlobalPlanResult | None = None
    homing: HomingCheck | None = None
    exploration_complete: bool = False

    @property
    def ok(self) -> bool:
        return self.path is not None


class GBPlanner:
    """GBPlanner2 for one robot that started at ``home``."""

    def __init__(self, config: GBPlannerConfig, home: np.ndarray) -> None:
        self.config = config
        self.local_planner = LocalPlanner(config)
        self.global_planner = GlobalPlanner(config, home)
        #: Heading of the last commanded path (the direction penalty's reference).
        self.exploring_direction_rad: float | None = None

    def plan(
        self,
        grid: Grid,
        position: np.ndarray,
        rng: np.random.Generator,
        *,
        yaw_rad: float = 0.0,
        endurance_remaining_s: float | None = None,
        exploration_bounds: tuple[np.ndarray, np.ndarray] | None = None,
        link_loss: LinkLoss | None = None,
    ) -> PlanResult:
        """One planning iteration (see the module docstring). With ``link_loss``, the
        local gain beyond the points where the radio link was lost is discounted and
        the frontiers beyond them (on the global graph, seen from home) are left out
        of this iteration's repositioning (they are kept for later)."""
        position = np.asarray(position, float).reshape(3)
        gp = self.global_planner
        if not np.all(np.isfinite(position)):
            return PlanResult(None, "none", reason="robot position is not finite")
        gp.record_position(position, grid)
        check = None
        if endurance_remaining_s is not None:
            check = gp.homing_check(grid, position, float(endurance_remaining_s))
            if check.required:
                home = check.home_path if check.home_path is not None else gp.plan_home(grid, position)
                reason = home.reason if not home.ok else "endurance barely covers the way home"
                return PlanResult(home.path, "homing" if home.ok else "none", 0.0, reason,
                                  global_result=home, homing=check)
        if self.exploring_direction_rad is None:
            direction = None
        else:
            direction = self.exploring_direction_rad
        local = self.local_planner.plan(
            grid, position, rng, yaw_rad=yaw_rad, exploring_direction_rad=direction,
            exploration_bounds=exploration_bounds, link_loss=link_loss,
        )
        gp.add_local_result(local, grid)
        if gp.reposition_due or local.path is None:
            hidden = {}
            if link_loss is not None and len(link_loss.points):
                beyond = link_loss.beyond_on_graph(gp.graph, gp.home_vertex, list(gp.frontiers), gp.position_of)
                hidden = {v: gp.frontiers.pop(v) for v in sorted(beyond)}
            try:
                rep = gp.plan_reposition(grid, position, endurance_remaining_s)
            finally:
                gp.frontiers.update(hidden)
            if rep.ok:
                self.exploring_direction_rad = _heading(rep.path)
                return PlanResult(rep.path, "reposition", rep.gain, "local gain stayed low" if local.ok
                                  else f"local planner: {local.reason}", local, rep, check)
            # No frontier left (but beyond a link loss) and the local gain low: the
            # exploration is complete.
            complete = not set(gp.frontiers).difference(hidden) and local.graph is not None and local.graph.num_vertices > 1
            if local.path is None or (complete and gp.reposition_due):
                what = "exploration complete: " if complete else ""
                reason = f"{what}local planner: {local.reason or 'low gain'}; global planner: {rep.reason}"
                return PlanResult(None, "none", 0.0, reason, local, rep, check, exploration_complete=complete)
        self.exploring_direction_rad = local.direction_rad
        return PlanResult(local.path, "explore", local.gain, "", local, None, check)

    def home(self, grid: Grid, position: np.ndarray) -> PlanResult:
        """The path home along the global graph."""
        res = self.global_planner.plan_home(grid, position)
        return PlanResult(res.path, "homing" if res.ok else "none", 0.0, res.reason, global_result=res)

    def goto(self, grid: Grid, position: np.ndarray, goal: np.ndarray) -> PlanResult:
        """A path to a goal point given by the supervisor or the tree."""
        res = self.global_planner.plan_to_goal(grid, position, goal)
        if res.ok:
            self.exploring_direction_rad = _heading(res.path)
        return PlanResult(res.path, "goal" if res.ok else "none", 0.0, res.reason, global_result=res)


def _heading(path: np.ndarray | None) -> float | None:
    if path is None or len(path) < 2:
        return None
    d = path[-1] - path[-2]
    if math.hypot(d[0], d[1]) < 1e-6:
        return None
    return math.atan2(d[1], d[0])
