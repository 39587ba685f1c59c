"""The global planner: global graph, repositioning, homing, goals."""
import networkx as nx
import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.global_planner import GlobalPlanner
from delve.planners.gbplanner2.local_map import LocalMap
from delve.planners.gbplanner2.local_planner import LocalPlanner, LocalPlanResult, PlanDiagnostics
from delve.planners.gbplanner2.path_improvement import segments_admissible
from delve.planners.geometry import path_length
from delve.planners.occupancy import OCCUPIED, Grid

CFG = GBPlannerConfig.anymal_c(num_vertices_max=200, num_edges_max=3000, low_gain_iterations_max=3)


@pytest.fixture(scope="module")
def tunnel():
    """A 60 m tunnel mapped to 40 m (open, unknown beyond); home near the west end."""
    g, a, _b = s.straight_tunnel(length_m=60, mapped_to_m=40)
    home = a + np.array([2.0, 0, 0.5])
    return g, a, home


def explored(tunnel, positions, seed=0):
    g, _a, home = tunnel
    gp = GlobalPlanner(CFG, home)
    lp = LocalPlanner(CFG)
    results = []
    for i, p in enumerate(positions):
        r = lp.plan(g, p, np.random.default_rng(seed + i))
        gp.add_local_result(r, g)
        results.append(r)
    return gp, results


def low_gain_result(root, gain):
    return LocalPlanResult(path=None, gain=gain, reason="test", diagnostics=PlanDiagnostics(), root=root)


def test_frontiers_are_recorded_where_the_gain_is(tunnel):
    _g, a, _home = tunnel
    gp, (_r,) = explored(tunnel, [a + np.array([25.0, 0, 0.5])])
    assert gp.frontiers
    for f in gp.frontiers.values():
        assert f.gain >= CFG.frontier_gain_min_m3
        assert gp.graph.nodes[f.vertex]["kind"] == "frontier"
    assert gp.graph.number_of_nodes() > 3
    assert len(gp.frontiers) <= CFG.frontiers_per_iteration_max


def test_the_goal_of_a_local_path_the_robot_did_not_reach_becomes_a_frontier(tunnel):
    _g, a, home = tunnel
    gp, (r,) = explored(tunnel, [a + np.array([25.0, 0, 0.5])])
    start, goal = gp.robot_vertex, r.graph.vertices[r.best_vertex]
    assert r.vertex_gains[r.best_vertex] >= CFG.frontier_gain_min_m3 and not r.graph.hanging[r.best_vertex]
    assert all(np.linalg.norm(f.position - goal) >= CFG.frontier_spacing_m for f in gp.frontiers.values())
    before = set(gp.frontiers)
    f = gp.add_unreached_goal(r, start)
    assert f is not None and set(gp.frontiers) == before | {f.vertex}
    assert np.linalg.norm(f.position - goal) < CFG.global_vertex_merge_radius_m + 1e-9
    assert gp.graph.nodes[f.vertex]["kind"] == "frontier" and f.gain == r.vertex_gains[r.best_vertex]
    way = np.array([gp.position_of(v) for v in nx.shortest_path(gp.graph, start, f.vertex, weight="weight")])
    assert len(way) > 1 and segments_admissible(r.local_map, way).all()   # joined by its path
    assert nx.has_path(gp.graph, gp.home_vertex, f.vertex)
    assert gp.add_unreached_goal(r, start) is None                          # one there already
    del gp.frontiers[f.vertex]
    r.graph.hanging[r.best_vertex] = True
    assert gp.add_unreached_goal(r, start) is None                          # no ground under it
    r.graph.hanging[r.best_vertex] = False
    r.vertex_gains[r.best_vertex] = CFG.frontier_gain_min_m3 - 1
    assert gp.add_unreached_goal(r, start) is None                          # too little gain left


