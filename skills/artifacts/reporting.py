"""Onboard reports: the list the fusion behaviours add to, and the behaviour that
sends them to the base station."""
from __future__ import annotations

from typing import Any

from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.artifacts import ArtifactReport
from ..base import Param, Skill

#: Radio message kind of an artifact report.
ARTIFACT_REPORT = "artifact_report"
#: The blackboard port of the robot's reports (plain dicts, ArtifactReport.to_dict()).
REPORTS_PORT = {"artifact_reports": PortInformation(list, description="the artifact reports this robot made, "
                                                    "oldest first (plain dicts)", default_value=[])}


class ReportingSkill(Skill):
    """A fusion behaviour: it adds the reports it makes to ``artifact_reports`` and
    logs an ``artifact_reported`` event for each."""

    ABSTRACT = True
    INPUT_PORTS = REPORTS_PORT
    OUTPUT_PORTS = REPORTS_PORT

    def add_reports(self, reports: list[ArtifactReport]) -> None:
        if not reports:
            return
        made = [r.to_dict() for r in reports]
        self.write("artifact_reports", self.read("artifact_reports") + made)
        for r in made:
            self.event("artifact_reported", artifact_class=r["artifact_class"], position=r["position"],
                       probability=r["probability"], detections=r["detections"], source=r["source"])


class SendArtifactReports(Skill):
    """Send each report of ``artifact_reports`` not sent yet to ``recipient``.

    Reports wait in the radio's outbox while no route to the base station exists
    (mesh, breadcrumbs or other robots), and leave when one returns: nothing is lost
    unless the robot is. Reads ``artifact_reports``. Returns RUNNING (a background
    task)."""

    PARAMS = {"recipient": Param(str, "base", "who receives the reports")}
    INPUT_PORTS = REPORTS_PORT

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.sent = 0

    def update(self) -> Status:
        reports = self.read("artifact_reports")
        for report in reports[self.sent:]:
            self.robot.radio.send(self.p["recipient"], ARTIFACT_REPORT, report)
        self.sent = len(reports)
        return Status.RUNNING
