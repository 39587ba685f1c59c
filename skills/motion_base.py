"""The one loop every motion behaviour shares: follow a path, re-plan when it ends
short (blocked, or arrived somewhere that is not the goal), give up after N re-plans.

``GoTo``, ``Home``, ``Backtrack`` and ``Relocate`` build on :class:`PathMotion`; each
says only where it is going (:meth:`~PathMotion.reached`), where its path comes from
(:meth:`~PathMotion.plan`), and what it writes and logs on the way.
"""
from __future__ import annotations

from abc import abstractmethod

from typing import Any

import numpy as np
from py_trees.common import Status

from ..planners.occupancy import Grid
from ..planners.trail import JumpCheck, jump_check
from .base import AgentContext, Skill
from .robot import PathStatus, Robot


class PathMotion(Skill):
    """Base of the behaviours that drive the robot along a path.

    Each tick: when :meth:`reached` holds, the robot is stopped (if it still follows
    this behaviour's path) and :meth:`arrived` gives the status. While the robot
    follows the path, RUNNING. When the path has ended (blocked, arrived, or stopped
    by someone else), that counts as one re-plan: :meth:`path_ended` may end the
    behaviour there; after more than :attr:`max_replans` re-plans :meth:`give_up`
    does. Otherwise, and on the first tick, :meth:`plan` issues the next path with
    :meth:`drive` (and returns RUNNING) or fails.

    Interrupted (INVALID) while driving, it stops the robot if the robot still follows
    its command. Subclasses read ``self.replans`` (re-plans so far) and ``self.moving``.
    """

    ABSTRACT = True

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.moving = False
        self.replans = 0

    @property
    def max_replans(self) -> int:
        """Re-plans allowed before :meth:`give_up` (the ``max_replans`` parameter)."""
        return int(self.p["max_replans"])

    # ---- what a subclass says --------------------------------------------------------
    def reached(self) -> bool:
        """Whether the behaviour is where it should be (checked first on every tick)."""
        return False

    def arrived(self) -> Status:
        """The status once :meth:`reached` holds (the robot has been stopped)."""
        return Status.SUCCESS

    def progress(self) -> None:
        """Called on each tick while driving, before the path's status is read."""

    def path_ended(self, status: PathStatus) -> Status | None:
        """The path ended with ``status`` (not FOLLOWING) and ``replans`` has counted it:
        a status ends the behaviour; None goes on (give up, or re-plan)."""
        return None

    @abstractmethod
    def give_up(self, status: PathStatus, reason: str) -> Status:
        """More than ``max_replans`` re-plans: ``reason`` is the robot's blocked reason."""

    @abstractmethod
    def plan(self) -> Status:
        """Issue the next path with :meth:`drive` and return RUNNING, or end the behaviour."""

    # ---- the loop ------------------------------------------------------------------
    def initialise(self) -> None:
        self.moving, self.replans = False, 0

    def update(self) -> Status:
        if self.reached():
            if self.moving:
                self.stop_own_motion()
            self.moving = False
            return self.arrived()
        if self.moving:
            self.progress()
            r = self.robot
            status = r.path_status
            if status == PathStatus.FOLLOWING:
                return Status.RUNNING
            self.moving = False
            self.replans += 1
            ended = self.path_ended(status)
            if ended is not None:
                return ended
            if self.replans > self.max_replans:
                return self.give_up(status, r.blocked_reason)
        return self.plan()

    def drive(self, path: np.ndarray) -> None:
        """Command the robot along ``path`` ((N, 3) waypoints)."""
        self.follow(path)
        self.moving = True

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.moving and self.ctx.robot is not None:
            self.stop_own_motion()
        self.moving = False


def trail_jump_check(robot: Robot) -> JumpCheck:
    """Whether ``robot`` can go straight between two points of its trail on its
    onboard map (see :func:`delve.planners.trail.jump_check`)."""
    m, mob = robot.onboard_map, robot.mobility
    return jump_check(Grid(m.occupancy, m.origin, m.voxel_size_m), aerial=mob.aerial,
                      body_height_m=mob.body_height_m, max_step_m=mob.max_step_m)


__all__ = ["PathMotion", "trail_jump_check"]
