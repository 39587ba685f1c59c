"""GBPlanner2 skills: exploration with the local/global planner (Kulkarni et al. 2022,
section IV-A; CERBERUS SubT Final, section 3.3.1), and the agent's shared planner.

One :class:`~delve.planners.gbplanner2.GBPlanner` per robot lives in the agent's
``ctx.services`` (see :func:`gbplanner`), so that ``Explore``, ``Home``
(``path_source: gbplanner2``), ``GoTo`` (``planner: gbplanner``) and ``Relocate``
share one global graph: the frontiers the local planner leaves behind, the visited
positions, and the way home. What the planner is given of the onboard map is made in
:mod:`delve.planners.gbplanner2.planning_map`.
"""
from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.gbplanner2 import Frontier, GBPlanner, GBPlannerConfig, PlanResult
from ..planners.gbplanner2.link_loss import LinkLoss
from ..planners.gbplanner2.local_planner import LocalPlanResult, ShrinkingLocalPlanner
from ..planners.gbplanner2.planning_map import MapSealer, blocked_spot, mark_blocked_spots, start_pose
from ..planners.geometry import path_length, xyz
from ..planners.occupancy import Grid
from .base import AgentContext, Param, Skill
from .navigation import navigator
from .robot import PathStatus, Robot

#: ``ctx.services`` key of the agent's :class:`PlannerService`.
SERVICE = "gbplanner"
#: The collision box is this much narrower than the robot on each side (half a voxel of
#: the 0.2 m maps the rule was tuned on), so that rounding it out to whole voxels does
#: not make it wider than the robot.
BOX_SIDE_ALLOWANCE_M = 0.1


@dataclass
class PlannerService:
    """The agent's GBPlanner2, its seeded random generator and the overrides it was
    configured with."""

    planner: GBPlanner
    rng: np.random.Generator
    overrides: dict[str, Any] = field(default_factory=dict)
    plans: int = 0
    #: Where the robot's paths were blocked although its map showed a way (body-centre
    #: points just ahead of it): the planner sees rock there from then on.
    blocked_spots: list[np.ndarray] = field(default_factory=list)


def robot_config(robot: Robot, overrides: dict[str, Any] | None = None) -> GBPlannerConfig:
    """GBPlanner2's configuration for ``robot``: the Table I preset of its platform
    (``legged``: ANYmal C, ``aerial``: RMF-Obelix), adapted to its mobility limits,
    then ``overrides`` (GBPlannerConfig field names) on top. The planner reads the
    robot's remaining endurance at each iteration (T_end is the robot's, not the
    configuration's).

    The collision box's horizontal sides are the robot's diameter less
    :data:`BOX_SIDE_ALLOWANCE_M` on each side: the planner rounds the box out to whole
    voxels (a 0.8 m box covers five 0.2 m voxels, 1.0 m), which would make the robot a
    voxel wider than it is and shut it out of squeezes it fits through. The allowance is
    in metres, not voxels: less half a voxel of a 0.4 m map left a box of one voxel,
    half the 0.8 m robot, whose paths hugged the rock until the global graph's edges
    along them were cut."""
    mob = robot.mobility
    preset = robot.platform if robot.platform in ("legged", "aerial") else ("aerial" if mob.aerial else "legged")
    radius = max(mob.radius_m - BOX_SIDE_ALLOWANCE_M, 0.5 * robot.onboard_map.voxel_size_m)
    cfg = GBPlannerConfig.preset(preset).with_robot_limits(
        speed_mps=mob.speed_mps,
        body_height_m=mob.body_height_m,
        radius_m=radius,
        max_inclination_deg=mob.max_inclination_deg,
        max_step_m=mob.max_step_m,
    )
    return cfg.replace(**overrides) if overrides else cfg


def stable_seed(seed: int, agent: str) -> list[int]:
    """Seed material for ``numpy.random.default_rng``: ``seed`` and a stable hash of the
    agent's name (zlib.crc32, the same in every process, unlike ``hash()``)."""
    return [int(seed), zlib.crc32(agent.encode("utf-8"))]


