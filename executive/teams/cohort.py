"""COHORT: robots explore with GBPlanner2 and are re-positioned to the team's global
frontiers by a hub on the base station (Kulkarni et al. 2022, section IV-B;
``planners/cohort/``, ``skills/cohort/``, ``docs/cohort.md``).

The strategy declares the COHORT parameters (``team: {strategy: cohort, period_s: 50,
...}``), builds one :class:`~delve.planners.cohort.CohortParams` from them and gives
it to the base station and to every robot as service ``cohort_params``. The mission is
over when every robot's tree has finished (the hub runs until then).
"""
from __future__ import annotations

import math
from dataclasses import fields
from typing import TYPE_CHECKING, Any

import numpy as np

from ...planners.cohort import CohortParams
from ...skills.base import Param, short_repr
from ...skills import cohort as cohort_skills
from ...skills.cohort.hub import HOME_SERVICE, HUB_SERVICE, PARAMS_SERVICE
from ..errors import DelveError
from ..worlds.height_bands import ALL_HEIGHTS, HeightBand
from ..worlds import BASE
from .base import TeamStrategy

if TYPE_CHECKING:
    from ..runner import Mission
    from ..scenario import Scenario

#: The behaviour that makes a base station tree a COHORT hub.
HUB_BEHAVIOUR = "AnswerRepositionRequests"


class Sizes(Param):
    """A list of three sizes (m), each > 0."""

    def problem(self, value: Any) -> str | None:
        problem = super().problem(value)
        if problem is None and any(v <= 0 for v in value):
            return f"must be three sizes > 0 (m), got {short_repr(value)}"
        return problem


_DEFAULTS = {f.name: f.default for f in fields(CohortParams)}

#: The COHORT parameters with their ranges (the paper's values as defaults).
PARAMS: dict[str, Param] = {
    "submap_window_s": Param(float, _DEFAULTS["submap_window_s"], "a submap ends after this much time (s)",
                             exclusive_minimum=0.0, maximum=1e5),
    "submap_displacement_m": Param(float, _DEFAULTS["submap_displacement_m"], "... or when the robot moved this "
                                   "far since it began (m)", exclusive_minimum=0.0, maximum=1e5),
    "resolution_m": Param(float, _DEFAULTS["resolution_m"], "r_C, the common map's resolution at the hub (m)",
                          exclusive_minimum=0.0, maximum=10.0),
    "f_min": Param(int, _DEFAULTS["f_min"], "frontier clusters with fewer points (at r_C) are dropped", minimum=1,
                   maximum=10**7),
    "n_vertices": Param(int, _DEFAULTS["n_vertices"], "N_C, vertices of G_C sampled per submap", minimum=1,
                        maximum=10**5),
    "edge_radius_m": Param(float, _DEFAULTS["edge_radius_m"], "rho_C, the longest edge of G_C (m)",
                           exclusive_minimum=0.0, maximum=1e3),
    "period_s": Param(float, _DEFAULTS["period_s"], "T_C, exploration between two calls to the hub (s)",
                      exclusive_minimum=0.0, maximum=1e5),
    "extra_explore_s": Param(float, _DEFAULTS["extra_explore_s"], "T_C^e, exploration out of reach before the "
                             "robot backtracks, when its box is not explored (s)", minimum=0.0, maximum=1e5),
    "best_share_pct": Param(float, _DEFAULTS["best_share_pct"], "n_C, the share of frontier clusters, largest "
                            "first, a robot may be sent to (%)", exclusive_minimum=0.0, maximum=100.0),
    "box_m": Sizes(list, list(_DEFAULTS["box_m"]), "D, the exploration box around an assigned frontier (x, y, "
                   "z, m); a box given larger than the world is refused", length=3, items=float),
}


def is_cohort_type(t: type) -> bool:
    """Whether node type ``t`` is a COHORT behaviour (robot or hub side)."""
    return t.__module__.startswith(cohort_skills.__name__ + ".")


