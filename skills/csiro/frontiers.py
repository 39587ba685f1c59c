"""Frontiers from the robot's own LiDAR (Sections III-A to III-C), and the robot's trajectory in
the topometric map (Section IV-C)."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.csiro.observer import observer_candidates, plan_observer
from ...planners.csiro.sharing import summarise
from ..base import Param, Skill
from .state import CsiroState, csiro_state


def body_lift(robot: Any) -> np.ndarray:
    """From a floor point to where the robot's body is over it (0 for a flying robot)."""
    return np.array([0.0, 0.0, 0.0 if robot.mobility.aerial else robot.mobility.body_height_m])


class UpdateFrontiers(Skill):
    """Keep the robot's frontiers up to date from its LiDAR (a background task).

    Every tick: the range sensors' sweeps (``take_lidar_scans``) go into the point cache, and
    the robot's position into the topometric map (a node every ~3 m) and its trajectory points
    (every 5 s). When a sweep came and the frontier update is due (d_min of motion, T_min apart;
    or the last update saw too little) the frontiers of Algorithm 2 are updated from the
    cache's cloud seen from the LiDAR; a ground robot plans the observer of every new or changed
    frontier on the current mesh (equation 13, seen with its LiDAR's elevations), hangs it off
    the topometric map and joins its current node to the trajectory nodes the mesh reaches; a
    frontier that no candidate's LiDAR sees (a patch of roof above the reachable floor) is no
    useful frontier and is dropped; an unchanged frontier in range takes a candidate that
    observes more of it than its observer does. A robot that has reached its goal
    (``look_due``) updates there without the d_min of motion. A degenerate cloud is no error:
    nothing changes, ``csiro_no_view`` says why (once per cause).

    Writes ``csiro_frontier_count`` (the robot's own frontiers). Logs ``csiro_frontiers`` when
    frontiers appear or go, ``csiro_frontiers_unobservable`` when some are dropped. Returns RUNNING.
    """

    PARAMS = {
        "link_radius_m": Param(float, 1.0, "a trajectory node this close to a reachable observer candidate is "
                               "joined to the robot's node (observer-planning edges)", exclusive_minimum=0),
        "cache_radius_m": Param(float, 20.0, "the point cache forgets voxels farther than this (m)",
                                exclusive_minimum=0),
    }
    OUTPUT_PORTS = {"csiro_frontier_count": PortInformation(int, description="the robot's own frontiers")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.no_view = ""

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        st = csiro_state(self.ctx, r.view_up_deg)
        scans = r.take_lidar_scans()
        for scan in scans:
            st.cache.insert(scan.points, scan.sensor)
        pos = r.position
        st.trajectory.add(now, pos)
        if not r.mobility.aerial:
            st.topometric.add_pose(self.ctx.name, now, pos)
        if scans and (st.frontiers.due(now, pos) or self.no_view or st.look_due):
            st.look_due = False
            self._update(st, now, pos)
        self.write("csiro_frontier_count", len(st.frontiers.frontiers))
        return Status.RUNNING

    def _update(self, st: CsiroState, now: float, sensor: np.ndarray) -> None:
        """One frontier update seen from ``sensor`` (the body centre: the LiDAR sits a few
        centimetres above it)."""
        r, name, fp = self.robot, self.ctx.name, st.frontier_params
        st.cache.prune(sensor, max(self.p["cache_radius_m"], fp.d_max_m))
        before = {f.id: f for f in st.frontiers.frontiers}
        upd = st.frontiers.update(now, sensor, st.cache.cloud(sensor, fp))
        if upd.mesh is None:
            if upd.reason != self.no_view:
                self.event("csiro_no_view", reason=upd.reason)
            self.no_view = upd.reason or ""
            return
        self.no_view = ""
        for fid in upd.removed_ids:
            st.summaries.pop((name, fid), None)
            st.topometric.detach_frontier((name, fid))
        changed = [f for f in upd.frontiers if before.get(f.id) is not f]
        if upd.new_ids or upd.removed_ids:
            self.event("csiro_frontiers", count=len(upd.frontiers), new=list(upd.new_ids),
                       removed=list(upd.removed_ids))
        if r.mobility.aerial:
            return
        lift = body_lift(r)
        candidates = observer_candidates(upd.mesh, r.position - lift, st.selection)
        node = st.topometric.last_node(name)
        if node is not None and len(candidates):
            st.topometric.connect_reachable(node, candidates.positions + lift, self.p["link_radius_m"])
        unseen = []
        view = {"sensor_height_m": float(lift[2]),
                "elevations_deg": (fp.elevation_min_deg, fp.elevation_max_deg)}
        for f in changed:
            observer = plan_observer(candidates, f, fp.d_max_m, st.selection, **view)
            if observer is None:
                continue  # no place to observe it from here: the old observer stays
            if observer.reward <= 0.0:
                unseen.append(f.id)  # no candidate's sensor sees any of it: no useful frontier
                continue
            summary = st.summaries[(name, f.id)] = summarise(f, name, observer, now)
            st.topometric.attach_frontier(summary.key, name, now, summary.observer + lift)
        for f in upd.frontiers:  # unchanged ones in range: a better observer among today's candidates
            old = st.summaries.get((name, f.id))
            if before.get(f.id) is not f or old is None or np.linalg.norm(f.mean - sensor) > fp.d_max_m:
                continue
            observer = plan_observer(candidates, f, fp.d_max_m, st.selection, **view)
            if observer is not None and observer.reward > old.reward:
                st.summaries[old.key] = summarise(f, name, observer, old.updated_s)
                st.topometric.attach_frontier(old.key, name, old.updated_s, observer.position + lift)
        if unseen:
            st.frontiers.discard(unseen)
            for fid in unseen:
                st.summaries.pop((name, fid), None)
                st.topometric.detach_frontier((name, fid))
            self.event("csiro_frontiers_unobservable", ids=unseen, count=len(st.frontiers.frontiers))


__all__ = ["UpdateFrontiers", "body_lift"]
