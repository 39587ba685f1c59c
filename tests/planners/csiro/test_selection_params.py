"""delve.planners.csiro.selection_params: the paper's values and one-line errors."""
from __future__ import annotations

import pytest
from delve.planners.csiro.selection_params import CsiroSelectionParams


def test_defaults_are_the_papers():
    p = CsiroSelectionParams()
    assert (p.eta_norm_deg, p.eta_trav_m, p.observer_spacing_m) == (30.0, 0.5, 0.8)
    assert (p.rho, p.eta_d_m, p.trajectory_period_s, p.share_period_s) == (0.2, 6.0, 5.0, 5.0)
    assert (p.progress_m, p.progress_window_s) == (1.0, 15.0)
    assert (p.uav_same_frontier_gain, p.uav_momentum_weight, p.uav_z_weight) == (4.0, 2.0, 2.0)
    assert (p.uav_max_size_m, p.uav_blacklist_m, p.uav_min_area_m2) == (5.0, 3.0, 1.7)
    assert p.reduced_dynamic_range


@pytest.mark.parametrize("field, value, message", [
    ("eta_norm_deg", 0.0, "eta_norm_deg: 0.0 must be in (0, 90)"),
    ("eta_norm_deg", 90.0, "eta_norm_deg: 90.0 must be in (0, 90)"),
    ("eta_trav_m", -0.5, "eta_trav_m: -0.5 must be > 0"),
    ("eta_d_m", 0.0, "eta_d_m: 0.0 must be > 0"),
    ("progress_window_s", 0.0, "progress_window_s: 0.0 must be > 0"),
    ("rho", 0.0, "rho: 0.0 must be in (0, 1]"),
    ("rho_fail", 1.5, "rho_fail: 1.5 must be in (0, 1]"),
    ("uav_momentum_weight", 0.5, "uav_momentum_weight: 0.5 must be >= 1"),
    ("uav_min_area_m2", -1.0, "uav_min_area_m2: -1.0 must be >= 0"),
])
def test_out_of_range_values_raise_one_line(field, value, message):
    with pytest.raises(ValueError) as err:
        CsiroSelectionParams(**{field: value})
    assert str(err.value) == message
