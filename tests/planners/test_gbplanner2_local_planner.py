"""The local planner (Algorithm 1) end to end on small synthetic worlds."""
import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.local_map import LocalMap
from delve.planners.gbplanner2.local_planner import LocalPlanner
from delve.planners.gbplanner2.path_improvement import segments_admissible
from delve.planners.geometry import path_length
from delve.planners.occupancy import OCCUPIED, UNKNOWN, Grid

LEGGED = GBPlannerConfig.anymal_c(num_vertices_max=250, num_edges_max=4000)
AERIAL = GBPlannerConfig.rmf_obelix(num_vertices_max=250)


def check_path(grid, cfg, path):
    lm = LocalMap(grid, path.min(axis=0) - 1, path.max(axis=0) + 1, cfg, clear_box_at=path[0])
    assert segments_admissible(lm, path).all()


@pytest.mark.parametrize("cfg,up,vs", [(LEGGED, 0.5, 0.2), (AERIAL, 1.5, 0.3)])
def test_path_heads_for_the_unknown_end_of_the_tunnel(cfg, up, vs):
    g, a, b = s.straight_tunnel(length_m=40, mapped_to_m=26, yaw_deg=30, voxel_size_m=vs)
    u = (b - a) / np.linalg.norm(b - a)
    p = a + 10 * u + np.array([0, 0, up])
    res = LocalPlanner(cfg).plan(g, p, np.random.default_rng(0))
    assert res.ok, res.reason
    assert res.gain > 0
    assert (res.path[-1] - res.path[0]) @ u > 5.0
    assert path_length(res.path) <= cfg.traverse_length_max_m + 1e-6
    check_path(g, cfg, res.path)
    d = res.diagnostics
    assert d.num_vertices == res.graph.num_vertices > 100
    assert d.total_s >= d.graph_s + d.gain_s + d.shortest_paths_s
    assert res.direction_rad is not None


def test_same_inputs_and_seed_give_the_same_result():
    g, a, _b = s.straight_tunnel(length_m=30, mapped_to_m=20)
    p = a + np.array([8.0, 0, 0.5])
    lp = LocalPlanner(LEGGED)
    r1 = lp.plan(g, p, np.random.default_rng(42))
    r2 = lp.plan(g, p, np.random.default_rng(42))
    assert np.array_equal(r1.path, r2.path) and r1.gain == r2.gain
    assert np.array_equal(r1.graph.vertices, r2.graph.vertices)


#: One iteration's outcome for a fixed map and seed, recorded before the speed-ups of
#: issue 17 (item 5): vertices, edges, hanging vertices, chosen vertex, path gain, gain
#: casts, samples drawn, sum of vertex gains, sum of edge lengths, and the path. A
#: faster planner must plan exactly the same.
PINNED = {
    "legged": (250, 1696, 0, 192, 11507.818630570599, 249, 1125, 187434.106232961, 1297.331750687208,
               [[15.526, 11.5, 1.5], [17.553, 12.789, 1.5], [19.58, 14.077, 1.5], [21.608, 15.366, 1.5],
                [23.635, 16.654, 1.5]]),
    "aerial": (250, 1740, 0, 2, 1631.0304816849025, 59, 852, 124875.02544962379, 1880.041777868778,
               [[15.526, 11.5, 2.5], [18.335, 12.932, 2.491], [21.143, 14.365, 2.481], [23.952, 15.797, 2.472]]),
    "shaft": (300, 1848, 21, 166, 47.57107765822729, 299, 17224, 846.1461831525198, 855.7255034570046,
              [[8.0, 4.0, 7.5], [9.388, 4.745, 7.5], [10.775, 5.49, 7.5]]),
}


def _pinned_case(name):
    if name == "shaft":
        g, west, hole = s.shaft_tunnel()
        p = np.array([hole.lo[0] - 2.5, west[1], west[2] + 0.5])
        return LocalPlanner(LEGGED.replace(num_vertices_max=300)).plan(g, p, np.random.default_rng(2))
    cfg, up, vs = (LEGGED, 0.5, 0.2) if name == "legged" else (AERIAL, 1.5, 0.3)
    g, a, b = s.straight_tunnel(length_m=40, mapped_to_m=26, yaw_deg=30, voxel_size_m=vs)
    u = (b - a) / np.linalg.norm(b - a)
    return LocalPlanner(cfg).plan(g, a + 10 * u + np.array([0, 0, up]), np.random.default_rng(5), yaw_rad=0.5)


@pytest.mark.parametrize("name", sorted(PINNED))
def test_a_fixed_map_and_seed_give_the_pinned_plan(name):
    r = _pinned_case(name)
    n_v, n_e, n_hang, best, gain, casts, samples, vgain_sum, length_sum, path = PINNED[name]
    g = r.graph
    assert (g.num_vertices, g.num_edges, int(g.hanging.sum()), r.best_vertex) == (n_v, n_e, n_hang, best)
    assert (r.diagnostics.num_gain_evaluations, r.diagnostics.num_samples) == (casts, samples)
    assert r.gain == pytest.approx(gain, rel=1e-9)
    assert float(r.vertex_gains.sum()) == pytest.approx(vgain_sum, rel=1e-9)
    assert float(g.lengths.sum()) == pytest.approx(length_sum, rel=1e-9)
    assert np.allclose(r.path, path, atol=1e-3)


