"""GBPlanner2 configuration: Table I presets and validation."""
import math

import pytest
from delve.planners.gbplanner2.config import ANYMAL_C, RMF_OBELIX, GBPlannerConfig


def test_anymal_c_preset_matches_table_1():
    c = GBPlannerConfig.anymal_c()
    assert c.robot_type == "legged"
    assert c.voxel_size_m == 0.2
    assert c.num_vertices_max == 1000
    assert (c.sensor_fov_horizontal_deg, c.sensor_fov_vertical_deg) == (360.0, 30.0)
    assert c.sensor_range_m == 30.0
    assert c.clustering_radius_m == 0.0 and not c.clustering_enabled
    assert c.hanging_vertex_penalty == 5.0
    assert math.isclose(c.hanging_gain_factor, math.exp(-5.0))
    assert c.local_pointcloud_range_m == 50.0  # mu_V


def test_rmf_obelix_preset_matches_table_1():
    c = GBPlannerConfig.rmf_obelix()
    assert c.robot_type == "aerial"
    assert c.voxel_size_m == 0.3
    assert c.num_vertices_max == 500
    assert (c.sensor_fov_horizontal_deg, c.sensor_fov_vertical_deg) == (360.0, 90.0)
    assert c.sensor_range_m == 30.0
    assert c.clustering_radius_m == 1.0 and c.clustering_enabled
    assert c.hanging_vertex_penalty == 5.0


def test_preset_by_name_and_alias_with_overrides():
    assert GBPlannerConfig.preset("legged") == GBPlannerConfig.anymal_c()
    assert GBPlannerConfig.preset("aerial") == GBPlannerConfig.rmf_obelix()
    c = GBPlannerConfig.preset("anymal_c", num_vertices_max=200)
    assert c.num_vertices_max == 200 and c.voxel_size_m == ANYMAL_C["voxel_size_m"]
    assert RMF_OBELIX["num_vertices_max"] == 500
    with pytest.raises(ValueError, match="unknown GBPlanner2 preset"):
        GBPlannerConfig.preset("spot")


@pytest.mark.parametrize(
    "change",
    [
        {"sensor_fov_horizontal_deg": 400.0},
        {"sensor_fov_vertical_deg": 0.0},
        {"num_vertices_max": 0},
        {"edge_length_max_m": -1.0},
        {"edge_length_min_m": 5.0},
        {"robot_type": "wheeled"},
        {"max_inclination_deg": 95.0},
        {"robot_box_size_m": (0.5, 0.5)},
        {"gain_ray_step_voxels": 2.0},
        {"clustering_radius_m": -1.0},
        {"num_edges_max": 1.5},
        {"sensor_range_m": float("nan")},
    ],
)
def test_invalid_configuration_raises_value_error(change):
    with pytest.raises(ValueError):
        GBPlannerConfig(**change)


def test_yaml_style_overrides_lists_and_unknown_names():
    c = GBPlannerConfig.preset("legged", robot_box_size_m=[0.6, 0.6, 0.2])
    assert c.robot_box_size_m == (0.6, 0.6, 0.2)
    hash(c)  # stays hashable
    with pytest.raises(ValueError, match="unknown GBPlannerConfig parameter"):
        GBPlannerConfig.preset("aerial", num_vertex=3)
    with pytest.raises(ValueError, match="true or false"):
        GBPlannerConfig.anymal_c(leaf_only_gain="yes")


def test_replace_rejects_unknown_parameters_and_validates():
    c = GBPlannerConfig.anymal_c()
    assert c.replace(num_vertices_max=300).num_vertices_max == 300
    with pytest.raises(ValueError, match="unknown"):
        c.replace(vertices=3)
    with pytest.raises(ValueError):
        c.replace(speed_mps=0.0)


def test_with_robot_limits_adapts_box_and_limits():
    c = GBPlannerConfig.anymal_c().with_robot_limits(
        speed_mps=0.8, body_height_m=0.55, radius_m=0.35, max_inclination_deg=35.0, max_step_m=0.25
    )
    assert c.speed_mps == 0.8 and c.body_height_m == 0.55
    assert c.robot_box_size_m[:2] == (0.7, 0.7)
    assert c.max_inclination_deg == 35.0 and c.max_step_m == 0.25
    a = GBPlannerConfig.rmf_obelix().with_robot_limits(max_inclination_deg=10.0)
    assert a.max_inclination_deg == GBPlannerConfig.rmf_obelix().max_inclination_deg  # not for aerial
