"""The COHORT hub on the base station (Kulkarni et al. 2022, section IV-B): three small
background behaviours that share one :class:`~delve.planners.cohort.CohortHub`.

* ``MergeSubmaps`` takes every ``cohort_submap``, merges it into the base station's
  ``map`` (as ``MergeMaps`` merges map deltas, so the base coverage counts it) and
  hands it to the hub (common map at r_C, the submap's frontier points, its subgraph
  of G_C).
* ``UpdateGlobalFrontiers`` re-checks, re-clusters and links the global frontiers
  after a new submap arrived (and only then).
* ``AnswerRepositionRequests`` answers every ``cohort_request`` with a
  ``cohort_assignment``: the frontier, the path along G_C, the box D.

The hub lives in ``ctx.services["cohort_hub"]``, created on first use from services
``cohort_params`` (the paper's values when absent), ``map`` (the fine base map) and,
when given, ``cohort_home`` (the home position; else the first trajectory point the
hub receives).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from py_trees.common import Status

from ...planners.cohort import CohortHub, CohortParams
from ...planners.geometry import xyz
from ...planners.occupancy import Grid
from ..base import AgentContext, Skill, mailbox

#: ``ctx.services`` keys: the hub's state, the team's parameters, home (optional).
HUB_SERVICE, PARAMS_SERVICE, HOME_SERVICE = "cohort_hub", "cohort_params", "cohort_home"
#: Radio message kinds (``docs/cohort.md``; the robot side uses the same).
SUBMAP, REQUEST, ASSIGNMENT = "cohort_submap", "cohort_request", "cohort_assignment"


def fine_grid(ctx: AgentContext) -> Grid:
    """The base station's ``map`` as a planner grid (its live arrays)."""
    m = ctx.services["map"]
    return Grid(occupancy=m.occupancy, origin=np.asarray(m.origin, float), voxel_size_m=float(m.voxel_size_m))


def cohort_hub(ctx: AgentContext) -> CohortHub:
    """The base station's :class:`CohortHub` (created on first use, in ``ctx.services``)."""
    hub = ctx.services.get(HUB_SERVICE)
    if hub is None:
        params = ctx.services.get(PARAMS_SERVICE) or CohortParams()
        hub = ctx.services[HUB_SERVICE] = CohortHub(params, fine_grid(ctx), ctx.services.get(HOME_SERVICE))
    return hub


class HubSkill(Skill):
    """Base of the hub behaviours: claims its message kind (``CLAIMS``) when built on
    an agent with a radio (not when a tree is only checked)."""

    ABSTRACT = True
    AGENT = "base"
    CLAIMS: str | None = None

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        if self.CLAIMS is not None and "radio" in ctx.services:
            mailbox(ctx, ctx.services["radio"]).claim(self.CLAIMS)

    def take(self) -> list[Any]:
        """The messages of the claimed kind delivered since the last tick."""
        return mailbox(self.ctx, self.ctx.services["radio"]).take(self.CLAIMS)


class MergeSubmaps(HubSkill):
    """Merge every ``cohort_submap`` that reached the base station into its ``map``
    and into the COHORT hub (common map, frontier points, G_C).

    Reads services ``radio``, ``map``, ``cohort_hub``. Logs ``cohort_submap`` per
    submap (robot, index, voxels, frontier points, vertices added, G_C size).
    Returns RUNNING (a background task).
    """

    CLAIMS = SUBMAP

    def update(self) -> Status:
        msgs = self.take()
        if not msgs:
            return Status.RUNNING
        hub, base_map, fine = cohort_hub(self.ctx), self.ctx.services["map"], fine_grid(self.ctx)
        for msg in msgs:
            d = msg.data
            flat = np.asarray(d["flat"], dtype=np.int64)
            values = np.asarray(d["values"], dtype=np.int8)
            base_map.merge(flat, values)
            info = hub.add_submap(fine, d["robot"], int(d["index"]), float(d["t_s"]), flat, values,
                                  np.asarray(d.get("trajectory", np.zeros((0, 3))), float))
            self.event("cohort_submap", robot=info.robot, index=info.index, t_s=info.t_s, voxels=info.voxels,
                       frontier_points=info.frontier_points, vertices=info.vertices,
                       graph_vertices=len(hub.graph), graph_edges=hub.graph.num_edges)
        return Status.RUNNING


class UpdateGlobalFrontiers(Skill):
    """Recompute the global frontiers when a submap arrived since the last time: re-check
    every frontier point against the common map, re-cluster (26-connectivity), drop
    clusters under f_min, link the rest to G_C.

    Reads service ``cohort_hub`` (nothing to do before it exists). Logs
    ``cohort_frontiers`` (clusters: size and centroid, largest first; points deleted).
    Returns RUNNING (a background task).
    """

    AGENT = "base"

    def update(self) -> Status:
        hub = self.ctx.services.get(HUB_SERVICE)
        if hub is not None and hub.stale:
            dropped = hub.update_frontiers()
            self.event("cohort_frontiers", clusters=[{"size": c.size, "centroid": xyz(c.centroid, 2)}
                                                     for c in hub.clusters],
                       points=len(hub.frontiers.all_points()), dropped=dropped)
        return Status.RUNNING


class AnswerRepositionRequests(HubSkill):
    """Answer every ``cohort_request``: send the caller a ``cohort_assignment`` with its
    frontier cluster among the best n_C % (the closest when no other robot competes:
    :func:`~delve.planners.cohort.choose_frontier`), the path to it along G_C and the
    box D around it, or ``frontier`` None and a ``reason`` ("no_frontier", "no_graph",
    "unreachable", "taken"; "explored" when the common map has no frontier point left)
    when there is none. The frontiers are recomputed first if a submap
    arrived since.

    Reads services ``radio``, ``map``, ``cohort_hub``. Logs ``cohort_assignment`` per
    answer. Returns RUNNING (a background task).
    """

    CLAIMS = REQUEST

    def update(self) -> Status:
        msgs = self.take()
        if not msgs:
            return Status.RUNNING
        hub, fine, radio = cohort_hub(self.ctx), fine_grid(self.ctx), self.ctx.services["radio"]
        for msg in msgs:
            d = msg.data
            robot, request_id = d.get("robot", msg.sender), int(d["request_id"])
            r = hub.reposition(fine, robot, np.asarray(d["position"], float), self.ctx.clock.now_s, request_id)
            radio.send(robot, ASSIGNMENT, {
                "request_id": request_id,
                "frontier": None if r.frontier is None else xyz(r.frontier),
                "path": r.path, "box_min": None if r.box_min is None else xyz(r.box_min),
                "box_max": None if r.box_max is None else xyz(r.box_max),
                "cluster_size": int(r.cluster_size), "reason": r.reason})
            self.event("cohort_assignment", robot=robot, request_id=request_id, reason=r.reason,
                       frontier=None if r.frontier is None else xyz(r.frontier, 2), cluster_size=r.cluster_size,
                       distance_m=round(r.distance_m, 2) if r.ok else None,
                       box=None if r.box_min is None else [xyz(r.box_min, 1), xyz(r.box_max, 1)],
                       path_points=0 if r.path is None else len(r.path),
                       distances_m={k: round(v, 2) if math.isfinite(v) else None for k, v in r.distances_m.items()},
                       clusters=len(hub.clusters))
        return Status.RUNNING
