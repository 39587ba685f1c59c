"""The base station's artifact candidates: the reports of all robots merged, one
candidate per artifact (CERBERUS paper, section 4.2.2: robots "might have reported
the same artifacts"; issue 12: "the same artifact seen by two robots is one
candidate").

A report joins the nearest candidate of its class whose position lies within
``merge_radius_m``, else it starts a new candidate. A candidate's position is the
mean of its reports' positions weighted by their detections; its probability the
highest of its reports'. Its outcome: open (never submitted), scored (closed for
good; later reports of it are absorbed), or missed (submitted and not scored: it may
be submitted again only once its position has moved ``resubmit_distance_m`` from
every position it was submitted at).
"""
from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from .params import CandidateParams
from .report import ArtifactReport

OPEN, SCORED, MISSED = "open", "scored", "missed"


@dataclass
class Candidate:
    """One artifact as the base station knows it: its id (creation order), class,
    the reports merged into it, its outcome and the positions it was submitted at."""

    id: int
    artifact_class: str
    reports: list[ArtifactReport] = field(default_factory=list)
    outcome: str = OPEN
    submitted_positions: list[np.ndarray] = field(default_factory=list)

    @property
    def position(self) -> np.ndarray:
        """Mean of the reports' positions weighted by their detections."""
        weights = [r.detections for r in self.reports]
        return np.average([r.position for r in self.reports], axis=0, weights=weights)

    @property
    def probability(self) -> float:
        return max(r.probability for r in self.reports)

    @property
    def detections(self) -> int:
        return sum(r.detections for r in self.reports)

    @property
    def robots(self) -> tuple[str, ...]:
        """The reporting robots' names, sorted ("" for a report without one)."""
        return tuple(sorted({r.robot or "" for r in self.reports}))

    @property
    def first_t_s(self) -> float:
        return min(r.t_s for r in self.reports)

    def submittable(self, resubmit_distance_m: float) -> bool:
        """Never submitted, or missed and moved ``resubmit_distance_m`` from every
        position it was submitted at."""
        if self.outcome == OPEN:
            return True
        if self.outcome == SCORED:
            return False
        moved = np.linalg.norm(np.asarray(self.submitted_positions) - self.position, axis=1)
        return bool(np.all(moved > resubmit_distance_m))


class Candidates:
    """All candidates of a mission, in creation order (see the module's docstring)."""

    def __init__(self, params: CandidateParams | None = None) -> None:
        self.params = params or CandidateParams()
        self._all: list[Candidate] = []

    def __iter__(self) -> Iterator[Candidate]:
        return iter(self._all)

    def __len__(self) -> int:
        return len(self._all)

    def __getitem__(self, candidate_id: int) -> Candidate:
        return self._all[candidate_id]

    def merge(self, report: ArtifactReport) -> Candidate:
        """Add a report: to the nearest candidate of its class within ``merge_radius_m``
        (the older of equals), else to a new candidate. Returns that candidate."""
        same = [c for c in self._all if c.artifact_class == report.artifact_class]
        if same:
            dist = np.linalg.norm(np.array([c.position for c in same]) - report.position, axis=1)
            i = int(np.argmin(dist))
            if dist[i] <= self.params.merge_radius_m:
                same[i].reports.append(report)
                return same[i]
        candidate = Candidate(len(self._all), report.artifact_class, [report])
        self._all.append(candidate)
        return candidate

    def record(self, candidate_id: int, scored: bool) -> None:
        """The referee's verdict on a submission of the candidate at its current
        position: scored closes it, else it is missed at this position."""
        c = self._all[candidate_id]
        c.submitted_positions.append(c.position)
        c.outcome = SCORED if scored else MISSED

    def submittable(self) -> list[Candidate]:
        """The candidates that may be submitted now (:meth:`Candidate.submittable`)."""
        return [c for c in self._all if c.submittable(self.params.resubmit_distance_m)]


__all__ = ["MISSED", "OPEN", "SCORED", "Candidate", "Candidates"]
