"""Volumetric gain (Algorithm 3) and path exploration gain."""
import math

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.gain import (
    cluster_vertices,
    compute_vertex_gains,
    exploration_gains,
    ring_phase,
    sensor_rays,
    volumetric_gain,
)
from delve.planners.gbplanner2.graph import LocalGraph, shortest_paths
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

CFG = GBPlannerConfig.anymal_c()


def test_rays_cover_the_field_of_view_solid_angle():
    for cfg in (CFG, GBPlannerConfig.rmf_obelix()):
        rays = sensor_rays(cfg)
        fv = math.radians(cfg.sensor_fov_vertical_deg)
        full = 2 * math.pi * 2 * math.sin(fv / 2)
        assert rays.solid_angle_sr.sum() == pytest.approx(full)
        assert rays.count == rays.ring_bins * rays.elevation_bins


def test_no_gain_in_a_closed_fully_mapped_tunnel():
    for yaw in (0.0, 30.0):
        g, a, b = s.straight_tunnel(length_m=30, yaw_deg=yaw)
        u = (b - a) / np.linalg.norm(b - a)
        pts = a + np.outer(np.linspace(1, 26, 8), u) + np.array([0, 0, 0.5])
        assert np.all(volumetric_gain(g, pts, CFG) == 0.0)


def test_gain_is_higher_toward_unknown_space_than_at_a_mapped_dead_end():
    g, a, b = s.straight_tunnel(length_m=40, mapped_to_m=26)  # open end at ~26 m, dead end at 1 m
    u = (b - a) / np.linalg.norm(b - a)
    up = np.array([0, 0, 0.5])
    near_open = a + 22 * u + up
    middle = a + 12 * u + up
    near_dead_end = a + 1.5 * u + up
    g_open, g_mid, g_dead = volumetric_gain(g, np.stack([near_open, middle, near_dead_end]), CFG)
    assert g_open > g_mid > g_dead >= 0.0
    assert g_open > 10 * max(g_dead, 1.0)


def _box_room(shape):
    """A closed room: occupied faces, free inside."""
    occ = np.full(shape, OCCUPIED, np.int8)
    occ[1:-1, 1:-1, 1:-1] = FREE
    return occ


def test_rays_stop_at_occupied_voxels():
    occ = _box_room((60, 20, 20))
    occ[30:-1, 1:-1, 1:-1] = UNKNOWN
    grid = Grid(occ.copy(), np.zeros(3), 0.2)
    p = np.array([[3.0, 2.0, 2.0]])
    open_gain = volumetric_gain(grid, p, CFG)[0]
    occ[30] = OCCUPIED  # a one-voxel wall between the robot and the unknown
    walled = volumetric_gain(Grid(occ, np.zeros(3), 0.2), p, CFG)[0]
    assert open_gain > 0 and walled == 0.0


def test_rays_leaving_the_grid_count_the_rest_of_their_range_as_unknown():
    grid = Grid(np.full((10, 10, 10), FREE, np.int8), np.zeros(3), 0.2)
    cfg = CFG.replace(sensor_range_m=5.0)
    g = volumetric_gain(grid, np.array([[1.0, 1.0, 1.0]]), cfg)[0]
    rays = sensor_rays(cfg)
    ball = rays.solid_angle_sr.sum() * 5.0**3 / 3  # the whole sensed volume
    assert 0.6 * ball < g < ball
    # all unknown: the whole sensed volume, less the sensor's own half-step
    unknown = Grid(np.full((10, 10, 10), UNKNOWN, np.int8), np.zeros(3), 0.2)
    g_unknown = volumetric_gain(unknown, np.array([[1.0, 1.0, 1.0]]), cfg)[0]
    assert g_unknown == pytest.approx(rays.solid_angle_sr.sum() * (5.0**3 - 0.1**3) / 3, rel=1e-5)
    # all free within range: nothing to gain
    free = Grid(np.full((60, 60, 60), FREE, np.int8), np.zeros(3), 0.2)
    assert volumetric_gain(free, np.array([[6.0, 6.0, 6.0]]), cfg)[0] == 0.0


def test_limited_horizontal_fov_depends_on_heading():
    occ = _box_room((100, 100, 20))
    occ[60:-1, 1:-1, 1:-1] = UNKNOWN  # unknown to the +x side only
    grid = Grid(occ, np.zeros(3), 0.2)
    cfg = CFG.replace(sensor_fov_horizontal_deg=90.0)
    p = np.array([[10.0, 10.0, 2.0]] * 2)
    toward, away = volumetric_gain(grid, p, cfg, np.array([0.0, math.pi]))
    assert toward > 0 and away == 0


