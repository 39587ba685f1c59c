"""The base station's submission policy: which candidates to submit to the referee
now, against the reports left (issue 12, item 5).

CERBERUS's Human Supervisor saw each report with its image, accepted or rejected it,
and "decided which artifact (class and position) to report" (paper, sections 3.6 and
4.2.2); in the last 7 minutes he only worked through the reports already received.
"best_first" models that filter:

- rank candidates by probability, then the number of robots that reported them, then
  their detections, then age (the older first);
- a candidate is strong when its probability reaches ``strong_probability`` or
  ``confirm_robots`` robots reported it; strong candidates are submitted at once, in
  rank order, while reports are left;
- weak ones are held back while the reports left (after the strong ones) do not
  exceed a reserve kept for strong candidates still to come,
  floor(``reserve_rate_per_s`` x time to the end); they go out, best first, when the
  budget is plenty or near the end, when the reserve has fallen to zero.

"immediate" submits every candidate at once, oldest first, while reports are left.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

from .candidates import Candidate
from .params import SubmissionParams


def rank_key(c: Candidate) -> tuple:
    """Sort key, best first: probability, robots, detections, then the oldest."""
    return (-c.probability, -len(c.robots), -c.detections, c.first_t_s, c.id)


def is_strong(c: Candidate, params: SubmissionParams) -> bool:
    """Probable enough, or confirmed by enough robots."""
    return c.probability >= params.strong_probability or len(c.robots) >= params.confirm_robots


def reserve(t_s: float, mission_end_s: float, params: SubmissionParams) -> int:
    """Reports kept back from weak candidates at ``t_s``: floor(rate x time left)."""
    return math.floor(params.reserve_rate_per_s * max(mission_end_s - t_s, 0.0))


def choose(candidates: Sequence[Candidate], reports_left: int, t_s: float, mission_end_s: float,
           params: SubmissionParams | None = None) -> list[int]:
    """Ids of the candidates to submit now, in order, at most ``reports_left`` of them.
    ``candidates`` are those that may be submitted (``Candidates.submittable()``)."""
    params = params or SubmissionParams()
    budget = max(reports_left, 0)
    if params.policy == "immediate":
        return [c.id for c in sorted(candidates, key=lambda c: (c.first_t_s, c.id))][:budget]
    ranked = sorted(candidates, key=rank_key)
    chosen = [c.id for c in ranked if is_strong(c, params)][:budget]
    spare = budget - len(chosen) - reserve(t_s, mission_end_s, params)
    weak = [c.id for c in ranked if not is_strong(c, params)]
    return chosen + weak[:max(spare, 0)]


__all__ = ["choose", "is_strong", "rank_key", "reserve"]
