"""Explore-sync (Section V): explore out of contact for a set time, drive back into radio range,
uplink map, frontiers and artifact reports, and go back to the region being explored (the
heuristic the paper says it should have had), not to the nearest frontier.

A tree runs them in a sequence: ``SyncDue`` -> ``ReturnToComms`` -> ``Uplink`` ->
``ReturnToRegion``. The explore-sync time comes from the team (``csiro_config``).
"""
from __future__ import annotations

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.geometry import path_length, xyz
from ..base import AgentContext, Param, Skill
from ..motion_base import PathMotion
from ..navigation import navigator
from ..robot import PathStatus
from .state import BASE, CsiroState, csiro_config, csiro_state


def way_to(ctx: AgentContext, st: CsiroState, target: np.ndarray, replans: int) -> np.ndarray | None:
    """Waypoints from the robot to ``target``: a ground robot's first plan follows the team's
    topometric map; a flying robot, a re-plan (a straight step between topometric nodes can
    cut a junction's corner through rock) or a target the map has no path to go by the
    onboard map's navigation graph (rebuilt on a re-plan). None when neither has a way."""
    r = ctx.robot
    if replans == 0 and not r.mobility.aerial:
        node = st.topometric.nearest_node(target)
        found = None if node is None else st.topometric.path(r.position, node)
        if found is not None and len(found.points) >= 2:
            return found.points[1:]
    path, _ = navigator(ctx, r).path_to_point(target, force=replans > 0)
    return path if path is not None and len(path) else None


class SyncDue(Skill):
    """Whether the robot has explored out of contact with the base station for the team's
    explore-sync time. While a link exists (``radio.linked_to``) it notes when and where; once
    the time is up it notes where the robot is (the region to come back to) and logs
    ``csiro_sync_due``.

    Writes ``csiro_out_of_contact_s``. Returns SUCCESS when a sync is due, else FAILURE.
    """

    OUTPUT_PORTS = {"csiro_out_of_contact_s": PortInformation(float, description="sim time since the last link "
                                                              "to the base station (s)")}

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        st = csiro_state(self.ctx, r.view_up_deg)
        if st.contact is None or r.radio.linked_to(BASE):
            st.contact_s, st.contact = now, r.position
        out = now - st.contact_s
        self.write("csiro_out_of_contact_s", round(out, 1))
        if out < csiro_config(self.ctx).explore_sync_s:
            return Status.FAILURE
        st.region = r.position
        self.event("csiro_sync_due", out_of_contact_s=round(out, 1), region=xyz(st.region, 2),
                   last_contact=xyz(st.contact, 2))
        return Status.SUCCESS


class ReturnToComms(PathMotion):
    """Drive back into radio range: along the topometric map to where the link to the base
    station was last seen (the navigation graph of the onboard map for a flying robot, or
    when the map has no path), then, re-planning on the navigation graph (a straight step
    between topometric nodes can cut a junction's corner through rock), on towards home
    while no link comes back.

    Returns SUCCESS as soon as a link to the base station exists; RUNNING on the way; FAILURE
    when home is reached without a link or the re-plans are used up, and then the time out of
    contact counts from now (the robot explores on and tries again after the explore-sync
    time, instead of trying again at once).
    """

    PARAMS = {"max_replans": Param(int, 4, "re-plans after a blocked path or an arrival short of the link",
                                   minimum=0)}

    def reached(self) -> bool:
        return self.robot.radio.linked_to(BASE)

    def arrived(self) -> Status:
        self.event("csiro_back_in_range", position=xyz(self.robot.position, 2))
        return Status.SUCCESS

    def give_up(self, status: PathStatus, reason: str) -> Status:
        self.feedback_message = f"no link after {self.replans - 1} re-plans ({reason or status})"
        self.event("csiro_return_failed", reason=self.feedback_message)
        csiro_state(self.ctx).contact_s = self.ctx.clock.now_s
        return Status.FAILURE

    def plan(self) -> Status:
        r = self.robot
        st = csiro_state(self.ctx, r.view_up_deg)
        target = st.contact if self.replans == 0 and st.contact is not None else r.home
        path = way_to(self.ctx, st, target, self.replans)
        if path is None:
            path = np.asarray([r.home], float)
        self.drive(path)
        self.feedback_message = f"back to the link, {path_length(np.vstack([r.position, path])):.0f} m"
        self.event("csiro_return_to_comms", to=xyz(path[-1], 2))
        return Status.RUNNING