def test_repositioning_after_k_low_gain_iterations(tunnel):
    g, a, home = tunnel
    far = a + np.array([30.0, 0, 0.5])
    gp, _ = explored(tunnel, [home + np.array([6.0, 0, 0]), far])
    gp.low_gain_iterations = 0
    robot = home + np.array([1.0, 0, 0])
    for k in range(CFG.low_gain_iterations_max):
        assert not gp.reposition_due
        gp.add_local_result(low_gain_result(robot, gain=CFG.low_gain_threshold_m3 / 2))
    assert gp.reposition_due
    before = dict(gp.frontiers)
    rep = gp.plan_reposition(g, robot)
    assert rep.ok, rep.reason
    assert rep.kind == "reposition" and rep.gain > 0
    assert np.allclose(rep.path[0], robot)
    assert np.linalg.norm(rep.path[-1] - rep.target) < 1e-9
    # the chosen frontier is the best by gain / (path length + offset)
    chosen = [v for v in before if v not in gp.frontiers]
    assert len(chosen) == 1
    assert not gp.reposition_due
    # a good iteration resets the count
    gp.add_local_result(low_gain_result(robot, gain=1e6))
    assert gp.low_gain_iterations == 0


def test_reposition_respects_the_endurance(tunnel):
    g, a, home = tunnel
    gp, _ = explored(tunnel, [a + np.array([30.0, 0, 0.5])])
    rep = gp.plan_reposition(g, home, endurance_remaining_s=5.0)
    assert not rep.ok and "endurance" in rep.reason


def test_a_frontier_cut_off_from_home_on_the_graph_is_judged_by_the_straight_line_home(tunnel):
    """An edge found blocked cut the robot's part of the graph from home's: its frontiers
    are still explored when the endurance covers the way to them and the straight line
    home (as the homing check estimates it), and not when it does not."""
    g, a, home = tunnel
    p = a + np.array([30.0, 0, 0.5])
    gp, _ = explored(tunnel, [p])
    assert gp.frontiers
    gp.graph.remove_edges_from(list(gp.graph.edges(gp.home_vertex)))
    assert not nx.has_path(gp.graph, gp.robot_vertex, gp.home_vertex)
    assert gp.plan_reposition(g, p, endurance_remaining_s=3600.0).ok
    short = np.linalg.norm(p - home) / CFG.speed_mps + CFG.homing_margin_s
    assert not gp.plan_reposition(g, p, endurance_remaining_s=short).ok


def test_homing_triggers_only_when_endurance_is_short(tunnel):
    g, a, home = tunnel
    p = a + np.array([30.0, 0, 0.5])
    gp, _ = explored(tunnel, [home + np.array([8.0, 0, 0]), a + np.array([20.0, 0, 0.5]), p])
    way = gp.plan_home(g, p)
    assert way.ok, way.reason
    assert np.allclose(way.path[-1], home) and np.allclose(way.path[0], p)
    assert path_length(way.path) >= np.linalg.norm(p - home) - 1e-6
    long = gp.homing_check(g, p, endurance_remaining_s=3600.0)
    assert not long.required
    t_home = way.length_m / CFG.speed_mps
    short = gp.homing_check(g, p, endurance_remaining_s=t_home + CFG.homing_margin_s)
    assert short.required
    assert short.time_home_s == pytest.approx(t_home)
    lm = LocalMap(g, way.path.min(axis=0) - 1, way.path.max(axis=0) + 1, CFG)
    assert segments_admissible(lm, way.path).all()


