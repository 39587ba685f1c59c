"""The random local graph (Algorithm 2) and its shortest paths."""

import numpy as np
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.bounds import adaptive_local_bound
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.graph import (
    LocalGraph,
    build_local_graph,
    shortest_paths,
    thin_samples,
)
from delve.planners.gbplanner2.local_map import GROUND_ATTACHED, LocalMap
from delve.planners.occupancy import FREE, OCCUPIED

LEGGED = GBPlannerConfig.anymal_c(num_vertices_max=250, num_edges_max=4000)
AERIAL = GBPlannerConfig.rmf_obelix(num_vertices_max=250)


def make(grid, position, cfg, seed=0):
    box = adaptive_local_bound(grid, position, cfg)
    lo, hi = box.aabb()
    lm = LocalMap(grid, np.minimum(lo, position), np.maximum(hi, position), cfg, clear_box_at=position)
    return lm, build_local_graph(lm, position, box, cfg, np.random.default_rng(seed))


def brute_force_box_free(grid, points, cfg):
    half = np.ceil(0.5 * np.asarray(cfg.robot_box_size_m) / grid.voxel_size_m + 0.5).astype(int) - 1
    out = []
    for i in grid.to_index(points):
        lo, hi = i - half, i + half + 1
        box = grid.occupancy[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        out.append(bool(np.all(box == FREE)))
    return np.array(out)


def test_aerial_vertices_and_edges_are_collision_free():
    g, a, b = s.straight_tunnel(length_m=30, width_m=4, height_m=3, voxel_size_m=0.3, yaw_deg=20)
    p = (a + b) / 2 + np.array([0, 0, 1.5])
    lm, graph = make(g, p, AERIAL)
    assert graph.num_vertices == AERIAL.num_vertices_max
    assert np.allclose(graph.vertices[0], p)
    assert brute_force_box_free(g, graph.vertices[1:], AERIAL).all()
    assert lm.check_edges(graph.vertices[graph.edges[:, 0]], graph.vertices[graph.edges[:, 1]]).admissible.all()
    assert np.all(graph.lengths <= AERIAL.edge_length_max_m + 1e-9)
    assert not graph.hanging.any()
    sp = shortest_paths(graph)
    assert sp.reachable.all()  # G_L is connected to the robot


def test_legged_vertices_lie_on_the_ground_at_body_height():
    g, a, b = s.straight_tunnel(length_m=30, width_m=4, height_m=3)
    p = (a + b) / 2 + np.array([0, 0, LEGGED.body_height_m])
    _lm, graph = make(g, p, LEGGED)
    v = graph.vertices[~graph.hanging]
    assert len(v) == graph.num_vertices
    assert np.allclose(v[:, 2], a[2] + LEGGED.body_height_m)
    below = v - np.array([0, 0, LEGGED.body_height_m + 0.1])
    assert np.all(g.value_at(below) == OCCUPIED)
    assert brute_force_box_free(g, v[1:], LEGGED).all()


def test_legged_graph_climbs_gentle_slopes_and_refuses_steep_ones():
    # A 1.4 m wide ramp leaves the 1 m robot box no room to zig-zag up a steep slope
    # (in a wide tunnel, edges across a steep slope can be gentle enough).
    for angle, width, climbs in ((15.0, 4.0, True), (25.0, 4.0, True), (25.0, 1.4, True), (45.0, 1.4, False)):
        g, bottom, top = s.slope_tunnel(angle, slope_m=6.0, width_m=width)
        p = bottom + np.array([-2.0, 0, LEGGED.body_height_m])
        lm, graph = make(g, p, LEGGED.replace(max_inclination_deg=30.0))
        on_top = graph.vertices[:, 0] > top[0] + 0.5
        assert on_top.any() == climbs, (angle, width)
        # every vertex still sits on supported ground
        _gz, st = lm.project_to_ground(graph.vertices[~graph.hanging])
        assert np.all(st == GROUND_ATTACHED)
        # every edge's own inclination is within the limit
        e = graph.edges
        d = graph.vertices[e[:, 1]] - graph.vertices[e[:, 0]]
        incl = np.degrees(np.arctan2(np.abs(d[:, 2]), np.hypot(d[:, 0], d[:, 1])))
        assert incl.max() <= 30.0 + 1e-6


def test_hanging_vertices_over_a_shaft_are_path_ends_only():
    g, west, hole = s.shaft_tunnel()
    p = np.array([hole.lo[0] - 2.5, west[1], west[2] + LEGGED.body_height_m])
    _lm, graph = make(g, p, LEGGED.replace(num_vertices_max=300))
    hanging = np.flatnonzero(graph.hanging)
    assert len(hanging) > 0
    hv = graph.vertices[hanging]
    assert np.all((hv[:, 0] > hole.lo[0] - 0.5) & (hv[:, 0] < hole.hi[0] + 0.5))
    sp = shortest_paths(graph)
    # no shortest path passes through a hanging vertex
    assert not np.any(graph.hanging[sp.predecessor[sp.predecessor >= 0]])
    adj = graph.directed_adjacency()
    assert adj[hanging].nnz == 0


def test_graph_respects_vertex_and_edge_limits():
    g, a, b = s.straight_tunnel(length_m=30, width_m=4, height_m=3, voxel_size_m=0.3)
    p = (a + b) / 2 + np.array([0, 0, 1.5])
    _lm, graph = make(g, p, AERIAL.replace(num_vertices_max=120, num_edges_max=150))
    assert graph.num_vertices <= 120
    assert graph.num_edges <= 150
    assert shortest_paths(graph).reachable.all()


def test_same_seed_same_graph_other_seed_other_graph():
    g, a, b = s.straight_tunnel(length_m=30, width_m=4, height_m=3)
    p = (a + b) / 2 + np.array([0, 0, LEGGED.body_height_m])
    _, g1 = make(g, p, LEGGED, seed=7)
    _, g2 = make(g, p, LEGGED, seed=7)
    _, g3 = make(g, p, LEGGED, seed=8)
    assert np.array_equal(g1.vertices, g2.vertices) and np.array_equal(g1.edges, g2.edges)
    assert not np.array_equal(g1.vertices, g3.vertices)


def test_thinning_keeps_the_sequential_rule():
    rng = np.random.default_rng(3)
    pts = rng.uniform(0, 2, size=(400, 3))
    keep = thin_samples(pts, 0.3)
    kept = []
    for i, p in enumerate(pts):  # the sequential rule, one sample at a time
        if all(np.linalg.norm(p - pts[j]) >= 0.3 for j in kept):
            kept.append(i)
    assert np.flatnonzero(keep).tolist() == kept


def test_shortest_paths_and_leaves():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0]], float)
    e = np.array([[0, 1], [1, 2], [1, 3]])
    graph = LocalGraph(v, e, np.array([1.0, 1.0, 1.0]), np.array([False, False, False, True]))
    sp = shortest_paths(graph)
    assert sp.path(2) == [0, 1, 2]
    assert sp.distance_m.tolist() == [0.0, 1.0, 2.0, 2.0]
    assert sorted(sp.leaves().tolist()) == [2, 3]
