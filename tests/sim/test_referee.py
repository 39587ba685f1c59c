"""Unit tests for delve.sim.referee: the SubT scoring rules (osrf/subt GameLogicPlugin)."""

import numpy as np
import pytest

from delve.sim.artifacts import Artifact
from delve.sim.referee import Referee

UP = np.array([0.0, 0.0, 1.0])


def _art(name, cls, pos):
    return Artifact(name=name, artifact_class=cls, position=np.asarray(pos, float),
                    surface="floor", normal=UP, size_m=0.5)


@pytest.fixture
def arts():
    return [_art("backpack_1", "backpack", [0, 0, 0]), _art("backpack_2", "backpack", [50, 0, 0]),
            _art("drill_1", "drill", [20, 0, 0])]


def test_within_five_metres_scores(arts):
    ref = Referee(arts)
    near = ref.submit(10.0, "backpack", [4.9, 0, 0])
    assert near.scored and near.reason == "scored" and near.artifact == "backpack_1"
    assert near.error_m == pytest.approx(4.9)
    far = ref.submit(11.0, "backpack", [50, 5.1, 0])
    assert not far.scored and far.reason == "too far" and far.error_m == pytest.approx(5.1)
    assert ref.score == 1 and ref.reports_used == 2 and ref.reports_left == 43


def test_wrong_class_does_not_score(arts):
    ref = Referee(arts)
    s = ref.submit(1.0, "drill", [0.5, 0, 0])
    assert not s.scored and s.reason == "too far" and s.artifact == "drill_1"
    assert ref.submit(2.0, "helmet", [0, 0, 0]).reason == "no artifact of class"
    assert ref.score == 0 and ref.reports_used == 2


def test_already_found_artifact_scores_once(arts):
    ref = Referee(arts)
    assert ref.submit(1.0, "backpack", [1, 0, 0]).scored
    again = ref.submit(2.0, "backpack", [-1, 0, 0])
    assert not again.scored and again.reason == "already found" and again.counted
    assert ref.score == 1 and ref.reports_used == 2


def test_duplicate_is_refused_and_not_counted(arts):
    ref = Referee(arts)
    first = ref.submit(1.0, "drill", [30, 0, 0])
    dup = ref.submit(2.0, "drill", [30, 0, 0])
    assert first.counted and not dup.counted and dup.reason == "duplicate"
    assert ref.reports_used == 1
    assert ref.submit(3.0, "drill", [30.000001, 0, 0]).reason == "too far"   # six decimals differ


def test_report_limit(arts):
    ref = Referee(arts, report_limit=45)
    for i in range(45):
        assert ref.submit(float(i), "drill", [100.0 + i, 0, 0]).counted
    refused = ref.submit(45.0, "backpack", [0, 0, 0])
    assert refused.reason == "limit reached" and not refused.scored and not refused.counted
    assert ref.reports_used == 45 and ref.reports_left == 0 and len(ref.scores) == 46


def test_unknown_class_and_all_found(arts):
    ref = Referee(arts[:1])
    assert ref.submit(0.0, "toolbox", [0, 0, 0]).reason == "unknown class"
    assert ref.submit(1.0, "backpack", [0, 0, 0]).scored
    assert ref.submit(2.0, "backpack", [1, 0, 0]).reason == "all found"
    assert ref.reports_used == 1


@pytest.mark.parametrize("limit", [0, -3, 1.5, True])
def test_bad_limit(arts, limit):
    with pytest.raises(ValueError, match="report_limit"):
        Referee(arts, report_limit=limit)
