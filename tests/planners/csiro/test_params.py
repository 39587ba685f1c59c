import dataclasses
import math

import pytest

from delve.planners.csiro.params import CsiroFrontierParams


def test_defaults_are_the_papers_values():
    p = CsiroFrontierParams()
    assert (p.d_vox_m, p.d_max_m, p.eta_subsample_m, p.gamma, p.eta_disc_m, p.eta_area_m2) == \
        (0.3, 9.0, 1.5, -0.018, 0.8, 0.2)
    assert (p.d_min_m, p.t_min_s, p.d_vp_m, p.eta_vis_m) == (1.0, 0.5, 5.0, 0.005)
    assert math.isclose(p.sphere_spacing_rad, 0.4 / 9.0)
    assert not p.blind_frontiers                     # the sphere limited to the sensor's elevations (eq. 2)


@pytest.mark.parametrize("field, value, words", [
    ("gamma", 0.0, "gamma must be negative"),
    ("gamma", 0.5, "gamma must be negative"),
    ("d_max_m", -1.0, "d_max_m must be > 0"),
    ("d_vox_m", 0.0, "d_vox_m must be > 0"),
    ("eta_area_m2", -0.2, "eta_area_m2 must be > 0"),
    ("d_min_m", -1.0, "d_min_m must be >= 0"),
    ("eta_subsample_m", 10.0, "eta_subsample_m (10.0) must not exceed d_max_m"),
    ("elevation_min_deg", 20.0, "elevation_min_deg (20.0) must be below"),
    ("elevation_max_deg", 120.0, "elevation_max_deg must be within [-90, 90]"),
    ("eta_dia_m", float("nan"), "eta_dia_m must be a number"),
    ("blind_frontiers", 1, "blind_frontiers must be true or false"),
])
def test_out_of_range_values_raise_a_clear_value_error(field, value, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
        CsiroFrontierParams(**{field: value})


def test_replace_checks_again():
    with pytest.raises(ValueError, match="gamma"):
        dataclasses.replace(CsiroFrontierParams(), gamma=1.0)
