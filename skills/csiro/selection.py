"""Frontier selection (Section IV): the ground robot's reward per unit distance over every
frontier the team shared (equation 15, Algorithm 3), the flying robot's own frontiers by
equation 16."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.csiro.frontier_types import Frontier
from ...planners.csiro.selection import rank_uav_frontiers, select_ugv_frontier, uav_frontier_complete
from ...planners.csiro.topometric import frontier_node
from ...planners.geometry import xyz
from ...planners.occupancy import Grid
from ...planners.visibility import line_of_sight
from ..base import Param, Skill
from ..navigation import navigator
from .follow import reachable_near, way_lengths
from .frontiers import body_lift
from .state import csiro_state

_OUTPUTS = {
    "goal": PortInformation(list | None, description="[x, y, z] where to go: the frontier's observer (ground "
                            "robot, body height added) or the reachable place nearest its centre (flying robot)"),
    "csiro_goal": PortInformation(list | None, description="[owner, id] the frontier selected; null: none"),
}


class _Select(Skill):
    """Shared: wait up to ``wait_s`` for a frontier to select, then fail."""

    ABSTRACT = True
    PARAMS = {"wait_s": Param(float, 10.0, "sim time to wait for a frontier to select before exploration counts "
                              "as done", minimum=0)}
    OUTPUT_PORTS = _OUTPUTS

    def initialise(self) -> None:
        self.since_s = self.ctx.clock.now_s

    def none_left(self) -> Status:
        """RUNNING while waiting for a frontier, then FAILURE (logs ``csiro_no_frontier``)."""
        csiro_state(self.ctx).goal = None
        self.write("csiro_goal", None)
        if self.ctx.clock.now_s - self.since_s < self.p["wait_s"]:
            self.feedback_message = "waiting for a frontier"
            return Status.RUNNING
        self.feedback_message = "no frontier left"
        self.event("csiro_no_frontier", position=xyz(self.robot.position, 2))
        return Status.FAILURE

    def chosen(self, key: tuple[str, int], goal: np.ndarray, **why: Any) -> Status:
        st = csiro_state(self.ctx)
        st.goal = key
        self.write("csiro_goal", [key[0], key[1]])
        self.write("goal", xyz(goal, 3))
        self.feedback_message = f"frontier {key[0]}/{key[1]}"
        self.event("csiro_goal_selected", key=[key[0], key[1]], goal=xyz(goal, 2), **why)
        return Status.SUCCESS


class SelectUgvFrontier(_Select):
    """Algorithm 3 for a ground robot: of every frontier summary it knows (its own and the
    team's), the one of highest discounted reward per unit of topometric distance to its
    observer (equations 14-15), skipping those other robots hold and penalising failed ones.

    Writes ``goal`` (the observer, body height added) and ``csiro_goal``. Returns SUCCESS with a
    goal; RUNNING while none is selectable, up to ``wait_s``; then FAILURE (exploration over).
    """

    def update(self) -> Status:
        r, name = self.robot, self.ctx.name
        st = csiro_state(self.ctx, r.view_up_deg)
        keys = sorted(st.summaries)
        summaries = [st.summaries[k] for k in keys]
        distances = st.topometric.distances(r.position, [frontier_node(k) for k in keys])
        held = [g[0] for other, g in sorted(st.goals.items()) if other != name]
        choice = select_ugv_frontier(summaries, distances, st.places_set(name), st.selection,
                                     held_by_others=held, failed=st.failed) if keys else None
        if choice is None:
            return self.none_left()
        goal = st.summaries[choice.key].observer + body_lift(r)
        return self.chosen(choice.key, goal, utility=round(choice.utility, 3), reward=round(choice.reward, 2),
                           distance_m=round(choice.distance_m, 1))


class SelectUavFrontier(_Select):
    """Equation 16 for a flying robot, over its own frontiers: size, z-weighted distance (or the
    way there along its navigation graph where that is longer) and momentum, none smaller than
    the size limit, blacklisted or complete. Its goal is the place
    of the navigation graph it can reach that lies nearest the frontier's centre; a frontier whose
    centre no such place comes within eta_blacklist of (a patch in rock or beyond a wall: the UAV
    could never complete it) is skipped at this selection (``csiro_frontier_out_of_reach``, once
    per frontier). A frontier
    that lies wholly behind rock of the onboard map seen from that place (a patch beyond a roof,
    floor or wall whose cached points left gaps: flying there would complete it unseen) is
    blacklisted at once (``csiro_frontier_behind_surface``) and the next one taken.

    Writes ``goal`` and ``csiro_goal``. Returns SUCCESS with a goal; RUNNING while none is
    selectable, up to ``wait_s``; then FAILURE (exploration over).
    """

    def update(self) -> Status:
        r, name = self.robot, self.ctx.name
        st = csiro_state(self.ctx, r.view_up_deg)
        frontiers = st.frontiers.frontiers
        ways = way_lengths(self.ctx, r, np.array([f.mean for f in frontiers])) if frontiers else None
        ranked = rank_uav_frontiers(frontiers, r.position, st.momentum, st.selection,
                                    blacklist=st.blacklist.ids(frontiers),
                                    path_m=None if ways is None else dict(zip((f.id for f in frontiers), ways)))
        for frontier, momentum in ranked:   # by eq. 16; skipped: out of reach, blacklisted: behind rock
            near, unreachable = self._nearest_place(frontier)
            if unreachable:
                # Section IV-B: the UAV flies to the frontier's centre and completes the frontier
                # within eta_blacklist of it. A centre that no reachable place comes within
                # eta_blacklist of (in rock, beyond a wall) cannot be completed: skipped for now.
                if frontier.id not in st.out_of_reach_logged and near is not None:
                    st.out_of_reach_logged.add(frontier.id)
                    self.event("csiro_frontier_out_of_reach", id=frontier.id, centre=xyz(frontier.mean, 2),
                               nearest_m=round(float(np.linalg.norm(near[1] - frontier.mean)), 2))
                continue
            place = r.position if near is None else near[1]
            if in_sight(r.onboard_map, place, frontier.points):
                break
            st.blacklist.add(frontier)
            self.event("csiro_frontier_behind_surface", id=frontier.id, centre=xyz(frontier.mean, 2))
        else:
            return self.none_left()
        st.momentum = momentum
        return self.chosen((name, frontier.id), frontier.mean if near is None else near[1],
                           area_m2=round(frontier.area, 2))

    def _nearest_place(self, frontier: Frontier) -> tuple[tuple[np.ndarray, np.ndarray] | None, bool]:
        """The path to the reachable place nearest ``frontier``'s centre and that place (None off
        the graph), and whether that place is farther than eta_blacklist from the centre (out of
        reach). A frontier out of reach is looked for again on the navigation graph rebuilt from
        the current map (the graph may be ``rebuild_period_s`` old) once per version of it (each
        update of Algorithm 2 replaces the frontier); that version stays out of reach, without a
        search, until the graph is rebuilt."""
        st, nav = csiro_state(self.ctx), navigator(self.ctx, self.robot)
        checked = st.out_of_reach.get(frontier.id)
        if checked is not None and checked[0] is frontier and checked[1] is nav.graph():
            return None, True
        near = reachable_near(self.ctx, self.robot, frontier.mean)
        if near is not None and uav_frontier_complete(frontier, near[1], st.selection):
            st.out_of_reach.pop(frontier.id, None)
            return near, False
        if checked is None or checked[0] is not frontier:
            near = reachable_near(self.ctx, self.robot, frontier.mean, fresh=True) or near
        if near is not None and not uav_frontier_complete(frontier, near[1], st.selection):
            st.out_of_reach[frontier.id] = (frontier, nav.graph())
            return near, True
        st.out_of_reach.pop(frontier.id, None)
        return near, False


def in_sight(voxel_map: Any, eye: np.ndarray, points: np.ndarray) -> bool:
    """Whether the straight line from ``eye`` to at least one of ``points`` (K, 3) crosses no
    occupied voxel of ``voxel_map`` (but those next to that point's)."""
    ijk = Grid(voxel_map.occupancy, voxel_map.origin, voxel_map.voxel_size_m).to_index(np.reshape(points, (-1, 3)))
    return bool(line_of_sight(voxel_map, eye, ijk).any())


__all__ = ["SelectUavFrontier", "SelectUgvFrontier"]