def test_rings_of_several_azimuths_in_one_call_by_their_phase():
    g, a, b = s.straight_tunnel(length_m=40, mapped_to_m=26, yaw_deg=30.0)
    u = (b - a) / np.linalg.norm(b - a)
    pts = a + np.outer([4.0, 12.0, 20.0, 23.0], u) + np.array([0, 0, 0.5])
    az = np.array([0.0, 0.7, 2.0, -1.3])
    one_by_one = [volumetric_gain(g, p[None], CFG, 0.0, float(x))[0] for p, x in zip(pts, az)]
    phases = ring_phase(CFG, az)
    assert len(set(phases.tolist())) > 1
    together = volumetric_gain(g, pts, CFG, 0.0, 0.0, ray_phase=phases)
    assert np.allclose(together, one_by_one, rtol=1e-6)
    assert together[3] > together[0] > 0


def _star_graph(hanging_last=False):
    v = np.array([[2.0, 2.0, 2.0], [3.0, 2.0, 2.0], [4.0, 2.0, 2.0], [4.3, 2.0, 2.0], [2.0, 3.0, 2.0]])
    e = np.array([[0, 1], [1, 2], [1, 3], [0, 4]])
    hang = np.array([False, False, False, False, hanging_last])
    return LocalGraph(v, e, np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1), hang)


def _open_grid():
    occ = np.full((40, 40, 20), FREE, np.int8)
    occ[30:] = UNKNOWN
    return Grid(occ, np.zeros(3), 0.2)


def test_hanging_vertex_gain_is_scaled_by_exp_minus_gamma_h():
    grid = _open_grid()
    graph = _star_graph(hanging_last=True)
    sp = shortest_paths(graph)
    gains, _ = compute_vertex_gains(grid, graph, sp, CFG)
    raw = volumetric_gain(grid, graph.vertices[4:5], CFG)[0]
    assert raw > 0
    assert gains[4] == pytest.approx(raw * math.exp(-5.0))
    assert gains[0] == 0.0  # the root


def test_leaf_only_gain_with_clustering_radius():
    grid = _open_grid()
    graph = _star_graph()
    sp = shortest_paths(graph)
    leaves = sorted(sp.leaves().tolist())
    assert leaves == [2, 3, 4]
    cfg = CFG.replace(leaf_only_gain=True, clustering_radius_m=0.0)
    gains, casts = compute_vertex_gains(grid, graph, sp, cfg)
    assert casts == 3 and gains[1] == 0.0 and np.all(gains[leaves] > 0)
    clustered = CFG.replace(leaf_only_gain=True, clustering_radius_m=1.0)
    gains_c, casts_c = compute_vertex_gains(grid, graph, sp, clustered)
    assert casts_c == 2  # vertices 2 and 3 are 0.3 m apart: one cluster
    assert gains_c[3] == gains_c[2] == pytest.approx(gains[2])
    assert gains_c[4] == pytest.approx(gains[4])
    _centres, owner = cluster_vertices(graph.vertices, 1.1)
    assert owner[0] == owner[1] == owner[4] == 0 and owner[2] == owner[3]
    all_cfg = CFG.replace(leaf_only_gain=False)
    assert compute_vertex_gains(grid, graph, sp, all_cfg)[1] == 4


def test_path_gain_discounts_distance_and_penalises_turning_back():
    v = np.array([[0.0, 0, 0], [2, 0, 0], [4, 0, 0], [-2, 0, 0], [-4, 0, 0]])
    e = np.array([[0, 1], [1, 2], [0, 3], [3, 4]])
    graph = LocalGraph(v, e, np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1), np.zeros(5, bool))
    sp = shortest_paths(graph)
    g = np.array([0.0, 0.0, 10.0, 0.0, 10.0])
    pg = exploration_gains(graph, sp, g, CFG, exploring_direction_rad=None)
    assert pg.exploration_gain[2] == pytest.approx(10 * math.exp(-CFG.path_length_penalty_per_m * 4))
    assert pg.exploration_gain[2] == pytest.approx(pg.exploration_gain[4])
    pg_dir = exploration_gains(graph, sp, g, CFG, exploring_direction_rad=0.0)
    assert pg_dir.deviation[2] == pytest.approx(0.0)
    assert pg_dir.deviation[4] == pytest.approx(2.0)
    assert pg_dir.exploration_gain[4] == pytest.approx(pg_dir.exploration_gain[2] * math.exp(-2 * CFG.path_direction_penalty))
