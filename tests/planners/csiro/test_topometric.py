"""planners/csiro/topometric.py: nodes every ~3 m along trajectories, observer-planning edges,
frontiers hung off the node closest in time, A* paths and eq. 15 distances, merging maps."""
from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from delve.planners.csiro.topometric import TopometricMap, frontier_node


def walk(m: TopometricMap, robot: str, points, t0: float = 0.0, dt: float = 1.0) -> list:
    """Feed ``robot``'s poses at 0.5 m steps between the corner ``points``; the nodes added."""
    added, t = [], t0
    for a, b in zip(points[:-1], points[1:]):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(int(np.ceil(np.linalg.norm(b - a) / 0.5)), 1)
        for s in np.linspace(0.0, 1.0, n + 1)[:-1]:
            node = m.add_pose(robot, t, a + s * (b - a))
            t += dt
            if node is not None:
                added.append(node)
    node = m.add_pose(robot, t, points[-1])
    return added + ([node] if node is not None else [])


def test_nodes_every_spacing_joined_along_the_trajectory():
    m = TopometricMap(3.0)
    nodes = walk(m, "a", [[0, 0, 0], [30, 0, 0]])
    xs = [m.position(n)[0] for n in nodes]
    assert len(nodes) == 11 and np.allclose(np.diff(xs), 3.0)
    assert all(m.graph.has_edge(p, q) for p, q in zip(nodes[:-1], nodes[1:]))
    assert m.add_pose("a", 100.0, [31.0, 0, 0]) is None        # within 3 m of the last node
    assert m.last_node("a") == nodes[-1] and m.last_node("b") is None


def test_distances_and_astar_path_follow_the_trajectory_not_the_straight_line():
    m = TopometricMap(3.0)
    walk(m, "a", [[0, 0, 0], [30, 0, 0], [30, 30, 0]])
    m.attach_frontier(("a", 7), "a", updated_s=1e6, position=[30.0, 31.0, 0.0])
    target = frontier_node(("a", 7))
    d = m.distances([0.0, 0.0, 0.0], [target])
    assert d[0] == pytest.approx(61.0, abs=0.01)                  # around the corner, not 43 m
    path = m.path([0.0, 0.0, 0.0], target)
    assert path is not None and path.length_m == pytest.approx(61.0, abs=0.01)
    assert np.allclose(path.points[-1], [30.0, 31.0, 0.0])
    assert path.nodes[-1] == target and path.nodes[0] == ("a", 0)
    assert (np.abs(path.points[:, 1]) < 1e-9).sum() >= 10           # along y = 0 first


def test_observer_planning_edges_make_a_short_cut():
    m = TopometricMap(3.0)
    walk(m, "a", [[0, 0, 0], [30, 0, 0], [30, 6, 0], [0, 6, 0]])
    here = m.nearest_node([0.0, 6.0, 0.0])
    before = m.distances([0.0, 6.0, 0.0], [("a", 0)])[0]
    assert before > 60
    assert m.connect_reachable(here, np.array([[0.2, 0.3, 0.0]]), radius_m=1.0) == 1
    assert m.distances([0.0, 6.0, 0.0], [("a", 0)])[0] == pytest.approx(6.0)
    assert m.connect_reachable(here, np.array([[0.2, 0.3, 0.0]]), radius_m=1.0) == 0   # known edge


def test_frontier_hangs_off_the_node_closest_in_time_and_moves_on_update():
    m = TopometricMap(3.0)
    nodes = walk(m, "a", [[0, 0, 0], [30, 0, 0]])                # 2 s per metre: node k at t = 6 k
    m.attach_frontier(("a", 1), "a", updated_s=13.0, position=[6.0, 2.0, 0.0])
    f = frontier_node(("a", 1))
    assert list(m.graph.neighbors(f)) == [nodes[2]]
    m.attach_frontier(("a", 1), "a", updated_s=60.0, position=[30.0, 2.0, 0.0])
    assert list(m.graph.neighbors(f)) == [nodes[10]]
    assert not m.attach_frontier(("b", 0), "b", 0.0, [0.0, 0.0, 0.0])   # no node of b known
    m.detach_frontier(("a", 1))
    assert f not in m.graph


def test_merge_when_robots_meet_lets_one_plan_along_the_others_trajectory():
    a, b = TopometricMap(3.0), TopometricMap(3.0)
    walk(a, "a", [[0, 0, 0], [15, 0, 0]])
    walk(b, "b", [[0, 1, 0], [0, 31, 0]])
    assert a.merge(b.changes()) == len(b)
    a.connect(a.nearest_node([0, 0, 0]), ("b", 0))                # the robots met at the start
    b.merge(a.changes())                                           # b learns a's map and the joint
    a.attach_frontier(("b", 4), "b", updated_s=1e6, position=[0.0, 32.0, 0.0])
    assert a.distances([15.0, 0.0, 0.0], [frontier_node(("b", 4))])[0] == pytest.approx(15 + 1 + 31, abs=0.01)
    assert set(b.graph.nodes) == set(a.graph.nodes) - {frontier_node(("b", 4))}
    assert nx.utils.edges_equal(sorted(b.graph.edges), sorted(e for e in a.graph.edges if "frontier" not in
                                                              (e[0][0], e[1][0])))


def test_merge_logs_only_what_is_new_so_gossip_ends():
    a, b, c = TopometricMap(), TopometricMap(), TopometricMap()
    walk(a, "a", [[0, 0, 0], [12, 0, 0]])
    assert b.merge(a.changes()) == len(a)
    assert c.merge(b.changes()) == len(a)                          # c learns a's map through b
    assert a.merge(c.changes()) == 0                               # nothing comes back new
    assert b.merge(a.changes()) == 0
    since = len(b)
    walk(a, "a", [[12, 0, 0], [18, 0, 0]], t0=100.0)
    assert b.merge(a.changes(len(b))) == 4 and len(b.changes(since)) == 4   # two nodes, two edges


def test_empty_map():
    m = TopometricMap()
    assert m.nearest_node([0.0, 0.0, 0.0]) is None
    assert np.isinf(m.distances([0.0, 0.0, 0.0], [("a", 0)])).all()
    assert m.path([0.0, 0.0, 0.0], ("a", 0)) is None
    with pytest.raises(ValueError):
        TopometricMap(0.0)