def test_path_to_a_goal_point_and_blocked_edges(tunnel):
    g, a, _home = tunnel
    p = a + np.array([4.0, 0, 0.5])
    gp, _ = explored(tunnel, [p, a + np.array([16.0, 0, 0.5])])
    goal = a + np.array([22.0, 0.5, 0.5])
    res = gp.plan_to_goal(g, p, goal)
    assert res.ok, res.reason
    assert np.allclose(res.path[0], p) and np.allclose(res.path[-1], goal)
    near = gp.plan_to_goal(g, p, p + np.array([2.0, 0, 0]))
    assert near.ok and len(near.path) == 2
    # rock across the tunnel, mapped after the graph was built: no way through
    occ = g.occupancy.copy()
    i = g.to_index((a + np.array([12.0, 0, 0]))[None])[0]
    occ[i[0]:i[0] + 2, :, :] = OCCUPIED
    blocked = Grid(occ, g.origin, g.voxel_size_m)
    res2 = gp.plan_to_goal(blocked, p, goal)
    assert not res2.ok and res2.reason
    outside = gp.plan_to_goal(g, p, np.array([1e4, 0, 0]))
    assert not outside.ok and "outside" in outside.reason


def test_frontiers_are_dropped_once_explored(tunnel):
    _g, a, home = tunnel
    gp, _ = explored(tunnel, [a + np.array([30.0, 0, 0.5])])
    assert gp.frontiers
    mapped, _, _ = s.straight_tunnel(length_m=60)
    gp.update_frontiers(mapped)
    assert not gp.frontiers
    assert not gp.plan_reposition(mapped, home).ok


def test_new_vertices_are_joined_to_their_neighbours(tunnel):
    """Out along one side of the tunnel and back along the other: the global graph joins
    the two tracks where an admissible edge does (gbplanner's RRG), so the way between
    them is not the way the robot came."""
    g, a, home = tunnel
    out = home + np.array([[x, 0.8, 0] for x in np.arange(1.0, 30.0, 1.5)])
    back = home + np.array([[x, -0.8, 0] for x in np.arange(28.5, 1.0, -1.5)])

    def across(grid, paths=(out, back)):
        """Graph distance between the two tracks 20 m in, after driving ``paths``."""
        gp = GlobalPlanner(CFG, home)
        lm = None if grid is None else LocalMap(grid, a - 2, a + np.array([42.0, 2, 2]), CFG)
        for path in paths:
            gp.add_local_result(LocalPlanResult(path=path, gain=1e3, reason="", diagnostics=PlanDiagnostics(),
                                                root=path[0], local_map=lm))
        u, v = (int(np.argmin(np.linalg.norm(gp.positions - (home + [20.0, y, 0]), axis=1))) for y in (0.8, -0.8))
        return nx.shortest_path_length(gp.graph, u, v, weight="weight")

    assert across(g) < 2.5
    assert across(g, paths=(np.concatenate([out, back]),)) < 2.5  # new vertices joined to each other
    assert across(None) > 15.0  # no map to check edges on: the track only
    # rock along the tunnel's axis beyond 2 m: the tracks are not joined through it
    occ = g.occupancy.copy()
    i, j, _ = g.to_index(home[None])[0]
    occ[i + 10:, j - 1:j + 2, :] = OCCUPIED
    assert across(Grid(occ, g.origin, g.voxel_size_m)) > 15.0


def test_recorded_positions_are_joined_to_their_neighbours(tunnel):
    """A position recorded with the map (each plan, a COHORT transit) is joined to the
    vertices beside it; without the map only to the last one."""
    g, _a, home = tunnel

    def across(grid):
        gp = GlobalPlanner(CFG, home)
        for x, y in [(x, 0.8) for x in np.arange(2.0, 20.0, 2.0)] + [(x, -0.8) for x in np.arange(18.0, 0.0, -2.0)]:
            gp.record_position(home + [x, y, 0], grid)
        u, v = (int(np.argmin(np.linalg.norm(gp.positions - (home + [10.0, y, 0]), axis=1))) for y in (0.8, -0.8))
        return nx.shortest_path_length(gp.graph, u, v, weight="weight")

    assert across(g) < 2.5
    assert across(None) > 15.0


def test_invalid_home_raises():
    with pytest.raises(ValueError):
        GlobalPlanner(CFG, np.array([np.nan, 0, 0]))
