"""Safety conditions of the ANYmal behaviour tree: the watchdog, the homing timer and
the link to the base station (the CERBERUS paper, section 3.3.3, Figures 13–15)."""
from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.gbplanner2.link_loss import near_points
from ..planners.geometry import xyz
from .base import Param, Skill
from .robot import PathStatus

BASE = "base"


class RobotStuck(Skill):
    """Watchdog: a motion command is active but the robot has not moved.

    Keeps the robot's positions over the last ``stuck_time_s`` while it follows a
    path. Returns SUCCESS (and logs a ``watchdog`` trigger) when it has followed a
    path for ``stuck_time_s`` and every position in that time lies within
    ``min_motion_m`` of where it is now (going away and back is motion); FAILURE
    otherwise.

    """

    PARAMS = {
        "stuck_time_s": Param(float, 20.0, "time without motion that counts as stuck", exclusive_minimum=0),
        "min_motion_m": Param(float, 0.3, "less motion than this in stuck_time_s is no motion", exclusive_minimum=0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.history: deque[tuple[float, np.ndarray]] = deque()

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        if r.path_status != PathStatus.FOLLOWING:
            self.history.clear()
            return Status.FAILURE
        self.history.append((now, r.position))
        while len(self.history) > 1 and now - self.history[1][0] >= self.p["stuck_time_s"]:
            self.history.popleft()
        if now - self.history[0][0] >= self.p["stuck_time_s"] and self._still(r.position):
            self.history.clear()
            self.feedback_message = f"no motion for {self.p['stuck_time_s']:.0f} s"
            self.event("watchdog", trigger=True, position=xyz(r.position, 2))
            return Status.SUCCESS
        return Status.FAILURE

    def _still(self, here: np.ndarray) -> bool:
        """Whether every kept position lies within ``min_motion_m`` of ``here``; the
        oldest first, which for a robot under way is the far one (one test a tick)."""
        return all(float(np.linalg.norm(here - p)) < self.p["min_motion_m"] for _, p in self.history)


class BudgetElapsed(Skill):
    """Homing timer: the supervisor's time budget for exploring out of range is spent.

    Reads ``time_budget_s`` and ``budget_start_s`` (written by
    ProcessOperatorCommands). Returns SUCCESS (and logs a ``homing_timer`` trigger)
    once the budget has elapsed; FAILURE while it has not, or when no budget is set.
    """

    AGENT = None
    INPUT_PORTS = {
        "time_budget_s": PortInformation(float, required=False, description="the budget (s); null: none"),
        "budget_start_s": PortInformation(float, required=False, description="sim time the budget started at (s)"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.fired = False

    def update(self) -> Status:
        budget, start = self.read("time_budget_s"), self.read("budget_start_s")
        if budget is None or start is None or self.ctx.clock.now_s - start < budget:
            self.fired = False
            return Status.FAILURE
        if not self.fired:
            self.event("homing_timer", trigger=True, budget_s=budget)
            self.fired = True
        return Status.SUCCESS


class Ping(Skill):
    """Ping the base station every ``period_s``; a ping can fail.

    Writes ``ping_ok`` (the last ping's result), ``failed_pings`` (consecutive
    failures) and ``link_lost_at`` (where the robot was at the first of those
    failures: the radio edge; None while pings succeed). Returns RUNNING (it is a
    background task).
    """

    PARAMS = {
        "period_s": Param(float, 2.0, "time between pings", exclusive_minimum=0),
        "target": Param(str, BASE, "who is pinged"),
    }
    OUTPUT_PORTS = {
        "ping_ok": PortInformation(bool, description="the last ping's result (True before the first)"),
        "failed_pings": PortInformation(int, description="consecutive failed pings"),
        "link_lost_at": PortInformation(list | None, description="[x, y, z] where the first of the consecutive "
                                        "failed pings was made (m); None while pings succeed"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.next_s = 0.0
        self.failed = 0

    def setup(self, **kwargs: Any) -> None:
        self.write("ping_ok", True)
        self.write("failed_pings", 0)
        self.write("link_lost_at", None)

    def update(self) -> Status:
        now = self.ctx.clock.now_s
        if now + 1e-9 >= self.next_s:
            self.next_s = now + self.p["period_s"]
            ok = bool(self.robot.radio.ping(self.p["target"]))
            self.failed = 0 if ok else self.failed + 1
            self.write("ping_ok", ok)
            self.write("failed_pings", self.failed)
            if self.failed <= 1:
                self.write("link_lost_at", None if ok else xyz(self.robot.position, 2))
        return Status.RUNNING




class RememberLinkLoss(Skill):
    """Remember where the robot found its link to the base station lost, so that its
    exploration discounts what lies beyond (the WiFi safety block, before it backs off).

    Appends ``link_lost_at`` (where the first failed ping was made, which is
    nearer the radio edge than where the robot noticed the loss) or else the robot's
    position to ``link_loss_points`` unless one of them lies within
    ``merge_radius_m``; logs ``link_loss``. Always SUCCESS. The points are
    cleared when the supervisor sends the robot exploring again or a breadcrumb
    extends the mesh.
    """

    PARAMS = {"merge_radius_m": Param(float, 2.0, "a loss this close to a remembered one is the same", minimum=0)}
    INPUT_PORTS = {"link_loss_points": PortInformation(list, required=False, default_value=[],
                                                       description="[x, y, z] points where the link was lost"),
                   "link_lost_at": PortInformation(list, required=False, description="[x, y, z] where the first "
                                                   "failed ping of this loss was made (m)")}
    OUTPUT_PORTS = {"link_loss_points": PortInformation(list, description="[x, y, z] points where the link was "
                                                        "lost (m)")}

    def update(self) -> Status:
        points = list(self.read("link_loss_points") or [])
        lost_at = self.read("link_lost_at")
        here = self.robot.position if lost_at is None else np.asarray(lost_at, float)
        known = bool(near_points(here, np.asarray(points, float), self.p["merge_radius_m"]).any())
        if not known:
            points.append(xyz(here, 2))
            self.write("link_loss_points", points)
        self.event("link_loss", at=xyz(here, 2), remembered=len(points), new=not known)
        return Status.SUCCESS
