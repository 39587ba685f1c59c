"""Endurance and homing skills."""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status

from .base import Param, Skill
from .navigation import navigator
from .robot import PathStatus


class EnduranceLow(Skill):
    """Whether the remaining endurance barely covers the way home.

    The way home is the shortest path on the onboard map from the robot to its home
    (its straight-line length times ``detour_factor`` while no path is known). It is
    re-planned at most every ``check_period_s``, and only when the reserve could have
    run out: the way home grows by at most the distance walked, so the reserve
    shrinks by at most ``1 + safety_factor`` seconds per second.

    Writes: ``time_to_home_s``. Returns SUCCESS when
    ``endurance <= safety_factor * time_to_home + margin_s``, else FAILURE.
    """

    PARAMS = {
        "safety_factor": Param(float, 1.2, "multiplies the time the way home takes", minimum=1.0),
        "margin_s": Param(float, 60.0, "reserve kept on top", minimum=0),
        "check_period_s": Param(float, 5.0, "how often the way home is re-planned", exclusive_minimum=0),
        "detour_factor": Param(float, 1.5, "straight line to path length when no path is known", minimum=1.0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.k_time = self.key("time_to_home_s")
        self.next_check_s = -float("inf")
        self.time_to_home_s = 0.0

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        sf = self.p["safety_factor"]
        if now >= self.next_check_s:
            _, length = navigator(self.ctx, r).path_to_point(r.home)
            if not np.isfinite(length):
                length = float(np.linalg.norm(r.position - r.home)) * self.p["detour_factor"]
            self.time_to_home_s = length / r.mobility.speed_mps
            self.bb.set(self.k_time, round(self.time_to_home_s, 2))
            reserve = r.endurance_remaining_s - (sf * self.time_to_home_s + self.p["margin_s"])
            self.next_check_s = now + max(self.p["check_period_s"], reserve / (1 + sf))
        needed = sf * self.time_to_home_s + self.p["margin_s"]
        if r.endurance_remaining_s <= needed:
            self.feedback_message = f"{r.endurance_remaining_s:.0f} s left, home takes {self.time_to_home_s:.0f} s"
            self.event("endurance_low", trigger=True, endurance_s=round(r.endurance_remaining_s, 1),
                       time_to_home_s=round(self.time_to_home_s, 1))
            return Status.SUCCESS
        return Status.FAILURE



class ReturnHome(Skill):
    """Walk or fly home through known free space.

    Writes: ``returned_home`` (True on arrival). Returns RUNNING on the way; SUCCESS
    within ``tolerance_m`` of home; FAILURE when no path home is found after
    ``max_replans`` attempts.
    """

    PARAMS = {
        "tolerance_m": Param(float, 1.0, "distance to home that counts as home", exclusive_minimum=0),
        "max_replans": Param(int, 5, "re-plans allowed after a blocked path", minimum=0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.k_home = self.key("returned_home")
        self.replans = 0
        self.moving = False

    def initialise(self) -> None:
        self.replans, self.moving = 0, False

    def update(self) -> Status:
        r = self.robot
        if np.linalg.norm(r.position - r.home) <= self.p["tolerance_m"]:
            r.stop()
            self.bb.set(self.k_home, True)
            self.event("home_reached", endurance_s=round(r.endurance_remaining_s, 1))
            return Status.SUCCESS
        if self.moving and r.path_status == PathStatus.FOLLOWING:
            return Status.RUNNING
        if self.moving:
            self.replans += 1
            if self.replans > self.p["max_replans"]:
                self.feedback_message = "no way home"
                self.event("homing_failed", reason=getattr(r, "blocked_reason", ""))
                return Status.FAILURE
        path, length = navigator(self.ctx, r).path_to_point(r.home, force=True)
        if path is None:
            path = np.array([r.home])  # the last stretch: straight to the start pose
        self.follow(np.vstack([path, r.home]))
        self.moving = True
        self.feedback_message = f"home is {length:.0f} m away"
        self.event("homing", path_length_m=round(length, 1) if np.isfinite(length) else None)
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.ctx.robot is not None:
            self.stop_own_motion()
