"""CSIRO 3D frontier exploration: frontiers straight from LiDAR points, shared frontier summaries,
the topometric map and explore-sync (Williams et al.; ``planners/csiro/``, ``skills/csiro/``,
``docs/csiro.md``).

The strategy declares the team's parameters (``team: {strategy: csiro, explore_sync_s: 180,
...}``), builds one :class:`~delve.skills.csiro.CsiroConfig` and gives it to the base station
and every robot as service ``csiro_config``. ``frontier:`` and ``selection:`` override fields of
:class:`~delve.planners.csiro.CsiroFrontierParams` and :class:`~delve.planners.csiro.
CsiroSelectionParams` (the paper's values by default); a value out of range is refused with the
line of its key. The mission is over when every robot's tree has finished.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ...planners.csiro.params import CsiroFrontierParams
from ...planners.csiro.selection_params import CsiroSelectionParams
from ...planners.csiro.topometric import DEFAULT_SPACING_M
from ...skills import csiro as csiro_skills
from ...skills.base import Param, short_repr
from ...skills.csiro import BASE_SERVICE, CONFIG_SERVICE, STATE_SERVICE, CsiroConfig
from ...skills.csiro.state import EXPLORE_SYNC_S
from ..worlds import BASE
from ..worlds.height_bands import ALL_HEIGHTS, HeightBand
from .base import TeamStrategy

if TYPE_CHECKING:
    from ..runner import Mission


@dataclass(frozen=True)
class Overrides(Param):
    """A mapping of field values of the dataclass ``target``, checked by building it."""

    target: type | None = None

    def problem(self, value: Any) -> str | None:
        problem = super().problem(value)
        if problem is not None or self.target is None:
            return problem
        names = [f.name for f in fields(self.target)]
        unknown = sorted(str(k) for k in value if k not in names)
        if unknown:
            return f"unknown parameter {short_repr(unknown[0])} (one of {', '.join(names)})"
        try:
            self.target(**value)
        except (TypeError, ValueError) as err:
            return str(err)
        return None


PARAMS: dict[str, Param] = {
    "explore_sync_s": Param(float, EXPLORE_SYNC_S, "explore-sync: sim time a robot explores out of contact "
                            "before it drives back into radio range (s; the SubT Final's 3 minutes)",
                            exclusive_minimum=0.0, maximum=1e6),
    "topometric_spacing_m": Param(float, DEFAULT_SPACING_M, "spacing of the topometric map's nodes along "
                                  "trajectories (m)", exclusive_minimum=0.0, maximum=1e3),
    "frontier": Overrides(dict, {}, "overrides of the frontier generation's parameters (CsiroFrontierParams: "
                          "d_vox_m, d_max_m, gamma, eta_disc_m, ...)", target=CsiroFrontierParams),
    "selection": Overrides(dict, {}, "overrides of observer planning, sharing and selection (CsiroSelectionParams: "
                           "eta_norm_deg, rho, eta_d_m, rho_fail, ...)", target=CsiroSelectionParams),
}


def is_csiro_type(t: type) -> bool:
    """Whether node type ``t`` is a CSIRO behaviour."""
    return t.__module__.startswith(csiro_skills.__name__ + ".")


class Csiro(TeamStrategy):
    """The CSIRO plug-in. Report section ``csiro``: per robot its syncs, returns to its region,
    goals selected and failed, frontiers and topometric nodes at the end; the frontiers and
    robots that reached the base station."""

    PARAMS = PARAMS
    NEEDS_BASE_TREE = True

    def __init__(self, **params: Any):
        super().__init__(**params)
        p = self.params
        self.config = CsiroConfig(frontier=CsiroFrontierParams(**p["frontier"]),
                                  selection=CsiroSelectionParams(**p["selection"]),
                                  explore_sync_s=float(p["explore_sync_s"]),
                                  topometric_spacing_m=float(p["topometric_spacing_m"]))

    @classmethod
    def implied_by(cls, base_tree_types: set[type]) -> bool:
        return any(is_csiro_type(t) for t in base_tree_types)

    def robot_services(self, name: str) -> dict[str, Any]:
        return {CONFIG_SERVICE: self.config}

    def base_services(self) -> dict[str, Any]:
        return {CONFIG_SERVICE: self.config}

    def start(self, mission: "Mission") -> None:
        """Every agent learns the team's names (whom to share with)."""
        self.config = replace(self.config, team=tuple(mission.robots))
        for agent in mission.agents.values():
            agent.ctx.services[CONFIG_SERVICE] = self.config

    def figures(self, mission: "Mission") -> dict[str, Any]:
        events = mission.state.events

        def count(event: str, robot: str) -> int:
            return sum(1 for e in events if e["event"] == event and e.get("agent") == robot)

        robots = {}
        for name in mission.robots:
            st = mission.agents[name].ctx.services.get(STATE_SERVICE)
            robots[name] = {
                "syncs": count("csiro_sync", name), "regions_reached": count("csiro_region_reached", name),
                "goals_selected": count("csiro_goal_selected", name), "goals_failed": count("csiro_goal_failed", name),
                "frontiers_at_end": 0 if st is None else len(st.frontiers.frontiers),
                "topometric_nodes": 0 if st is None else len(st.topometric.trajectory_nodes())}
        base = self._base(mission)
        return {"csiro": {"robots": robots,
                          "frontiers_at_base": 0 if base is None else len(base.state.summaries),
                          "uplinks": sum(1 for e in events if e["event"] == "csiro_uplink"),
                          "robots_heard_at_base": [] if base is None else sorted(base.last_s)}}

    @staticmethod
    def _base(mission: "Mission") -> Any:
        agent = mission.agents.get(BASE)
        return None if agent is None else agent.ctx.services.get(BASE_SERVICE)

    def draw(self, ax: Any, mission: "Mission", band: HeightBand = ALL_HEIGHTS) -> None:
        """On ``map.png``: the team's topometric map (grey: the trajectory edges; the observer-planning
        edges, which join nodes across junctions, are counted in the legend, not drawn), the frontiers
        current at the end (magenta dots at their means; where a mean lies off the world's free space,
        the mean of a patch of wall or roof, a ground robot's frontier is drawn at its observer and a
        flying robot's not at all), the goals that failed (red crosses, at the goal), where syncs
        happened and the regions robots went back to; those at ``band``'s heights."""
        states = {name: mission.agents[name].ctx.services.get(STATE_SERVICE) for name in mission.robots}
        states = {name: st for name, st in states.items() if st is not None}
        _draw_topometric(ax, [st.topometric for st in states.values()], band)
        _draw_frontiers(ax, mission, states, band)
        events = mission.state.events
        failed = band.within(np.array(failed_goals(events)))
        if len(failed):
            ax.plot(failed[:, 0], failed[:, 1], "x", ms=4, mew=0.8, color="firebrick", zorder=4,
                    label=f"frontier goals that failed ({len(failed)})")
        syncs = band.within(np.array([e["position"] for e in events if e["event"] == "csiro_sync"]))
        if len(syncs):
            ax.plot(syncs[:, 0], syncs[:, 1], "s", ms=6, mfc="none", color="blue", label="explore-sync uplink",
                    zorder=5)
        regions = band.within(np.array([e["region"] for e in events if e["event"] == "csiro_region_reached"]))
        if len(regions):
            ax.plot(regions[:, 0], regions[:, 1], "*", ms=8, color="orange", label="region returned to", zorder=5)


