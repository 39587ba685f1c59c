import networkx as nx
import numpy as np
import pytest

from delve.planners.exploration_bound import exploration_bound, trimmed_graph
from delve.sim import worldgen


def line(lengths):
    g = nx.Graph()
    x = 0.0
    g.add_node(0, pos=np.array([0.0, 0.0, 0.0]))
    for i, length in enumerate(lengths):
        x += length
        g.add_node(i + 1, pos=np.array([x, 0.0, 0.0]))
        g.add_edge(i, i + 1, length_m=length)
    return g


def star(arms, length):
    g = nx.Graph()
    g.add_node("c", pos=np.zeros(3))
    for i in range(arms):
        angle = 2 * np.pi * i / arms
        g.add_node(i, pos=length * np.array([np.cos(angle), np.sin(angle), 0.0]))
        g.add_edge("c", i)
    return g


def test_a_passage_is_walked_to_within_sensor_range_of_its_end():
    g = line([40.0, 60.0])
    assert exploration_bound(g, 0, 10.0).walk_m == pytest.approx(90.0)
    assert exploration_bound(g, 0, 10.0, closed=True).walk_m == pytest.approx(180.0)


def test_the_trim_goes_past_junctions_that_become_dead_ends():
    g = line([40.0, 5.0, 3.0])  # the last 8 m are seen from 10 m back
    trimmed = trimmed_graph(g, 0, 10.0)
    assert sorted(trimmed.nodes) == [0, 1]
    assert trimmed.edges[0, 1]["length_m"] == pytest.approx(38.0)


def test_a_star_from_its_centre_walks_all_arms_but_one_twice():
    bound = exploration_bound(star(3, 50.0), "c", 0.0)
    assert bound.walk_m == pytest.approx(250.0)
    assert bound.repeated_m == pytest.approx(100.0)
    assert exploration_bound(star(3, 50.0), "c", 0.0, closed=True).walk_m == pytest.approx(300.0)


def test_a_loop_is_walked_once():
    g = nx.cycle_graph(4)
    nx.set_edge_attributes(g, 25.0, "length_m")
    assert exploration_bound(g, 0, 10.0).walk_m == pytest.approx(100.0)
    assert exploration_bound(g, 0, 10.0, closed=True).walk_m == pytest.approx(100.0)


def test_unwalkable_and_unreachable_passages_are_left_out():
    g = line([30.0, 30.0])
    g.edges[1, 2]["kind"] = "shaft"
    g.add_edge(7, 8, length_m=500.0)
    bound = exploration_bound(g, 0, 0.0, walkable=lambda d: d.get("kind") != "shaft")
    assert bound.walk_m == pytest.approx(30.0)


def test_a_generated_network_is_bounded_by_its_centreline():
    world = worldgen.tunnel_network(3, total_length_m=300.0, loops=2)
    total = sum(d["length_m"] for _, _, d in world.centreline.edges(data=True))
    start = min(world.centreline.nodes, key=lambda n: np.linalg.norm(world.centreline.nodes[n]["pos"]))
    open_walk = exploration_bound(world.centreline, start, 10.0)
    closed = exploration_bound(world.centreline, start, 10.0, closed=True)
    assert open_walk.covered_m < total
    assert open_walk.covered_m <= open_walk.walk_m <= closed.walk_m <= 2 * total
    assert open_walk.time_s(1.0) == pytest.approx(open_walk.walk_m)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="sensor_range_m"):
        exploration_bound(line([10.0]), 0, -1.0)
    with pytest.raises(ValueError, match="speed_mps"):
        exploration_bound(line([10.0]), 0, 1.0).time_s(0.0)
