"""When faults start, step and end during a mission (the runner holds one schedule)."""
from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING

from .base import Fault

if TYPE_CHECKING:
    from ..runner import Mission

#: Slack when comparing sim times (steps add up floating-point seconds).
EPS_S = 1e-9


class FaultSchedule:
    """The faults of a mission: pending ones by time, active ones until they end.

    Each update starts the faults that are due (a ``fault`` event), ends those whose
    ``end_s`` has come (a ``fault_end`` event) and steps the others. A fault is in
    ``active`` while it starts and lasts, and no longer when it ends, so that faults
    of a kind that overlap can work out what the others still hold. A fault aimed at
    a robot that is already lost does not start (its ``fault`` event says so)."""

    def __init__(self, faults: list[Fault]):
        self.pending: deque[Fault] = deque(sorted(faults, key=lambda f: f.at_s))
        self.active: list[Fault] = []

    def update(self, mission: "Mission", now_s: float) -> None:
        while self.pending and self.pending[0].at_s <= now_s + EPS_S:
            fault = self.pending.popleft()
            if fault.robot is not None and fault.robot in mission.lost:
                mission.log("fault", **fault.fields(), skipped=f"robot {fault.robot} is lost")
                continue
            self.active.append(fault)
            extra = fault.start(mission) or {}
            mission.log("fault", **fault.fields(), **extra)
        for fault in list(self.active):
            end = fault.end_s
            if end is not None and end <= now_s + EPS_S:
                self.active.remove(fault)
                extra = fault.end(mission) or {}
                mission.log("fault_end", **fault.fields(), **extra)
            else:
                fault.step(mission, now_s)

    def holding(self, kind: type[Fault], robot: str | None = None) -> list[Fault]:
        """The active faults of ``kind`` (and its subclasses), on ``robot`` if given."""
        return [f for f in self.active if isinstance(f, kind) and (robot is None or f.robot == robot)]