def gbplanner(ctx: AgentContext, robot: Robot, overrides: dict[str, Any] | None = None, seed: int = 0) -> PlannerService:
    """The agent's shared GBPlanner2, created on first use from :func:`robot_config`.

    A later caller with other (non-empty) ``overrides`` reconfigures the planner and
    keeps its global graph; callers without overrides use it as it is.
    """
    svc = ctx.services.get(SERVICE)
    if svc is None:
        planner = GBPlanner(robot_config(robot, overrides), robot.home)
        planner.local_planner = ShrinkingLocalPlanner(planner.config)
        svc = ctx.services[SERVICE] = PlannerService(planner, np.random.default_rng(stable_seed(seed, ctx.name)),
                                                     dict(overrides or {}))
    elif overrides and overrides != svc.overrides:
        cfg = robot_config(robot, overrides)
        svc.planner.config = cfg
        svc.planner.local_planner = ShrinkingLocalPlanner(cfg)
        svc.planner.global_planner.config = cfg
        svc.overrides = dict(overrides)
    return svc


def onboard_grid(ctx: AgentContext, robot: Robot) -> Grid:
    """The robot's onboard map as a planner grid."""
    return navigator(ctx, robot).grid()


def _frontier_of(res: PlanResult, iteration: int) -> Frontier | None:
    """The frontier a repositioning result leads to (its last global vertex)."""
    g = res.global_result
    if res.mode != "reposition" or g is None or not g.vertices or g.target is None:
        return None
    return Frontier(int(g.vertices[-1]), np.asarray(g.target, float).copy(), float(g.gain), iteration)


