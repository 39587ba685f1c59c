"""Fault kinds: one plug-in per kind of fault a scenario can inject (``faults:``).

A scenario's fault names its ``kind``; the kind's class (a :class:`Fault`) checks the
entry and injects it. A new kind is a module here (or anywhere) that subclasses
:class:`Fault` and calls :func:`register_fault`; the runner needs no change (see
docs/extending.md).
"""
from __future__ import annotations

from .base import BASE_STATION, LINK, NEVER, OPTIONAL, REQUIRED, ROBOT, Fault, FaultContext, Target
from .base_station import BaseRestart
from .planner import InjectedPlannerError, PlannerError, PlannerSlow
from .radio import BreadcrumbDies, RadioBlackout
from .robot import BatteryDrop, Lost, Stuck
from .sensing import LidarDegraded, LidarDropout, LocalisationDrift, MapArtifact

#: The registered fault kinds by the name a scenario gives.
FAULT_KINDS: dict[str, type[Fault]] = {}


def register_fault(kind: type[Fault]) -> None:
    """Make ``kind`` available to scenarios as ``kind: <kind.KIND>`` (a later class
    with the same name replaces an earlier one)."""
    if not kind.KIND:
        raise ValueError(f"{kind.__name__} has no KIND")
    FAULT_KINDS[kind.KIND] = kind


for _kind in (Stuck, MapArtifact, Lost, RadioBlackout, LidarDegraded, LidarDropout, PlannerError, PlannerSlow,
              BatteryDrop, LocalisationDrift, BreadcrumbDies, BaseRestart):
    register_fault(_kind)

# After the registry: the loader and the schedule look kinds up in it.
from .loader import load_faults  # noqa: E402
from .schedule import FaultSchedule  # noqa: E402

__all__ = ["BASE_STATION", "FAULT_KINDS", "Fault", "FaultContext", "FaultSchedule", "InjectedPlannerError", "LINK",
           "NEVER", "OPTIONAL", "REQUIRED", "ROBOT", "Target", "load_faults", "register_fault"]
