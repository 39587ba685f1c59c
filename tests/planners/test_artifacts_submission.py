"""delve.planners.artifacts.submission: "immediate" and "best_first" against the
reports left."""
from __future__ import annotations

import numpy as np
from delve.planners.artifacts.candidates import Candidates
from delve.planners.artifacts.params import SubmissionParams
from delve.planners.artifacts.report import ArtifactReport
from delve.planners.artifacts.submission import choose, reserve

END = 3600.0
BEST, NOW = SubmissionParams(), SubmissionParams(policy="immediate")


def _cands(specs) -> Candidates:
    """One candidate per (probability, robots, t_s), 20 m apart."""
    cands = Candidates()
    for i, (probability, robots, t_s) in enumerate(specs):
        for robot in robots:
            cands.merge(ArtifactReport("drill", np.array([20.0 * i, 0.0, 0.0]), probability, 3, t_s, "camera",
                                       robot))
    assert len(cands) == len(specs)
    return cands


def test_immediate_submits_every_new_candidate_oldest_first():
    cands = _cands([(0.97, ["a"], 30.0), (0.2, ["b"], 10.0), (0.99, ["a"], 20.0)])
    assert choose(cands.submittable(), 45, 100.0, END, NOW) == [1, 2, 0]


def test_immediate_never_submits_more_than_reports_left():
    cands = _cands([(0.97, ["a"], float(t)) for t in range(5)])
    assert choose(cands.submittable(), 2, 100.0, END, NOW) == [0, 1]
    assert choose(cands.submittable(), 0, 100.0, END, NOW) == []


def test_best_first_holds_a_weak_candidate_while_the_budget_is_short_and_submits_it_near_the_end():
    cands = _cands([(0.97, ["a"], 0.0), (0.3, ["b"], 0.0)])         # strong, weak (one robot, faint)
    assert choose(cands.submittable(), 10, 600.0, END, BEST) == [0]
    assert choose(cands.submittable(), 10, END - 60.0, END, BEST) == [0, 1]
    assert reserve(END - 60.0, END, BEST) == 0 < reserve(600.0, END, BEST)


def test_best_first_submits_a_weak_candidate_when_the_budget_is_plenty():
    cands = _cands([(0.3, ["b"], 0.0)])
    plenty = reserve(600.0, END, BEST) + 1
    assert choose(cands.submittable(), plenty - 1, 600.0, END, BEST) == []
    assert choose(cands.submittable(), plenty, 600.0, END, BEST) == [0]


def test_a_weak_candidate_confirmed_by_a_second_robot_is_strong():
    cands = _cands([(0.3, ["a", "b"], 0.0)])
    assert choose(cands.submittable(), 1, 600.0, END, BEST) == [0]


def test_best_first_ranks_and_never_submits_more_than_reports_left():
    cands = _cands([(0.96, ["a"], 0.0), (0.99, ["a"], 5.0), (0.97, ["a", "b"], 9.0), (0.97, ["c"], 1.0),
                    (0.4, ["d"], 0.0)])
    assert choose(cands.submittable(), 2, END - 1.0, END, BEST) == [1, 2]
    assert choose(cands.submittable(), 5, END - 1.0, END, BEST) == [1, 2, 3, 0, 4]
    for left in range(6):
        for t in (0.0, 1800.0, END):
            assert len(choose(cands.submittable(), left, t, END, BEST)) <= left


def test_scored_candidates_are_not_chosen_again():
    cands = _cands([(0.97, ["a"], 0.0), (0.97, ["a"], 1.0)])
    cands.record(0, scored=True)
    assert choose(cands.submittable(), 45, 100.0, END, BEST) == [1]