def failed_goals(events: list[dict[str, Any]]) -> list[list[float]]:
    """Where each failed goal was: the goal of the robot's ``csiro_goal_selected`` event before its
    ``csiro_goal_failed``, in the order of the log."""
    goal: dict[str, list[float]] = {}
    out = []
    for e in events:
        if e["event"] == "csiro_goal_selected":
            goal[e["agent"]] = e["goal"]
        elif e["event"] == "csiro_goal_failed" and e.get("agent") in goal:
            out.append(goal[e["agent"]])
    return out


def _draw_topometric(ax: Any, maps: list[Any], band: HeightBand) -> None:
    """The union of the robots' topometric maps: trajectory edges (a robot's node k to k + 1)
    with both ends at ``band``'s heights."""
    edges, positions = set(), {}
    for m in maps:
        for a, b in m.graph.edges:
            if a[0] != "frontier" and b[0] != "frontier":
                edges.add((min(a, b), max(a, b)))
                positions[a], positions[b] = m.position(a), m.position(b)
    here = [e for e in edges if band.holds(np.array([positions[e[0]], positions[e[1]]])).all()]
    along = sorted(e for e in here if e[0][0] == e[1][0] and abs(e[0][1] - e[1][1]) == 1)
    planning = len(here) - len(along)
    if not along:
        return
    segments = np.array([[positions[a][:2], positions[b][:2]] for a, b in along])
    xs = np.column_stack([segments[:, :, 0], np.full(len(segments), np.nan)]).reshape(-1)
    ys = np.column_stack([segments[:, :, 1], np.full(len(segments), np.nan)]).reshape(-1)
    ax.plot(xs, ys, "-", lw=0.6, color="0.45", zorder=1,
            label=f"topometric map ({planning} observer-planning edges not drawn)")


def _draw_frontiers(ax: Any, mission: "Mission", states: dict[str, Any], band: HeightBand) -> None:
    """Every robot's frontiers at the end (see :meth:`Csiro.draw`)."""
    is_free = getattr(mission.world, "is_free", None)
    means, observers, hidden_means = [], [], []
    for name, st in states.items():
        aerial = mission.robots[name].mobility.aerial
        for f in st.frontiers.frontiers:
            if is_free is None or bool(is_free(f.mean[None])[0]):
                means.append(f.mean)
                continue
            summary = None if aerial else st.summaries.get((name, f.id))
            if summary is None:
                hidden_means.append(f.mean)
            else:
                observers.append(summary.observer)
    means, observers = band.within(np.array(means)), band.within(np.array(observers))
    hidden = len(band.within(np.array(hidden_means)))
    if len(means):
        ax.plot(means[:, 0], means[:, 1], "o", ms=3, color="magenta", zorder=4,
                label=f"frontiers at the end, at their means ({len(means)})")
    if len(observers) or hidden:
        ax.plot(observers[:, 0], observers[:, 1], "o", ms=4, mfc="none", color="magenta", zorder=4,
                label=f"frontiers at the end, mean off free space: at their observers ({len(observers)}; "
                      f"{hidden} without one not drawn)")


__all__ = ["PARAMS", "Csiro", "Overrides", "failed_goals"]