def parse_bbox(value: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """An exploration bounding box from the blackboard: ``{min: [x, y, z], max: [x, y, z]}``
    or ``[[x, y, z], [x, y, z]]`` (either corner order); None when unset.

    Raises ValueError for anything else."""
    if value is None:
        return None
    if isinstance(value, dict):
        if "min" not in value or "max" not in value:
            raise ValueError(f"exploration box needs 'min' and 'max' corners, got keys {sorted(value)}")
        a, b = value["min"], value["max"]
    elif isinstance(value, (list, tuple, np.ndarray)) and len(value) == 2:
        a, b = value
    else:
        raise ValueError(f"exploration box must be {{min: [x, y, z], max: [x, y, z]}}, got {value!r}")
    a, b = np.asarray(a, float).reshape(-1), np.asarray(b, float).reshape(-1)
    if a.shape != (3,) or b.shape != (3,) or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError(f"exploration box corners must be three finite numbers each, got {value!r}")
    return np.minimum(a, b), np.maximum(a, b)


# Planner parameters a tree may override: the YAML name -> GBPlannerConfig field.
_OVERRIDES = {
    "max_vertices": "num_vertices_max",
    "rho_m": "clustering_radius_m",
    "gamma_h": "hanging_vertex_penalty",
    "sensor_range_m": "sensor_range_m",
    "traverse_length_max_m": "traverse_length_max_m",
    "low_gain_iterations": "low_gain_iterations_max",
}


#: Codes ``Explore`` writes to ``last_plan_reason``.
PLAN_REASONS = ("ok", "reposition", "homing_due", "exploration_complete", "invalid_start", "no_path", "blocked",
                "error")

# Local planner reasons that mean the robot's start pose is invalid on its map.
_INVALID_START = ("start position is invalid", "robot position is outside the map", "robot position is not finite")


def plan_reason(res: PlanResult) -> str:
    """The code of a :class:`PlanResult` (one of :data:`PLAN_REASONS` but ``blocked``
    and ``error``, which come from the robot and from exceptions)."""
    if res.homing is not None and res.homing.required:
        return "homing_due"
    if res.ok:
        return "reposition" if res.mode == "reposition" else "ok"
    if res.exploration_complete:
        return "exploration_complete"
    local = res.local.reason if res.local is not None else res.reason
    if any(local.startswith(s) for s in _INVALID_START):
        return "invalid_start"
    return "no_path"


class Explore(Skill):
    """GBPlanner2 exploration: plan one iteration, follow its path, repeat.

    Each iteration is :meth:`GBPlanner.plan`: the local planner (Algorithm 1) on the
    onboard map; the global planner repositions the robot to the best frontier when
    the local gain stayed low for ``low_gain_iterations`` iterations or the local
    planner found no path; with ``endurance_homing`` it also checks at every iteration
    whether the remaining endurance still covers one more step and the way home.
    The next iteration starts when the robot has arrived. A blocked path is first
    re-planned on the terrain-aware navigation graph of the onboard map, to the
    farthest of its poses that graph reaches (``reroute_poses``); where that is
    blocked too (a step or trench finer than the voxels), the planner sees rock from
    then on (``no_go_radius_m``) and plans again. Halted on the way (a COHORT call, a
    safety block), it leaves the global planner the frontier of a repositioning path,
    or the goal of a local path as a new frontier, so that the direction is not lost.
    The planner's parameters come from the robot's platform (Table I preset: ``legged``
    ANYmal C, ``aerial`` RMF-Obelix) and its mobility limits; the parameters below that
    are not null override them, and ``planner`` overrides any GBPlannerConfig field.
    Randomness comes from a generator seeded with ``seed`` and the agent's name.

    Reads: ``exploration_bbox`` (optional ``{min: [x, y, z], max: [x, y, z]}`` or
    ``[min, max]``): the local graph stays inside it and only frontiers inside it are
    repositioned to; ``link_loss_points`` (optional, written by RememberLinkLoss):
    the gain of vertices whose path passes within ``link_loss_radius_m`` of one is
    multiplied by ``link_loss_gain_factor``, and frontiers beyond one are not
    repositioned to (:mod:`delve.planners.gbplanner2.link_loss`), so that a robot
    backed off from the radio edge explores elsewhere.
    Writes: ``planner_mode`` (explore, reposition, homing, none),
    ``last_plan_reason`` (ok, reposition, homing_due, exploration_complete,
    invalid_start, no_path, blocked, error), ``last_plan_detail`` (the planner's words),
    ``exploration_complete`` (True when nothing is left to explore), ``homing_due``
    (True when the planner decided that the endurance calls for homing).
    Returns: RUNNING while exploring (also after a failed iteration, which is retried
    after ``retry_period_s``); SUCCESS when the exploration is complete or homing is
    due (the tree's ``Home`` then walks the way home); FAILURE at once when the start
    pose is invalid or the planner raises, after ``max_failed_plans`` failed
    iterations in a row, and after ``max_blocked_paths`` paths in a row blocked
    without progress (the reason is logged as ``explore_failed``).
    """

    #: The YAML name says the planner; ``Explore`` is the name it had before.
    TYPE_NAME = "ExploreGBPlanner2"
    ALIASES: ClassVar[dict[str, dict[str, Any]]] = {"Explore": {}}
    PARAMS = {
        "seed": Param(int, 0, "seeds the planner's random generator (with the agent's name)", minimum=0),
        "endurance_homing": Param(bool, True, "the planner checks at each iteration whether to go home"),
        "max_failed_plans": Param(int, 3, "failed iterations in a row before FAILURE", minimum=1),
        "retry_period_s": Param(float, 2.0, "wait before retrying a failed iteration", minimum=0),
        "max_vertices": Param(int, None, "N_V,max, vertices of the local graph (null: preset, 1000 / 500)",
                              minimum=2, nullable=True),
        "rho_m": Param(float, None, "clustering radius of the leaf-only gain (0 disables; null: preset, 0 / 1 m)",
                       minimum=0, nullable=True),
        "gamma_h": Param(float, None, "hanging-vertex gain penalty gamma_H, gain times exp(-gamma_H) (null: 5)",
                         minimum=0, nullable=True),
        "sensor_range_m": Param(float, None, "d_max, sensor range of the gain model (null: preset, 30 m)",
                                exclusive_minimum=0, nullable=True),
        "traverse_length_max_m": Param(float, None, "commanded paths are cut to this length (null: preset, 12 / 10 m)",
                                       exclusive_minimum=0, nullable=True),
        "low_gain_iterations": Param(int, None, "low-gain iterations before repositioning (null: preset, 3)",
                                     minimum=1, nullable=True),
        "planner": Param(dict, {}, "further GBPlannerConfig overrides by field name, e.g. {leaf_only_gain: true}"),
        "seal_map_holes": Param(bool, True, "the planner sees unknown voxels next to mapped rock as rock"),
        "no_go_radius_m": Param(float, 0.3, "where a path was blocked the planner sees rock this wide (0: off)",
                                minimum=0),
        "max_blocked_paths": Param(int, 3, "paths blocked in a row, without progress, before FAILURE", minimum=1),
        "start_shift_m": Param(float, 0.4, "when the robot box touches rock, plan from a clear point this near "
                                           "(0: off)", minimum=0),
        "reroute_poses": Param(int, 5, "a blocked path is re-planned on the navigation graph to the farthest of "
                                       "this many of its poses (0: off)", minimum=0),
        "link_loss_radius_m": Param(float, 3.0, "gain beyond a point where the radio link was lost is discounted: "
                                    "of vertices whose path passes this close to it", exclusive_minimum=0),
        "link_loss_gain_factor": Param(float, 0.0, "the gain beyond a link-loss point is multiplied by this",
                                       minimum=0, maximum=1),
    }
    INPUT_PORTS = {
        "exploration_bbox": PortInformation(list | dict, required=False, description="{min: [x, y, z], max: [x, y, "
                                            "z]} or [min, max] (m): the local graph stays inside it, only frontiers "
                                            "inside it are repositioned to"),
        "link_loss_points": PortInformation(list, required=False, description="[x, y, z] points where the radio link "
                                            "was lost (m): the gain beyond them is discounted, the frontiers beyond "
                                            "them wait"),
    }
    OUTPUT_PORTS = {
        "planner_mode": PortInformation(str, description="explore, reposition, homing or none"),
        "last_plan_reason": PortInformation(str, description="ok, reposition, homing_due, exploration_complete, "
                                            "invalid_start, no_path, blocked or error"),
        "last_plan_detail": PortInformation(str, description="the planner's words"),
        "exploration_complete": PortInformation(bool, description="True when nothing is left to explore"),
        "homing_due": PortInformation(bool, description="True when the planner decided that the endurance calls "
                                      "for homing"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.overrides = {field: self.p[p] for p, field in _OVERRIDES.items() if self.p.get(p) is not None}
        self.overrides.update(self.p["planner"])
        # Unknown names and impossible values fail when the tree is built (file and line).
        GBPlannerConfig.preset("legged").replace(**self.overrides)
        self.following = False
        self.failures = 0
        self.next_plan_s = -float("inf")
        self.path: np.ndarray | None = None
        self.rerouted = False
        self.frontier: Frontier | None = None
        #: The local plan being followed (its goal, ``best_vertex``, is no frontier) and
        #: the global graph's vertex of its start.
        self.local: tuple[LocalPlanResult, int] | None = None
        self.blocked = 0
        self.blocked_at: np.ndarray | None = None

    def initialise(self) -> None:
        self.following, self.failures, self.next_plan_s = False, 0, -float("inf")
        self.path, self.rerouted, self.frontier, self.blocked, self.blocked_at = None, False, None, 0, None
        self.local = None

    def update(self) -> Status:
        r = self.robot
        if self.following:
            status = r.path_status
            if status == PathStatus.FOLLOWING:
                return Status.RUNNING
            self.following = False
            if status == PathStatus.BLOCKED:
                if not self.rerouted and self._reroute():
                    return Status.RUNNING
                if self._path_blocked():
                    return Status.FAILURE
            else:
                self.blocked = 0
        if self.ctx.clock.now_s < self.next_plan_s:
            return Status.RUNNING
        return self._plan()

    def _reroute(self) -> bool:
        """The planner's path is blocked: follow the navigation graph of the onboard map
        (terrain-aware: steps, slopes, standable ground) to the farthest pose of that
        path it reaches, as the paper's legged robots hand the exploration path to
        their navigation planner. False when it reaches none of them."""
        r, path = self.robot, self.path
        if path is None or not self.p["reroute_poses"]:
            return False
        nav = navigator(self.ctx, r)
        plan = nav.from_robot(force=True)
        if plan is None:
            return False
        pos, reason = r.position, r.blocked_reason
        poses = [q for q in path[::-1] if np.linalg.norm((q - pos)[:2]) > 1.0][: self.p["reroute_poses"]]
        for q in poses:
            node = nav.node_near(plan.graph, q)
            if node is None or not np.isfinite(plan.distances[node]) or node == plan.source:
                continue
            route = plan.path_to(node)
            self.follow(route)
            self.following, self.rerouted, self.path = True, True, route
            self.event("explore_rerouted", to=xyz(route[-1]), path_length_m=round(float(plan.distances[node]), 1),
                       reason=reason)
            return True
        return False

    def _restore_frontier(self) -> None:
        """The frontier a blocked repositioning path led to is still unexplored: give it
        back to the global planner (which dropped it when it planned the path)."""
        f, self.frontier = self.frontier, None
        if f is None:
            return
        gp = gbplanner(self.ctx, self.robot).planner.global_planner
        if f.vertex in gp.graph and f.vertex not in gp.frontiers:
            gp.frontiers[f.vertex] = f
            gp.graph.nodes[f.vertex]["kind"] = "frontier"

    def _path_blocked(self) -> bool:
        """Remember where the path was blocked (the planner's map showed a way there);
        True when too many paths in a row were blocked without progress."""
        r = self.robot
        reason = r.blocked_reason
        pos = r.position
        progress = self.blocked_at is None or np.linalg.norm(pos - self.blocked_at) > 2.0 * r.mobility.radius_m
        self.blocked = 1 if progress else self.blocked + 1
        self.blocked_at = pos
        spot = None
        if self.p["no_go_radius_m"] > 0:
            # Far enough ahead that the robot's own box stays clear of it.
            ahead = r.mobility.radius_m + self.p["no_go_radius_m"] + 2.0 * r.onboard_map.voxel_size_m
            spot = blocked_spot(pos, self.path, ahead)
            if spot is not None:
                gbplanner(self.ctx, r).blocked_spots.append(spot)
        self.event("explore_path_blocked", reason=reason, no_go=None if spot is None else xyz(spot),
                   in_a_row=self.blocked)
        self._restore_frontier()
        if self.blocked < self.p["max_blocked_paths"]:
            return False
        detail = f"{self.blocked} paths blocked in a row ({reason})"
        self._write("none", "blocked", detail)
        self.feedback_message = detail
        self.event("explore_failed", reason="blocked", detail=detail)
        self.blocked, self.blocked_at = 0, None
        return True

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.following and self.ctx.robot is not None:
            self.stop_own_motion()
            # Halted on the way to a frontier (a COHORT robot's T_C ends, a safety block
            # takes over): the frontier is still unexplored; without this the global
            # planner, which dropped it when it planned the path, would never go there.
            self._restore_frontier()
            # Likewise the goal of a local path, which was never a frontier (a COHORT
            # robot called back to a link point from a ramp it was climbing).
            if self.local is not None:
                gbplanner(self.ctx, self.robot).planner.global_planner.add_unreached_goal(*self.local)
        self.following, self.local = False, None

    def _plan(self) -> Status:
        r = self.robot
        try:
            svc = gbplanner(self.ctx, r, self.overrides, self.p["seed"])
            bounds = parse_bbox(self.read("exploration_bbox"))
            grid = (navigator(self.ctx, r).updated("sealed map", MapSealer) if self.p["seal_map_holes"]
                    else onboard_grid(self.ctx, r))
            mob = r.mobility
            below = 0.0 if mob.aerial else mob.body_height_m + grid.voxel_size_m
            grid = mark_blocked_spots(grid, svc.blocked_spots, self.p["no_go_radius_m"],
                                      below or self.p["no_go_radius_m"])
            res = self._call(svc, grid, bounds)
        except Exception as err:  # a failed planner call never crashes the tree
            detail = f"{type(err).__name__}: {err}"
            self._write("none", "error", detail)
            self.feedback_message = detail
            self.event("explore_failed", reason="error", detail=detail)
            return Status.FAILURE
        svc.plans += 1
        code = plan_reason(res)
        self._write(res.mode, code, res.reason)
        if code == "homing_due":
            assert res.homing is not None
            self.write("homing_due", True)
            self.feedback_message = "homing due: " + res.reason
            self.event("planner_homing", trigger=True, endurance_s=round(r.endurance_remaining_s, 1),
                       time_home_s=round(res.homing.time_home_s, 1), detail=res.reason)
            return Status.SUCCESS
        if res.ok:
            assert res.path is not None
            self.failures = 0
            self.follow(res.path)
            self.following, self.path, self.rerouted = True, res.path, False
            self.frontier = _frontier_of(res, svc.planner.global_planner.iteration)
            gp = svc.planner.global_planner
            self.local = (res.local, gp.robot_vertex) if res.mode == "explore" and res.local is not None else None
            length = path_length(res.path)
            self.feedback_message = f"{res.mode}: {length:.1f} m, gain {res.gain:.0f} m3"
            self.event("gbplanner_path", mode=res.mode, gain_m3=round(res.gain, 1), path_length_m=round(length, 2),
                       to=xyz(res.path[-1]), frontiers=len(svc.planner.global_planner.frontiers),
                       **({"detail": res.reason} if res.reason else {}))
            return Status.RUNNING
        if code == "exploration_complete":
            self.write("exploration_complete", True)
            self.feedback_message = "exploration complete"
            self.event("exploration_complete", detail=res.reason, iterations=svc.plans)
            return Status.SUCCESS
        self.failures += 1
        self.event("plan_failed", reason=code, detail=res.reason, attempt=self.failures)
        if code == "invalid_start" or self.failures >= self.p["max_failed_plans"]:
            self.feedback_message = f"{code}: {res.reason}"
            self.event("explore_failed", reason=code, detail=res.reason)
            return Status.FAILURE
        self.next_plan_s = self.ctx.clock.now_s + self.p["retry_period_s"]
        self.feedback_message = f"retrying: {res.reason}"
        return Status.RUNNING

    def _call(self, svc: PlannerService, grid: Grid, bounds: tuple[np.ndarray, np.ndarray] | None) -> PlanResult:
        r = self.robot
        planner = svc.planner
        gp = planner.global_planner
        endurance = r.endurance_remaining_s if self.p["endurance_homing"] else None
        hidden = {}
        if bounds is not None:
            # Repositioning considers only the frontiers inside the box (the others are
            # kept for later, when the box is lifted).
            lo, hi = bounds
            hidden = {v: f for v, f in gp.frontiers.items() if not np.all((f.position >= lo) & (f.position <= hi))}
            for v in hidden:
                del gp.frontiers[v]
        try:
            return planner.plan(grid, start_pose(grid, planner.config, r.position, self.p["start_shift_m"]), svc.rng,
                                yaw_rad=r.yaw_rad, endurance_remaining_s=endurance, exploration_bounds=bounds,
                                link_loss=self._link_loss())
        finally:
            gp.frontiers.update(hidden)

    def _link_loss(self) -> LinkLoss | None:
        points = self.read("link_loss_points")
        if not points:
            return None
        return LinkLoss(np.asarray(points, float), self.p["link_loss_radius_m"], self.p["link_loss_gain_factor"])

    def _write(self, mode: str, code: str, detail: str) -> None:
        self.write("planner_mode", mode)
        self.write("last_plan_reason", code)
        self.write("last_plan_detail", detail)
        self.write("exploration_complete", code == "exploration_complete")
        self.write("homing_due", code == "homing_due")


__all__ = ["PLAN_REASONS", "Explore", "PlannerService", "gbplanner", "onboard_grid", "parse_bbox", "plan_reason",
           "robot_config", "stable_seed"]