class Uplink(Skill):
    """Stand in radio range while the uplink drains: at least ``min_wait_s`` (so that the map
    and the frontiers, shared every 5 s, are sent) and until the radio's outbox is empty or
    ``timeout_s`` has passed. Logs ``csiro_sync`` (time out of contact, messages left).

    Returns RUNNING while waiting, then SUCCESS.
    """

    PARAMS = {
        "min_wait_s": Param(float, 6.0, "sim time to stand in range at least", minimum=0),
        "timeout_s": Param(float, 60.0, "sim time to wait for the outbox to drain at most", exclusive_minimum=0),
    }

    def initialise(self) -> None:
        self.start_s = self.ctx.clock.now_s
        self.robot.stop()

    def update(self) -> Status:
        r, waited = self.robot, self.ctx.clock.now_s - self.start_s
        if waited < self.p["min_wait_s"] or (r.radio.pending and waited < self.p["timeout_s"]):
            self.feedback_message = f"uplink: {r.radio.pending} messages to send"
            return Status.RUNNING
        st = csiro_state(self.ctx)
        st.contact_s, st.contact = self.ctx.clock.now_s, r.position
        self.event("csiro_sync", position=xyz(r.position, 2), waited_s=round(waited, 1), pending=r.radio.pending)
        return Status.SUCCESS


class ReturnToRegion(PathMotion):
    """After a sync, go back to the region being explored (where the sync began) along the
    topometric map (the onboard map's navigation graph for a flying robot, or on a re-plan).

    Returns SUCCESS within ``tolerance_m`` of the region (at once when there is none) and logs
    ``csiro_region_reached``; RUNNING on the way; FAILURE when the re-plans are used up. Either
    way the region is forgotten and the time out of contact counts from then.
    """

    PARAMS = {
        "tolerance_m": Param(float, 3.0, "distance to the region that counts as back", exclusive_minimum=0),
        "max_replans": Param(int, 3, "re-plans after a blocked path or an arrival short of the region", minimum=0),
    }

    def reached(self) -> bool:
        region = csiro_state(self.ctx).region
        return region is None or float(np.linalg.norm(self.robot.position - region)) <= self.p["tolerance_m"]

    def arrived(self) -> Status:
        st = csiro_state(self.ctx)
        if st.region is not None:
            self.event("csiro_region_reached", region=xyz(st.region, 2), position=xyz(self.robot.position, 2))
        self._explore_again(st)
        return Status.SUCCESS

    def give_up(self, status: PathStatus, reason: str) -> Status:
        st = csiro_state(self.ctx)
        self.event("csiro_region_failed", region=xyz(st.region, 2), reason=reason or str(status))
        self._explore_again(st)
        return Status.FAILURE

    def _explore_again(self, st: CsiroState) -> None:
        """The region is forgotten and the time out of contact counts from now: the explore-sync
        time is time spent exploring, not driving back to the region."""
        st.region = None
        st.contact_s = self.ctx.clock.now_s

    def plan(self) -> Status:
        r, st = self.robot, csiro_state(self.ctx)
        path = way_to(self.ctx, st, st.region, self.replans)
        if path is None:
            return self.give_up(PathStatus.BLOCKED, "no path to the region")
        self.drive(path)
        self.event("csiro_return_to_region", region=xyz(st.region, 2),
                   length_m=round(path_length(np.vstack([r.position, path])), 1))
        return Status.RUNNING


__all__ = ["ReturnToComms", "ReturnToRegion", "SyncDue", "Uplink"]
