"""Bluetooth and CO2 readings clustered into reports."""
from __future__ import annotations

from typing import Any

from py_trees.common import Status

from ...planners.artifacts import SignalClusterer
from .reporting import ReportingSkill


class FuseSignalReadings(ReportingSkill):
    """Bluetooth and CO2 detection (paper, Section 3.5): the robot's readings since the
    last tick, clustered by SSID (Bluetooth) or by distance (CO2); a cluster with
    enough readings above threshold is reported once, at the centre of its strongest
    readings.

    Writes ``artifact_reports`` (appends). Returns RUNNING (a background task)."""

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.clusterer = SignalClusterer(robot=ctx.name)

    def update(self) -> Status:
        for r in self.robot.take_signal_readings():
            self.add_reports(self.clusterer.add(r.t_s, r.kind, r.identifier, r.position, r.value))
        return Status.RUNNING
