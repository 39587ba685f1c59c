"""delve.planners.artifacts.candidates: the base station's merge of all robots'
reports into candidates, and when a candidate may be submitted again."""
from __future__ import annotations

import numpy as np
from delve.planners.artifacts.candidates import MISSED, OPEN, SCORED, Candidates
from delve.planners.artifacts.report import ArtifactReport

A = np.array([50.0, -10.0, 2.0])


def _report(position, artifact_class="survivor", robot="anymal_1", detections=3, probability=0.97, t_s=0.0):
    return ArtifactReport(artifact_class, np.asarray(position, float), probability, detections, t_s, "camera",
                          robot)


def test_two_robots_reporting_one_artifact_make_one_candidate():
    cands = Candidates()
    a = cands.merge(_report(A, robot="anymal_1", t_s=100.0))
    b = cands.merge(_report(A + [1.0, 0.0, 0.0], robot="anymal_3", t_s=700.0))
    assert a is b and len(cands) == 1
    assert a.robots == ("anymal_1", "anymal_3")
    assert [r.t_s for r in a.reports] == [100.0, 700.0] and a.first_t_s == 100.0
    assert np.allclose(a.position, A + [0.5, 0.0, 0.0])


def test_different_classes_or_far_apart_make_two_candidates():
    cands = Candidates()
    cands.merge(_report(A))
    cands.merge(_report(A + [1.0, 0.0, 0.0], artifact_class="backpack"))
    cands.merge(_report(A + [10.0, 0.0, 0.0]))
    assert [c.artifact_class for c in cands] == ["survivor", "backpack", "survivor"]


def test_the_position_is_weighted_by_detections_and_the_probability_is_the_best():
    cands = Candidates()
    c = cands.merge(_report(A, detections=3, probability=0.96))
    cands.merge(_report(A + [2.0, 0.0, 0.0], detections=1, probability=0.99, robot="anymal_2"))
    assert np.allclose(c.position, A + [0.5, 0.0, 0.0])
    assert c.probability == 0.99 and c.detections == 4


def test_a_report_joins_the_nearest_candidate_of_its_class():
    cands = Candidates()
    cands.merge(_report(A))
    cands.merge(_report(A + [6.0, 0.0, 0.0]))
    assert cands.merge(_report(A + [3.5, 0.0, 0.0])).id == 1


def test_a_scored_candidate_is_closed_and_absorbs_later_reports():
    cands = Candidates()
    c = cands.merge(_report(A))
    assert c.outcome == OPEN and cands.submittable() == [c]
    cands.record(c.id, scored=True)
    assert c.outcome == SCORED and cands.submittable() == []
    assert cands.merge(_report(A + [0.5, 0.0, 0.0], robot="anymal_2")) is c
    assert cands.submittable() == []


def test_a_missed_candidate_is_resubmitted_only_once_it_has_moved_far_enough():
    cands = Candidates()
    c = cands.merge(_report(A, detections=2))
    cands.record(c.id, scored=False)
    assert c.outcome == MISSED and cands.submittable() == []
    cands.merge(_report(A + [3.0, 0.0, 0.0], detections=2))          # moves the candidate 1.5 m
    assert cands.submittable() == []
    cands.merge(_report(A + [3.5, 0.0, 0.0], detections=8))          # and now 2.8 m > 2.5 m
    assert np.linalg.norm(c.position - A) > cands.params.resubmit_distance_m
    assert cands.submittable() == [c]
    cands.record(c.id, scored=False)
    assert cands.submittable() == []
