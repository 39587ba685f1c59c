"""delve.planners.artifacts.camera_fusion: association spheres, averaged centres, a
binary Bayes filter per class, one report per track."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.artifacts import camera_fusion
from delve.planners.artifacts.camera_fusion import ArtifactTracker
from delve.planners.artifacts.params import CameraFusionParams

P = np.array([10.0, 5.0, 1.0])


def _feed(tracker: ArtifactTracker, labels: list[str], positions=None, confidence: float = 0.8) -> list:
    reports = []
    for i, label in enumerate(labels):
        pos = P if positions is None else positions[i]
        reports += tracker.add(float(i), label, confidence, pos)
    return reports


def test_detections_inside_the_sphere_are_one_track_and_farther_ones_two():
    t = ArtifactTracker()
    t.add(0.0, "drill", 0.8, P)
    t.add(0.3, "drill", 0.8, P + [1.0, 0.0, 0.0])
    assert len(t.tracks) == 1
    t.add(0.6, "drill", 0.8, P + [4.5, 0.0, 0.0])              # 4.5 m from the first, 4 m from the centre
    assert len(t.tracks) == 2
    assert CameraFusionParams().association_radius_m == 2.0


def test_the_centre_is_the_average_of_the_accepted_detections():
    t = ArtifactTracker()
    offsets = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.6, -0.3]])
    reports = _feed(t, ["helmet"] * 3, P + offsets)
    assert np.allclose(t.tracks[0].centre, P + offsets.mean(axis=0))
    assert len(reports) == 1 and np.allclose(reports[0].position, P + offsets.mean(axis=0))


def test_reported_once_after_enough_detections_and_never_again():
    t = ArtifactTracker(robot="anymal_2")
    assert _feed(t, ["backpack"] * 2) == []
    r = t.add(2.0, "backpack", 0.8, P)
    assert len(r) == 1
    assert (r[0].artifact_class, r[0].detections, r[0].source, r[0].robot, r[0].t_s) == \
        ("backpack", 3, "camera", "anymal_2", 2.0)
    assert r[0].probability >= CameraFusionParams().report_threshold
    assert _feed(t, ["backpack"] * 20) == []
    assert t.tracks[0].detections == 3                       # later detections are ignored, the centre stays
    assert len(t.tracks) == 1


def test_a_lone_false_positive_is_not_reported():
    t = ArtifactTracker()
    assert t.add(0.0, "survivor", 0.99, P) == []
    assert t.tracks[0].probabilities()["survivor"] < CameraFusionParams().report_threshold


def test_scattered_false_positives_are_never_reported():
    rng = np.random.default_rng(7)
    t = ArtifactTracker()
    positions = rng.uniform(-100.0, 100.0, size=(200, 3))
    labels = [str(c) for c in rng.choice(["rope", "vent", "drill"], size=200)]
    assert _feed(t, labels, positions) == []


def test_conflicting_labels_converge_to_the_majority():
    t = ArtifactTracker()
    reports = _feed(t, ["drill", "fire_extinguisher", "drill", "fire_extinguisher", "drill", "drill", "drill",
                        "drill"])
    assert [r.artifact_class for r in reports] == ["drill"]
    p = t.tracks[0].probabilities()
    assert p["fire_extinguisher"] < 0.1 < CameraFusionParams().report_threshold <= p["drill"]


def test_a_detection_lowers_the_other_classes():
    t = ArtifactTracker()
    _feed(t, ["rope"])
    before = t.tracks[0].probabilities()
    t.add(1.0, "vent", 0.8, P)
    after = t.tracks[0].probabilities()
    assert after["rope"] < before["rope"] and after["vent"] > before["vent"] and after["cube"] < before["cube"]


def test_low_confidence_detections_are_dropped():
    t = ArtifactTracker()
    assert _feed(t, ["drill"] * 10, confidence=0.3) == [] and t.tracks == []


def test_a_detection_joins_the_nearest_sphere():
    t = ArtifactTracker()
    t.add(0.0, "rope", 0.8, P)
    t.add(0.0, "rope", 0.8, P + [3.0, 0.0, 0.0])
    t.add(0.0, "rope", 0.8, P + [1.8, 0.0, 0.0])            # inside both spheres, nearer the second
    assert [tr.detections for tr in t.tracks] == [1, 2]


def test_same_inputs_give_the_same_reports():
    rng = np.random.default_rng(3)
    positions = P + rng.normal(0.0, 0.7, size=(40, 3))
    labels = [str(c) for c in rng.choice(["drill", "backpack"], size=40, p=[0.7, 0.3])]
    runs = [[r.to_dict() for r in _feed(ArtifactTracker(), labels, positions)] for _ in range(2)]
    assert runs[0] == runs[1] and runs[0]


def test_unknown_label_is_an_error_and_locate_is_reexported():
    with pytest.raises(ValueError, match="unknown artifact class"):
        ArtifactTracker().add(0.0, "phone", 0.9, P)
    assert camera_fusion.locate.__module__.endswith("ray_hits")
