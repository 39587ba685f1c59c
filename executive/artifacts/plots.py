"""Pictures of the artifacts: markers on ``map.png`` and points over time
(``scored.png``, as the CERBERUS paper's Figure 24)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..worlds.height_bands import ALL_HEIGHTS, HeightBand  # noqa: E402
from .view import CourseView  # noqa: E402

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..runner import Mission

#: Marker, colour and legend label of each artifact outcome, best first.
OUTCOMES = {
    "scored": ("*", "#1a9641", "artifact scored"),
    "reported": ("o", "#fdae61", "artifact reported, not scored"),
    "detected": ("s", "#2c7bb6", "artifact detected, no report within 5 m"),
    "missed": ("X", "#7f7f7f", "artifact missed"),
}


def artifact_outcomes(mission: "Mission", course: CourseView) -> dict[str, str]:
    """Each artifact's outcome: scored; reported (a report of its class reached the
    base station within the scoring radius); detected (a robot's sensor picked it
    up); or missed."""
    scored = {s.artifact for s in course.referee.scores if s.scored}
    delivered = [(e["artifact_class"], np.asarray(e["position"])) for e in mission.state.events
                 if e["event"] == "artifact_delivered"]
    detected = set().union(*(s.detected for s in course.sensors.values()))
    out = {}
    for a in course.artifacts:
        near = any(c == a.artifact_class and np.linalg.norm(p - a.position) < course.referee.radius_m
                   for c, p in delivered)
        out[a.name] = ("scored" if a.name in scored else "reported" if near else
                       "detected" if a.name in detected else "missed")
    return out


def draw_artifacts(ax: "Axes", mission: "Mission", course: CourseView, band: HeightBand = ALL_HEIGHTS) -> None:
    """Mark each artifact at ``band``'s heights on the top-down map by its outcome, with its
    class, and every submission there that scored nothing with a small red cross."""
    outcomes = artifact_outcomes(mission, course)
    for outcome, (marker, colour, label) in OUTCOMES.items():
        mine = [a for a in course.artifacts if outcomes[a.name] == outcome and band.holds(a.position).all()]
        if not mine:
            continue
        pts = np.array([a.position for a in mine])
        ax.scatter(pts[:, 0], pts[:, 1], marker=marker, s=90 if marker == "*" else 45, c=colour,
                   edgecolors="black", linewidths=0.6, zorder=5, label=f"{label} ({len(mine)})")
        for a in mine:
            ax.annotate(a.artifact_class.replace("_", " "), a.position[:2], fontsize=6,
                        xytext=(4, 4), textcoords="offset points", zorder=6)
    wrong = band.within(np.array([s.position for s in course.referee.scores if s.counted and not s.scored]))
    if len(wrong):
        ax.scatter(wrong[:, 0], wrong[:, 1], marker="x", s=20, c="red", zorder=5,
                   label=f"report that scored nothing ({len(wrong)})")


def plot_scores(mission: "Mission", course: CourseView, path: Path) -> None:
    """Points over sim time: the team's, and each robot's (a point goes to the robot
    whose report of the artifact reached the base station first)."""
    points = [(s.t_s, robots[0] if robots else "") for s, robots in zip(course.referee.scores, course.desk.reporters)
              if s.scored]
    end = (mission.finished_s or mission.clock.now_s) / 60.0
    fig, ax = plt.subplots(figsize=(7, 4))
    times = np.array([t for t, _ in points]) / 60.0

    def steps(ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.concatenate([[0.0], ts, [end]]), np.concatenate([[0], np.arange(1, len(ts) + 1), [len(ts)]])

    ax.step(*steps(times), where="post", lw=2.2, color="black", label=f"team ({len(points)})")
    for name in mission.robots:
        mine = np.array([t for t, r in points if r == name]) / 60.0
        ax.step(*steps(mine), where="post", lw=1.2, label=f"{name} ({len(mine)})")
    ax.set_xlabel("sim time (min)")
    ax.set_ylabel("points")
    ax.set_xlim(0, max(end, 1e-3))
    ax.set_ylim(0, max(len(points), 1) + 0.5)
    ax.yaxis.get_major_locator().set_params(integer=True)
    referee = course.referee
    ax.set_title(f"{mission.scenario.name}: {referee.score} of {len(course.artifacts)} artifacts, "
                 f"{referee.reports_used} of {referee.report_limit} reports used")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
