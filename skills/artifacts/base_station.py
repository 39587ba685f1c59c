"""The base station's side: reports merged into candidates, candidates submitted to
the referee (the Human Supervisor's filter modelled as a submission policy)."""
from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.artifacts import ArtifactReport, Candidates, SubmissionParams, choose
from ...planners.artifacts.params import SUBMISSION_POLICIES
from ...planners.geometry import xyz
from ..base import Param, Skill, mailbox
from .reporting import ARTIFACT_REPORT

#: ``ctx.services`` key of the referee the base station submits to.
REFEREE = "referee"
CANDIDATES_PORT = {"artifact_candidates": PortInformation(object, description="the base station's artifact "
                                                          "candidates (planners.artifacts.Candidates)")}


class Verdict(Protocol):
    """What the referee says of one submission."""

    scored: bool
    error_m: float | None
    reason: str


class Referee(Protocol):
    """The referee as the base station reaches it (the SubT rules)."""

    @property
    def reports_left(self) -> int: ...

    @property
    def mission_end_s(self) -> float: ...

    def submit(self, artifact_class: str, position: np.ndarray, reporters: tuple[str, ...] = ()) -> Verdict:
        """The verdict on a report of ``artifact_class`` at ``position``; ``reporters``:
        the robots behind it (for the record)."""


class CollectArtifactReports(Skill):
    """Take the artifact reports that reached the base station and merge them into
    candidates: the same class within a merge radius is one artifact, whoever saw it.

    Reads the base station's radio (service ``radio``, messages of kind
    ``artifact_report``). Writes ``artifact_candidates``. Logs an
    ``artifact_delivered`` event per report. Returns RUNNING (a background task)."""

    AGENT = "base"
    OUTPUT_PORTS = CANDIDATES_PORT

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.candidates = Candidates()
        if "radio" in ctx.services:  # not when a tree is only checked
            mailbox(ctx, ctx.services["radio"]).claim(ARTIFACT_REPORT)

    def initialise(self) -> None:
        self.write("artifact_candidates", self.candidates)

    def update(self) -> Status:
        for msg in mailbox(self.ctx, self.ctx.services["radio"]).take(ARTIFACT_REPORT):
            report = ArtifactReport.from_dict(msg.data)
            candidate = self.candidates.merge(report)
            self.event("artifact_delivered", sender=msg.sender, artifact_class=report.artifact_class,
                       position=xyz(report.position, 2), made_s=report.t_s, sent_s=msg.sent_s,
                       candidate=candidate.id)
        return Status.RUNNING


class SubmitArtifacts(Skill):
    """Submit candidates to the referee by ``policy``: ``immediate`` (each new one at
    once) or ``best_first`` (strong candidates in rank order, weak ones held back while
    the reports left are needed for strong ones still to come). A candidate that did
    not score is submitted again only once its position has moved.

    Reads ``artifact_candidates`` and service ``referee`` (a mission without
    artifacts has none: then it does nothing). Logs an ``artifact_submitted`` event
    per submission (its verdict, error, reason). Returns RUNNING (a background
    task)."""

    AGENT = "base"
    PARAMS = {
        "policy": Param(str, SubmissionParams.policy, "immediate or best_first", choices=SUBMISSION_POLICIES),
        "strong_probability": Param(float, SubmissionParams.strong_probability,
                                    "a candidate this probable is strong", minimum=0, maximum=1),
        "confirm_robots": Param(int, SubmissionParams.confirm_robots,
                                "a candidate this many robots reported is strong", minimum=1),
    }
    INPUT_PORTS = CANDIDATES_PORT

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.params = SubmissionParams(policy=self.p["policy"], strong_probability=self.p["strong_probability"],
                                       confirm_robots=self.p["confirm_robots"])

    def update(self) -> Status:
        candidates: Candidates | None = self.read("artifact_candidates")
        referee: Referee | None = self.ctx.services.get(REFEREE)
        if candidates is None or referee is None:
            return Status.RUNNING
        chosen = choose(candidates.submittable(), referee.reports_left, self.ctx.clock.now_s, referee.mission_end_s,
                        self.params)
        for cid in chosen:
            c = candidates[cid]
            reporters = tuple(dict.fromkeys(r.robot or "" for r in c.reports))  # first reporter first
            verdict = referee.submit(c.artifact_class, c.position, reporters)
            candidates.record(cid, verdict.scored)
            self.event("artifact_submitted", candidate=cid, artifact_class=c.artifact_class,
                       position=xyz(c.position, 2), robots=list(reporters), scored=verdict.scored,
                       error_m=None if verdict.error_m is None else round(float(verdict.error_m), 2),
                       reason=verdict.reason)
        return Status.RUNNING
