"""delve.planners.artifacts.report: an artifact report and its radio form."""
from __future__ import annotations

import json

import numpy as np
import pytest
from delve.planners.artifacts.report import ARTIFACT_CLASSES, ArtifactReport


def _report(**kw) -> ArtifactReport:
    values = dict(artifact_class="backpack", position=np.array([1.23456, -2.0, 0.5]), probability=0.976543,
                  detections=3, t_s=12.34567, source="camera", robot="anymal_1")
    return ArtifactReport(**{**values, **kw})


def test_the_radio_form_is_plain_json_rounded_and_round_trips():
    r = _report()
    d = r.to_dict()
    assert json.loads(json.dumps(d)) == d
    assert d["position"] == [1.23, -2.0, 0.5] and d["probability"] == 0.9765 and d["t_s"] == 12.346
    back = ArtifactReport.from_dict(d)
    assert back.to_dict() == d
    assert back.robot == "anymal_1" and isinstance(back.position, np.ndarray)


def test_the_position_is_a_read_only_copy():
    p = np.array([1.0, 2.0, 3.0])
    r = _report(position=p)
    p[0] = 9.0
    assert r.position[0] == 1.0
    with pytest.raises(ValueError):
        r.position[0] = 5.0


def test_the_robot_is_optional():
    d = _report(robot=None).to_dict()
    del d["robot"]
    assert ArtifactReport.from_dict(d).robot is None


@pytest.mark.parametrize("bad, words", [
    (dict(artifact_class="Drill"), "unknown artifact class"),
    (dict(source="radar"), "unknown report source"),
    (dict(probability=1.2), "outside [0, 1]"),
    (dict(detections=0), "at least one detection"),
    (dict(position=[1.0, 2.0]), "3 finite numbers"),
    (dict(position=[1.0, np.nan, 2.0]), "3 finite numbers"),
])
def test_bad_values_are_one_line_errors(bad, words):
    with pytest.raises(ValueError) as err:
        _report(**bad)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_radio_message_without_a_key_is_a_one_line_error():
    d = _report().to_dict()
    del d["position"]
    with pytest.raises(ValueError, match="lacks 'position'"):
        ArtifactReport.from_dict(d)


def test_the_final_s_ten_classes():
    assert len(ARTIFACT_CLASSES) == 10 and "cell_phone" in ARTIFACT_CLASSES and "cube" in ARTIFACT_CLASSES