def test_legged_paths_never_end_at_or_cross_hanging_vertices():
    g, west, hole = s.shaft_tunnel()
    p = np.array([hole.lo[0] - 2.5, west[1], west[2] + 0.5])
    cfg = LEGGED.replace(num_vertices_max=300)
    for seed in range(3):
        res = LocalPlanner(cfg).plan(g, p, np.random.default_rng(seed))
        graph = res.graph
        assert graph.hanging.any()
        if res.ok:
            assert not graph.hanging[res.vertex_path].any()
            # never over the shaft (the ground circle reaches a little past its rim)
            assert np.all(res.path[:, 0] < hole.lo[0] + cfg.ground_circle_radius_m + 0.05)
            check_path(g, cfg, res.path)


def test_unplannable_situations_return_a_reason_instead_of_raising():
    g, a, _b = s.straight_tunnel(length_m=20)
    lp = LocalPlanner(LEGGED)
    rng = np.random.default_rng(0)
    outside = lp.plan(g, np.array([-50.0, 0, 0]), rng)
    assert outside.path is None and "outside" in outside.reason
    in_rock = lp.plan(g, a + np.array([5.0, 0, -0.1]), rng)
    assert in_rock.path is None and "start position is invalid" in in_rock.reason
    nan = lp.plan(g, np.array([np.nan, 0, 0]), rng)
    assert nan.path is None and nan.reason
    empty = Grid(np.full((50, 50, 20), UNKNOWN, np.int8), np.zeros(3), 0.2)
    r = lp.plan(empty, np.array([5.0, 5.0, 2.0]), rng)
    assert r.path is None and r.reason
    closed = np.full((40, 40, 20), OCCUPIED, np.int8)
    closed[18:23, 18:23, 8:13] = 0
    r = LocalPlanner(AERIAL).plan(Grid(closed, np.zeros(3), 0.2), np.array([4.1, 4.1, 2.1]), rng)
    assert r.path is None and r.reason


def test_fully_explored_tunnel_gives_no_gain_path():
    g, a, _b = s.straight_tunnel(length_m=24)
    res = LocalPlanner(LEGGED).plan(g, a + np.array([8.0, 0, 0.5]), np.random.default_rng(0))
    assert res.path is None and "gain" in res.reason
    assert res.graph is not None and res.graph.num_vertices > 1


def test_exploration_bounds_keep_vertices_inside():
    g, a, _b = s.straight_tunnel(length_m=30, mapped_to_m=20)
    p = a + np.array([8.0, 0, 0.5])
    lo, hi = a + np.array([4.0, -5, -5]), a + np.array([12.0, 5, 5])
    res = LocalPlanner(LEGGED).plan(g, p, np.random.default_rng(0), exploration_bounds=(lo, hi))
    v = res.graph.vertices[1:]
    assert np.all((v >= lo) & (v <= hi))


def test_unseen_ground_right_under_a_legged_robot_counts_as_ground():
    # A LiDAR on the body cannot see the floor within a couple of metres of the robot.
    g, a, _b = s.straight_tunnel(length_m=30, mapped_to_m=24)
    p = a + np.array([8.0, 0, 0.5])
    occ = g.occupancy.copy()
    lo = g.to_index((p - np.array([1.8, 1.8, 0.7]))[None])[0]
    hi = g.to_index((p + np.array([1.8, 1.8, -0.45]))[None])[0]
    floor = occ[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2] + 1]
    floor[floor == OCCUPIED] = UNKNOWN
    blind = Grid(occ, g.origin, g.voxel_size_m)
    assert blind.value_at((p - np.array([0, 0, 0.6]))[None])[0] == UNKNOWN
    ok = LocalPlanner(LEGGED).plan(blind, p, np.random.default_rng(0))
    assert ok.ok, ok.reason
    strict = LocalPlanner(LEGGED.replace(assumed_ground_radius_m=0.0)).plan(blind, p, np.random.default_rng(0))
    assert not strict.ok


def test_shrinking_local_planner_refills_a_graph_starved_box(monkeypatch):
    """A 2 m wide tunnel in a wide, mostly rock and unknown local box: graph building
    stops after its first batch of samples, and the smaller box fills with vertices."""
    import delve.planners.gbplanner2.local_planner as lp
    from delve.planners.gbplanner2 import LocalBound

    grid, a, _ = s.straight_tunnel(length_m=40, width_m=2.0)
    p = np.asarray(a, float) + np.array([10.0, 0.0, 0.5])
    # ANYmal C fitted to a 0.4 m radius robot on 0.2 m voxels (as the Explore skill fits it).
    cfg = GBPlannerConfig.preset("legged").with_robot_limits(
        speed_mps=1.0, body_height_m=0.5, radius_m=0.3, max_inclination_deg=35.0,
        max_step_m=0.3).replace(num_vertices_max=150, num_edges_max=2500)
    huge = LocalBound(p, np.eye(3), np.array([17.5, 17.5, 8.0]))
    monkeypatch.setattr(lp, "adaptive_local_bound", lambda *args, **kwargs: huge)
    starved = lp.LocalPlanner(cfg).plan(grid, p, np.random.default_rng(0))
    assert starved.graph.num_vertices < lp.ShrinkingLocalPlanner.min_vertices
    res = lp.ShrinkingLocalPlanner(cfg).plan(grid, p, np.random.default_rng(0))
    assert res.graph.num_vertices >= lp.ShrinkingLocalPlanner.min_vertices
    assert np.all(res.graph.bound.half_extents_m < huge.half_extents_m)