class Cohort(TeamStrategy):
    """The COHORT plug-in. Report section ``cohort``: submaps sent and received per
    robot, calls (reached or not), assignments, lost-link backtracks and frontier
    clusters at the hub at the end."""

    PARAMS = PARAMS
    NEEDS_BASE_TREE = True

    def __init__(self, **params: Any):
        super().__init__(**params)
        values = dict(self.params)
        values["box_m"] = tuple(float(v) for v in values["box_m"])
        self.cohort = CohortParams(**values)

    @classmethod
    def implied_by(cls, base_tree_types: set[type]) -> bool:
        return any(is_cohort_type(t) for t in base_tree_types)

    @classmethod
    def check_world(cls, scenario: "Scenario", world: Any) -> None:
        """The team keys that only the world can judge: ``box_m`` and ``resolution_m``."""
        team = scenario.doc.get("team")
        if team is not None and "box_m" in team and hasattr(world, "bounds_max"):
            cls._check_box(scenario, world, team)
        if team is not None and "resolution_m" in team and hasattr(world, "voxel_size_m"):
            cls._check_resolution(scenario, world, team)

    @staticmethod
    def _check_resolution(scenario: "Scenario", world: Any, team: Any) -> None:
        """r_C is the nearest multiple of the world's voxel (the common map pools whole
        voxels); one under half a voxel has none: a mistake."""
        v, r_c = float(world.voxel_size_m), float(team["resolution_m"])
        if r_c < 0.5 * v:
            raise DelveError(f"team: resolution_m {r_c:g} m is finer than the world's voxels ({v:g} m): the common "
                             f"map pools whole voxels; give at least {v:g} or leave it out", scenario.path,
                             team.key_line("resolution_m"))

    @staticmethod
    def _check_box(scenario: "Scenario", world: Any, team: Any) -> None:
        """A ``box_m`` given in the scenario that is at least twice the world's size
        along every axis covers the whole world wherever the hub centres it (on a
        frontier inside the world), so it restricts nothing: a mistake (the paper's
        default is not checked). A smaller box, even one larger than the world, keeps a
        robot near a frontier off-centre."""
        extent = np.asarray(world.bounds_max, float) - np.asarray(world.bounds_min, float)
        box = np.asarray(team["box_m"], float)
        if np.all(box >= 2.0 * extent):
            raise DelveError(f"team: box_m {' x '.join(f'{v:g}' for v in box)} m is larger than the world "
                             f"({' x '.join(f'{v:.0f}' for v in extent)} m), at least twice its size along every "
                             "axis: centred anywhere in it the box would restrict nothing; give a smaller box_m "
                             "or leave it out", scenario.path, team.key_line("box_m"))

    def robot_services(self, name: str) -> dict[str, Any]:
        return {PARAMS_SERVICE: self.cohort}

    def base_services(self) -> dict[str, Any]:
        return {PARAMS_SERVICE: self.cohort}

    @classmethod
    def base_tree_problem(cls, base_tree_types: set[type]) -> str | None:
        """A base station tree without the hub: the robots' calls would go unanswered."""
        if any(c.__name__ == HUB_BEHAVIOUR for c in base_tree_types):
            return None
        return f"team strategy 'cohort': the base station tree has no COHORT hub ({HUB_BEHAVIOUR}; " \
               "see trees/cohort_hub.yaml)"

    def start(self, mission: "Mission") -> None:
        """The hub's home is the first robot's (a Dijkstra source on G_C)."""
        mission.agents[BASE].ctx.services[HOME_SERVICE] = next(iter(mission.robots.values())).home.copy()

    def hub(self, mission: "Mission") -> Any:
        """The hub's state on the base station (None before its first submap)."""
        base = mission.agents.get(BASE)
        return None if base is None else base.ctx.services.get(HUB_SERVICE)

    def figures(self, mission: "Mission") -> dict[str, Any]:
        return {"cohort": cohort_figures(mission.state.events, list(mission.robots), self.hub(mission))}

    def draw(self, ax: Any, mission: "Mission", band: HeightBand = ALL_HEIGHTS) -> None:
        """On ``map.png``: the hub's frontier clusters at the end, every box it gave,
        each frontier it gave (with the robot and the time), and the points where
        robots called the hub, with a link and without (those at ``band``'s heights)."""
        hub = self.hub(mission)
        if hub is not None:
            world = mission.world
            lo = np.asarray(getattr(world, "bounds_min", (-np.inf,) * 3), float)[:2]
            hi = np.asarray(getattr(world, "bounds_max", (np.inf,) * 3), float)[:2]
            boxes = targets = 0
            for rec in hub.assignments:
                if rec.result.box_min is None or not band.holds(rec.result.frontier).all():
                    continue
                (x0, y0), (x1, y1) = rec.result.box_min[:2], rec.result.box_max[:2]
                # A box clipped to the world across (the paper's 360 m on our worlds) restricts
                # only height; drawn, it would be the world's frame.
                if not (x0 <= lo[0] and y0 <= lo[1] and x1 >= hi[0] and y1 >= hi[1]):
                    ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "--", lw=0.6, color="purple",
                            label=None if boxes else "COHORT box")
                    boxes += 1
                ax.plot(*rec.result.frontier[:2], "*", ms=8, color="purple",
                        label=None if targets else "COHORT target (robot, time given)")
                ax.annotate(f"{rec.robot} {rec.t_s:.0f} s", rec.result.frontier[:2], xytext=(4, 4 + 7 * (targets % 2)),
                            textcoords="offset points", fontsize=6.5, color="purple",
                            bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 0.5})
                targets += 1
            c = band.within(hub.frontier_centroids)
            if len(c):
                ax.plot(c[:, 0], c[:, 1], "D", ms=4, mfc="none", color="darkorange", label="hub frontiers (end)")
        for reached, colour, label in ((True, "black", "call to the hub (link)"),
                                       (False, "red", "call, hub out of reach")):
            calls = band.within(np.array([e["position"] for e in mission.state.events
                                          if e["event"] == "cohort_call" and bool(e.get("reached")) == reached]))
            if len(calls):   # above the radio-link dots
                ax.plot(calls[:, 0], calls[:, 1], "x", ms=5, mew=1.2, color=colour, label=label, zorder=6)


