"""The ``artifacts`` section of ``report.json``: what was there, what each robot
detected and reported, what reached the base station, what was submitted and what
scored, with the time and error of each point."""
from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING, Any

from ...skills.artifacts import ARTIFACT_REPORT
from .view import CourseView

if TYPE_CHECKING:
    from ..runner import Mission


def _events(mission: "Mission", name: str) -> list[dict[str, Any]]:
    return [e for e in mission.state.events if e["event"] == name]


def undelivered_reports(mission: "Mission") -> dict[str, int]:
    """Artifact reports still in each robot's radio outbox (a lost robot's for good)."""
    return {name: sum(m.kind == ARTIFACT_REPORT for m in mission.radio.endpoints[name].outbox)
            for name in mission.robots}


def artifact_figures(mission: "Mission", course: CourseView) -> dict[str, Any]:
    """The report's ``artifacts`` section."""
    referee = course.referee
    detected = {name: sorted(s.detected) for name, s in course.sensors.items()}
    made = Counter(e["agent"] for e in _events(mission, "artifact_reported"))
    delivered = Counter(e["sender"] for e in _events(mission, "artifact_delivered"))
    undelivered = undelivered_reports(mission)
    points = [{"t_s": round(s.t_s, 1), "artifact": s.artifact, "artifact_class": s.artifact_class,
               "error_m": round(float(s.error_m), 2), "robots": list(robots)}
              for s, robots in zip(referee.scores, course.desk.reporters) if s.scored]
    found = {p["artifact"] for p in points}
    return {"artifacts": {
        "total": len(course.artifacts),
        "classes": dict(sorted(Counter(a.artifact_class for a in course.artifacts).items())),
        "detected": len(set().union(*map(set, detected.values()))) if detected else 0,
        "robots": {name: {"detected": len(detected[name]), "reports_made": made[name],
                          "reports_delivered": delivered[name], "reports_undelivered": undelivered[name],
                          "points": sum(name in p["robots"] for p in points)} for name in mission.robots},
        "reported_to_base": sum(delivered.values()),
        "undelivered": sum(undelivered.values()),
        "submitted": referee.reports_used,
        "refused": sum(not s.counted for s in referee.scores),
        "scored": referee.score,
        "false_reports": sum(s.counted and not s.scored for s in referee.scores),
        "report_limit": referee.report_limit,
        "reports_left": referee.reports_left,
        "points": points,
        "missed": [a.name for a in course.artifacts if a.name not in found],
    }}
