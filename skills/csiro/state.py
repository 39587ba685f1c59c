"""One robot's CSIRO frontier state, shared by the behaviours of its tree (issue 14).

The team strategy gives every agent a :class:`CsiroConfig` as service ``csiro_config``; the
behaviours keep one :class:`CsiroState` per agent in ``ctx.services["csiro"]`` (created on first
use): the point cache and the agent's own frontiers (Algorithm 2), the summaries of every frontier
it knows (its own and those shared with it), the trajectory points of equation 14's set L, the
other robots' current goals, the failed goals and the topometric map.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...planners.csiro.params import CsiroFrontierParams
from ...planners.csiro.point_cache import PointCache
from ...planners.csiro.selection import FailedFrontiers, UavBlacklist, UavMomentum
from ...planners.csiro.selection_params import CsiroSelectionParams
from ...planners.csiro.sequential import SequentialFrontiers
from ...planners.csiro.sharing import FrontierKey, FrontierSummary, TrajectoryPoints
from ...planners.csiro.topometric import DEFAULT_SPACING_M, TopometricMap
from ..base import AgentContext

#: ``ctx.services`` keys: the team's configuration and the agent's state.
CONFIG_SERVICE, STATE_SERVICE = "csiro_config", "csiro"
#: The radio message of :class:`~.sharing.ShareFrontiers`.
SHARE = "csiro_share"
#: Who the base station is on the radio.
BASE = "base"
#: The SubT Final's explore-sync time (Section V): three minutes out of contact.
EXPLORE_SYNC_S = 180.0


@dataclass(frozen=True)
class CsiroConfig:
    """What the team strategy gives every agent: the frontier and selection parameters, the
    explore-sync time (s), the topometric node spacing (m) and the team's robot names."""

    frontier: CsiroFrontierParams = field(default_factory=CsiroFrontierParams)
    selection: CsiroSelectionParams = field(default_factory=CsiroSelectionParams)
    explore_sync_s: float = EXPLORE_SYNC_S
    topometric_spacing_m: float = DEFAULT_SPACING_M
    team: tuple[str, ...] = ()


def csiro_config(ctx: AgentContext) -> CsiroConfig:
    """The team's configuration (the paper's values when no strategy gave one, e.g. in a test)."""
    return ctx.services.get(CONFIG_SERVICE) or CsiroConfig()


@dataclass
class CsiroState:
    """One agent's CSIRO state (see the module's docstring). ``summaries`` maps every known
    frontier's key to its summary; ``places`` each other robot's trajectory points; ``goals``
    each other robot's current goal (key, observer); ``goal`` this robot's."""

    frontier_params: CsiroFrontierParams
    selection: CsiroSelectionParams
    cache: PointCache
    frontiers: SequentialFrontiers
    topometric: TopometricMap
    trajectory: TrajectoryPoints
    failed: FailedFrontiers = field(default_factory=FailedFrontiers)
    summaries: dict[FrontierKey, FrontierSummary] = field(default_factory=dict)
    places: dict[str, np.ndarray] = field(default_factory=dict)
    goals: dict[str, tuple[FrontierKey, np.ndarray]] = field(default_factory=dict)
    goal: FrontierKey | None = None
    #: A frontier update is due where the robot stands (it reached its goal to look from there).
    look_due: bool = False
    #: The UAV's momentum (equation 16) and the frontiers it blacklisted (each version blacklisted).
    momentum: UavMomentum | None = None
    blacklist: UavBlacklist = field(default_factory=UavBlacklist)
    #: Frontier ids logged as out of the UAV's reach (``csiro_frontier_out_of_reach``, once each),
    #: and per id the version of the frontier found out of reach and the navigation graph it was
    #: found on (no search again while both are the same).
    out_of_reach_logged: set[int] = field(default_factory=set)
    out_of_reach: dict[int, tuple[Any, Any]] = field(default_factory=dict)
    #: Explore-sync: when and where the link to the base station was last seen, and where the
    #: last sync began (the region to return to).
    contact_s: float = 0.0
    contact: np.ndarray | None = None
    region: np.ndarray | None = None

    def own_summaries(self, owner: str) -> list[FrontierSummary]:
        """The summaries of ``owner``'s frontiers, by id."""
        return [self.summaries[k] for k in sorted(self.summaries) if k[0] == owner]

    def places_set(self, own: str) -> np.ndarray:
        """Equation 14's L: this robot's and the others' trajectory points, the others'
        current goals and the failed goals, (M, 3)."""
        sets = [self.trajectory.points()] + [self.places[r] for r in sorted(self.places) if r != own]
        sets += [self.goals[r][1] for r in sorted(self.goals)] + [self.failed.goals]
        return np.concatenate([np.asarray(s, float).reshape(-1, 3) for s in sets])


def csiro_state(ctx: AgentContext, view_up_deg: float | None = None) -> CsiroState:
    """The agent's :class:`CsiroState`, created on first use; the sensor's elevations of the
    frontier parameters are set to +-``view_up_deg`` (the robot's LiDAR) when given, and a flying
    robot's blind cones hold frontiers (``blind_frontiers``: it can rise or sink to see them)."""
    state = ctx.services.get(STATE_SERVICE)
    if state is None:
        cfg = csiro_config(ctx)
        fp = cfg.frontier
        if view_up_deg is not None and 0.0 < view_up_deg <= 90.0:
            fp = replace(fp, elevation_min_deg=-view_up_deg, elevation_max_deg=view_up_deg)
        robot = getattr(ctx, "robot", None)
        if robot is not None and robot.mobility.aerial:
            fp = replace(fp, blind_frontiers=True)
        state = ctx.services[STATE_SERVICE] = CsiroState(
            frontier_params=fp, selection=cfg.selection, cache=PointCache(fp.d_vox_m),
            frontiers=SequentialFrontiers(fp), topometric=TopometricMap(cfg.topometric_spacing_m),
            trajectory=TrajectoryPoints(cfg.selection))
    return state


__all__ = ["BASE", "CONFIG_SERVICE", "EXPLORE_SYNC_S", "SHARE", "STATE_SERVICE", "CsiroConfig", "CsiroState",
           "csiro_config", "csiro_state"]