def cohort_figures(events: list[dict[str, Any]], robots: list[str], hub: Any) -> dict[str, Any]:
    """The report's ``cohort`` section, from the run's events and the hub's state."""
    def count(event: str, robot: str, **match: Any) -> int:
        return sum(1 for e in events if e["event"] == event and e.get("agent") == robot
                   and all(e.get(k) == v for k, v in match.items()))

    received = {r: 0 for r in robots}
    if hub is not None:
        for robot, _ in hub.submaps:
            received[robot] = received.get(robot, 0) + 1
    per_robot = {r: {"submaps_sent": count("cohort_submap_sent", r), "submaps_received": received.get(r, 0),
                     "calls": count("cohort_call", r), "calls_out_of_reach": count("cohort_call", r, reached=False),
                     "calls_unanswered": count("cohort_call_unanswered", r),
                     "assignments": count("cohort_assignment_received", r),
                     "frontiers_received": count("cohort_assignment_received", r)
                     - count("cohort_assignment_received", r, frontier=None),
                     "extra_explorations": count("cohort_extra_exploration", r),
                     "lost_link_backtracks": count("cohort_backtrack", r),
                     "links_regained_on_the_way": count("cohort_link_regained", r)}
                 for r in robots}
    assignments = [] if hub is None else [
        {"robot": a.robot, "t": a.t_s, "request_id": a.request_id, "reason": a.result.reason,
         "frontier": None if a.result.frontier is None else [round(float(v), 2) for v in a.result.frontier],
         "cluster_size": int(a.result.cluster_size),
         "distance_m": None if not math.isfinite(a.result.distance_m) else round(float(a.result.distance_m), 1)}
        for a in hub.assignments]
    return {"robots": per_robot,
            "submaps_at_hub": 0 if hub is None else len(hub.submaps),
            "frontier_clusters_at_end": 0 if hub is None else len(hub.clusters),
            "frontier_points_at_end": 0 if hub is None else int(sum(len(c.voxels) for c in hub.clusters)),
            "assignments": assignments}
