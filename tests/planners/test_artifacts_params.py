"""delve.planners.artifacts.params: the pipeline's defaults and their checks."""
from __future__ import annotations

import math

import pytest
from delve.planners.artifacts.params import (CameraFusionParams, CandidateParams, SignalFusionParams, SignalParams,
                                             SubmissionParams)


def _posterior(params: CameraFusionParams, n: int) -> float:
    """Probability of a class after n consistent detections, from the defaults."""
    hit, false = params.hit_likelihood, params.false_likelihood
    logit = math.log(params.prior / (1 - params.prior)) + n * math.log(hit / false)
    return 1 / (1 + math.exp(-logit))


def test_default_camera_fusion_needs_three_consistent_detections():
    p = CameraFusionParams()
    assert _posterior(p, 2) < p.report_threshold <= _posterior(p, 3)


def test_class_likelihood_overrides_apply_to_their_class_only():
    hit, false = CameraFusionParams(class_likelihoods={"cell_phone": (0.4, 0.05)}).likelihoods()
    assert hit[1] == 0.4 and false[1] == 0.05 and hit[0] == 0.7 and false[0] == 0.1


def test_normalise_clips_to_the_predefined_range():
    bt = SignalFusionParams().bluetooth
    assert bt.normalise(-120.0) == 0.0 and bt.normalise(-30.0) == 1.0 and bt.normalise(-70.0) == pytest.approx(0.5)


@pytest.mark.parametrize("make, field", [
    (lambda: CameraFusionParams(association_radius_m=0), "association_radius_m"),
    (lambda: CameraFusionParams(prior=1.0), "prior"),
    (lambda: CameraFusionParams(report_threshold=-0.1), "report_threshold"),
    (lambda: CameraFusionParams(min_confidence=1.5), "min_confidence"),
    (lambda: CameraFusionParams(hit_likelihood=0.1, false_likelihood=0.2), "hit likelihood"),
    (lambda: CameraFusionParams(class_likelihoods={"drill ": (0.7, 0.1)}), "unknown artifact class"),
    (lambda: CameraFusionParams(min_ray_hits=0), "min_ray_hits"),
    (lambda: SignalParams(raw_min=1.0, raw_max=0.0, threshold=0.5), "raw_max"),
    (lambda: SignalParams(raw_min=0.0, raw_max=1.0, threshold=0.5, cluster_distance_m=-1.0), "cluster_distance_m"),
    (lambda: SignalFusionParams(co2=SignalParams(0.0, 1.0, 0.5)), "co2.cluster_distance_m"),
    (lambda: SignalFusionParams(bluetooth_classes=("phone",)), "bluetooth_classes"),
    (lambda: CandidateParams(merge_radius_m=-1.0), "merge_radius_m"),
    (lambda: SubmissionParams(policy="fifo"), "policy"),
    (lambda: SubmissionParams(reserve_rate_per_s=-1.0), "reserve_rate_per_s"),
])
def test_bad_values_name_their_field_in_one_line(make, field):
    with pytest.raises(ValueError) as err:
        make()
    assert field in str(err.value) and "\n" not in str(err.value)
