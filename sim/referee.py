"""The SubT referee: scores artifact reports the way osrf/subt's game logic does.

Rules, as ``GameLogicPluginPrivate::OnNewArtifact`` and ``ScoreArtifact`` apply
them in osrf/subt ``subt_ign/src/GameLogicPlugin.cc`` (the Final's version):

- Once ``reportCount >= reportCountLimit`` every further report is refused
  ("report limit exceeded"); the Prize Round's limit was 45 (the paper, Section 4.2).
- A report of an unknown artifact type is answered but neither scored nor counted.
- A report whose type and position (each coordinate printed with
  ``std::to_string``, i.e. to six decimals) equal an earlier report's is a
  duplicate: refused, not scored, and **not** counted against the limit.
- Any other report counts against the limit. Its error is the distance to the
  nearest artifact of the reported class, found or not; it scores one point when
  that distance is below 5 m (strictly) and that artifact has not been found yet.
  A report near an already-found artifact therefore scores nothing, even when
  another, unfound artifact of the class lies within 5 m but farther away.
- When every artifact has been found, further reports are neither scored nor counted.

Positions are world coordinates (osrf/subt converts from the artifact origin
frame first; delve's reports are already in the world frame).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .artifacts import ARTIFACT_CLASSES, Artifact

#: The Prize Round's report limit (CERBERUS paper, Section 4.2: "all the 45 report submissions").
PRIZE_ROUND_REPORT_LIMIT = 45
#: A report scores within this distance (m) of the artifact (osrf/subt: ``distance < 5``).
SCORING_RADIUS_M = 5.0


@dataclass(frozen=True, eq=False)
class Score:
    """The referee's answer to one report.

    Fields:
        t_s: when the report was submitted (sim time).
        artifact_class, position: what was reported.
        scored: whether it earned a point.
        artifact: the nearest artifact of the class (its name), or None.
        error_m: distance (m) to that artifact, or None when there is none.
        reason: "scored", "too far", "already found", "duplicate", "limit reached",
            "unknown class", "no artifact of class" or "all found".
        counted: whether it used one of the reports allowed.
    """

    t_s: float
    artifact_class: str
    position: np.ndarray
    scored: bool
    artifact: str | None
    error_m: float | None
    reason: str
    counted: bool


class Referee:
    """Scores reports against the ground truth (see the module docstring for the rules).

    ``report_limit`` below 1 or ``radius_m`` not > 0 is a ValueError.
    """

    def __init__(self, artifacts: list[Artifact], *, report_limit: int = PRIZE_ROUND_REPORT_LIMIT,
                 radius_m: float = SCORING_RADIUS_M) -> None:
        if isinstance(report_limit, bool) or not isinstance(report_limit, (int, np.integer)) \
                or report_limit < 1:
            raise ValueError(f"report_limit must be an integer >= 1, got {report_limit!r}")
        if not (np.isfinite(radius_m) and radius_m > 0):
            raise ValueError(f"radius_m must be > 0, got {radius_m!r}")
        self.artifacts = list(artifacts)
        self.report_limit = int(report_limit)
        self.radius_m = float(radius_m)
        self.found: set[str] = set()
        self.scores: list[Score] = []
        self._reports: set[tuple[str, str, str, str]] = set()

    @property
    def reports_used(self) -> int:
        """Reports counted against the limit."""
        return sum(s.counted for s in self.scores)

    @property
    def reports_left(self) -> int:
        return self.report_limit - self.reports_used

    @property
    def score(self) -> int:
        """Points so far."""
        return sum(s.scored for s in self.scores)

    def submit(self, t_s: float, artifact_class: str, position) -> Score:
        """Score one report, keep the Score in ``scores`` and return it."""
        p = np.asarray(position, dtype=float).reshape(3)
        key = (artifact_class, *(f"{x:f}" for x in p))         # std::to_string's "%f"
        if self.reports_left <= 0:
            return self._keep(t_s, artifact_class, p, "limit reached", counted=False)
        if artifact_class not in ARTIFACT_CLASSES:
            return self._keep(t_s, artifact_class, p, "unknown class", counted=False)
        if len(self.found) >= len(self.artifacts):
            return self._keep(t_s, artifact_class, p, "all found", counted=False)
        if key in self._reports:
            return self._keep(t_s, artifact_class, p, "duplicate", counted=False)
        self._reports.add(key)
        same = [a for a in self.artifacts if a.artifact_class == artifact_class]
        if not same:
            return self._keep(t_s, artifact_class, p, "no artifact of class", counted=True)
        dist = [float(np.linalg.norm(a.position - p)) for a in same]
        nearest = same[int(np.argmin(dist))]
        error = min(dist)
        if error >= self.radius_m:
            reason = "too far"
        elif nearest.name in self.found:
            reason = "already found"
        else:
            reason = "scored"
            self.found.add(nearest.name)
        return self._keep(t_s, artifact_class, p, reason, counted=True, artifact=nearest.name,
                          error_m=error)

    def _keep(self, t_s: float, cls: str, p: np.ndarray, reason: str, *, counted: bool,
              artifact: str | None = None, error_m: float | None = None) -> Score:
        score = Score(float(t_s), cls, p, reason == "scored", artifact, error_m, reason, counted)
        self.scores.append(score)
        return score
