"""delve.planners.gbplanner2.link_loss: the gain beyond the points where the radio link
was lost, on a shortest-path tree, on a graph, and in a planning iteration."""
import networkx as nx
import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.link_loss import LinkLoss, beyond_in_tree, near_points, segments_near
from delve.planners.gbplanner2.planner import GBPlanner

CFG = GBPlannerConfig.anymal_c(num_vertices_max=200, num_edges_max=3000)

#: A tree along x: root 0 at x=0, a chain 0-1-2-3 (x = 2, 4, 6), a branch 0-4-5 along y.
POSITIONS = np.array([[0, 0, 0], [2, 0, 0], [4, 0, 0], [6, 0, 0], [0, 2, 0], [0, 4, 0]], float)
PREDECESSOR = np.array([-9999, 0, 1, 2, 0, 4])


def test_near_points_and_the_vertices_beyond_them_in_a_tree():
    near = near_points(POSITIONS, np.array([[4.2, 0.3, 0.0]]), 1.0)
    assert near.tolist() == [False, False, True, False, False, False]
    assert beyond_in_tree(near, PREDECESSOR).tolist() == [False, False, True, True, False, False]
    assert not beyond_in_tree(np.zeros(6, bool), PREDECESSOR).any()
    assert not near_points(POSITIONS, np.zeros((0, 3)), 1.0).any()


def test_the_gain_beyond_a_link_loss_is_discounted_but_not_the_rest():
    gains = np.array([0.0, 10.0, 20.0, 30.0, 5.0, 6.0])
    loss = LinkLoss(np.array([[4.0, 0.0, 0.0]]), radius_m=1.0, gain_factor=0.1)
    assert loss.discount_tree(POSITIONS, PREDECESSOR, gains) == pytest.approx([0, 10, 2, 3, 5, 6])
    # The robot stands by a point (it backed off until it heard the base again): only
    # what lies toward the point is beyond it, not the rest around the robot.
    by_root = LinkLoss(np.array([[0.5, 0.0, 0.0]]), radius_m=1.0, gain_factor=0.0)
    assert by_root.discount_tree(POSITIONS, PREDECESSOR, gains) == pytest.approx([0, 0, 0, 0, 5, 6])


def test_segments_near_a_point_and_coming_nearer_it():
    starts, ends = np.zeros((3, 3)), np.array([[4.0, 0, 0], [0, 4.0, 0], [-1.0, 0, 0]])
    point = np.array([[2.0, 0.5, 0.0]])
    assert segments_near(starts, ends, point, 1.0).tolist() == [True, False, False]
    assert segments_near(starts, ends, point, 3.0).tolist() == [True, True, True]
    # only the steps that end nearer the point than 2.1 m (the root's distance) or pass
    # within half of that
    assert segments_near(starts, ends, point, 3.0, np.array([2.1])).tolist() == [True, False, False]
    through = np.array([[3.0, 0.5, 0.0]])  # passes 0 m from the point, ends 1 m from it
    assert segments_near(np.zeros((1, 3)), through, point, 3.0, np.array([0.9])).tolist() == [True]
    assert not segments_near(starts, ends, np.zeros((0, 3)), 3.0).any()


def test_frontiers_beyond_a_link_loss_on_a_graph_seen_from_home():
    g = nx.Graph()
    for u, v in zip([0, 1, 2, 0, 4], [1, 2, 3, 4, 5]):
        g.add_edge(u, v, weight=float(np.linalg.norm(POSITIONS[u] - POSITIONS[v])))
    loss = LinkLoss(np.array([[4.0, 0.0, 0.0]]), radius_m=1.0)
    assert loss.beyond_on_graph(g, 0, [3, 5, 2], lambda v: POSITIONS[v]) == {2, 3}
    assert LinkLoss(radius_m=1.0).beyond_on_graph(g, 0, [3, 5], lambda v: POSITIONS[v]) == set()


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="radius_m"):
        LinkLoss(radius_m=0.0)
    with pytest.raises(ValueError, match="gain_factor"):
        LinkLoss(gain_factor=1.5)


def test_the_planner_explores_the_branch_where_the_link_holds():
    """At a T junction with the link lost 5 m into both arms of the main tunnel, the
    local planner's path goes up the branch, where it still explores in range."""
    grid, j = s.t_junction()
    start = j + np.array([0.0, 0.0, 0.5])
    loss = LinkLoss(np.array([j + [5.0, 0, 0.5], j + [-5.0, 0, 0.5]]), radius_m=2.0)
    for seed in range(3):
        planner = GBPlanner(CFG, start)
        res = planner.plan(grid, start, np.random.default_rng(seed), link_loss=loss)
        assert res.ok and res.mode == "explore"
        assert res.path[-1][1] - j[1] > 3.0 and abs(res.path[-1][0] - j[0]) < 2.5, res.path[-1]
