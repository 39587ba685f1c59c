"""Relocate to a frontier (the supervisor's third mode of operation) and drop WiFi
breadcrumbs."""
from __future__ import annotations

from typing import Any

from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.geometry import xyz
from .base import Param, Skill
from .gbplanner import gbplanner
from .motion_base import PathMotion
from .navigation import navigator
from .robot import PathStatus


class Relocate(PathMotion):
    """Relocate to the best frontier of GBPlanner2's global graph (gain over path
    length, among frontiers from which the robot can still get home).

    Writes ``relocation_target``. Returns RUNNING on the way; SUCCESS on arrival (the
    tree then explores from there); FAILURE when the global graph has no frontier, or
    the path is blocked ``max_replans`` times (the reason in the log).
    """

    PARAMS = {"max_replans": Param(int, 3, "re-plans allowed after a blocked path", minimum=0)}
    OUTPUT_PORTS = {"relocation_target": PortInformation(list | None, description="[x, y, z] of the frontier it "
                                                         "relocates to (m)")}

    def path_ended(self, status: PathStatus) -> Status | None:
        if status == PathStatus.ARRIVED:
            self.event("relocated", at=xyz(self.robot.position, 2))
            return Status.SUCCESS
        return None

    def give_up(self, status: PathStatus, reason: str) -> Status:
        return self._fail(f"path blocked {self.replans} times")

    def plan(self) -> Status:
        r = self.robot
        planner = gbplanner(self.ctx, r).planner
        res = planner.global_planner.plan_reposition(navigator(self.ctx, r).grid(), r.position,
                                                     r.endurance_remaining_s)
        if res.path is None:
            return self._fail(res.reason or "no frontier to relocate to")
        self.drive(res.path)
        target = xyz(res.target, 2) if res.target is not None else None
        self.write("relocation_target", target)
        self.event("relocate", trigger=True, to=target, path_length_m=round(res.length_m, 1))
        return Status.RUNNING

    def _fail(self, reason: str) -> Status:
        self.feedback_message = reason
        self.event("relocate_failed", reason=reason)
        return Status.FAILURE


class DeployBreadcrumb(Skill):
    """Drop a WiFi breadcrumb on the ground under the robot (Carrier ANYmals hold four).

    Reads ``breadcrumb_request``. A drop is refused where the breadcrumb would hear no
    mesh node, or has no ground to land on (a result with an error from the robot,
    never an exception). Writes ``breadcrumb_request``: cleared once a breadcrumb is
    dropped, once the robot has none left, and after ``max_attempts`` refusals in a
    row; kept after a refusal before that, so that the tree can back the robot up
    toward the mesh and try again. A drop also clears ``link_loss_points`` (the mesh
    now reaches farther than where the link was lost). Logs ``breadcrumb_dropped``
    or ``breadcrumb_failed`` (with ``gave_up`` when the request is dropped).
    Returns SUCCESS when a breadcrumb was dropped; FAILURE when none is requested,
    or the drop was refused.
    """

    PARAMS = {"max_attempts": Param(int, 4, "refused drops in a row before the request is given up", minimum=1)}
    INPUT_PORTS = {"breadcrumb_request": PortInformation(bool, required=False,
                                                         description="True when a breadcrumb is to be dropped")}
    OUTPUT_PORTS = {
        "breadcrumb_request": PortInformation(bool, description="cleared (False) when served or given up"),
        "link_loss_points": PortInformation(list, description="cleared ([]) by a drop"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.refusals = 0

    def update(self) -> Status:
        if not self.read("breadcrumb_request"):
            self.refusals = 0
            return Status.FAILURE
        drop = self.robot.deploy_breadcrumb()
        if not drop.ok:
            self.refusals += 1
            give_up = drop.remaining <= 0 or self.refusals >= self.p["max_attempts"]
            if give_up:
                self.write("breadcrumb_request", False)
                self.refusals = 0
            self.feedback_message = drop.error
            self.event("breadcrumb_failed", reason=drop.error, at=xyz(self.robot.position, 2), gave_up=give_up)
            return Status.FAILURE
        self.write("breadcrumb_request", False)
        self.write("link_loss_points", [])
        self.refusals = 0
        self.event("breadcrumb_dropped", trigger=True, name=drop.name, remaining=drop.remaining,
                   at=xyz(self.robot.position, 2))
        return Status.SUCCESS


__all__ = ["DeployBreadcrumb", "Relocate"]
