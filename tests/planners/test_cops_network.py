import networkx as nx
import pytest

from delve.planners.cops import MCNetwork, network_from_dict, tunnel_network_graph
from delve.planners.cops.network import dead_ends


def base_dict():
    return {
        "base": "s0",
        "locations": [{"name": "s0", "pos": [0, 0, 0]}, "s1", "s2"],
        "mobility": [["s0", "s1"], {"from": "s1", "to": "s2", "cost": 2.0}],
        "communication": [["s0", "s1", 0.2]],
        "robots": [{"name": "base", "location": "s0", "static": True}, {"name": "r1", "location": "s1"}],
        "base_station": "base",
        "frontiers": ["s2"],
    }


def test_loads_a_network_with_both_directions():
    net = network_from_dict(base_dict())
    assert isinstance(net, MCNetwork)
    assert net.mobility.has_edge("s0", "s1") and net.mobility.has_edge("s1", "s0")
    assert net.mobility_cost("s1", "s2") == 2.0
    assert net.communication_cost("s1", "s0") == pytest.approx(0.2)
    assert net.can_communicate("s0", "s1") and not net.can_communicate("s0", "s2")
    assert net.robots["base"].static and not net.robots["base"].explorer
    assert net.frontiers == {"s2"}
    again = network_from_dict(net.to_dict())
    assert set(again.mobility.edges) == set(net.mobility.edges)


@pytest.mark.parametrize("change, message", [
    (lambda d: d["mobility"].append(["s1", "s9"]), "unknown location 's9'"),
    (lambda d: d["communication"].append(["s7", "s0"]), "unknown location 's7'"),
    (lambda d: d["mobility"].append({"from": "s0", "to": "s2", "cost": -1}), "negative cost"),
    (lambda d: d["communication"].append(["s0", "s2", -0.5]), "negative cost"),
    (lambda d: d["robots"][0].update(static=False), "base station 'base' must be static"),
    (lambda d: d.update(base_station="nobody"), "base station 'nobody' is not a robot"),
    (lambda d: d["robots"].append({"name": "r2", "location": "s5"}), "unknown location 's5'"),
    (lambda d: d["robots"].append({"name": "r1", "location": "s0"}), "defined twice"),
    (lambda d: d["locations"].append("s1"), "defined twice"),
    (lambda d: d["frontiers"].append("s8"), "frontier 's8' is not a location"),
    (lambda d: d["mobility"].append(["s1", "s1"]), "self-loop"),
    (lambda d: d["mobility"].append(["s1", "s2", "far"]), "non-numeric cost"),
    (lambda d: d.update(locations=[]), "'locations' must be a non-empty list"),
    (lambda d: d.update(colour="red"), "unknown key 'colour'"),
    (lambda d: d.update(base="s4"), "base location 's4'"),
])
def test_loader_rejects_malformed_networks(change, message):
    d = base_dict()
    change(d)
    with pytest.raises(ValueError) as err:
        network_from_dict(d)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_tunnel_network_is_a_connected_tree_of_50m_steps_with_line_of_sight_radio():
    net = tunnel_network_graph(60, spacing_m=50, seed=3)
    assert len(net) == 60
    und = net.mobility.to_undirected()
    assert nx.is_tree(und)
    for u, v, d in net.mobility.edges(data=True):
        assert d["length_m"] == pytest.approx(50.0)
    # every tunnel step has radio; some radio links skip a location along a straight tunnel
    assert all(net.communication.has_edge(u, v) for u, v in net.mobility.edges)
    assert any(nx.shortest_path_length(und, u, v) == 2 for u, v in net.communication.edges)
    assert all(nx.shortest_path_length(und, u, v) <= 2 for u, v in net.communication.edges)
    assert net.base == "s0" and net.robots[net.base_station].static
    depth = nx.single_source_dijkstra_path_length(und, "s0", weight="length_m")
    assert max(depth.values()) <= 1000.0 + 1e-6
    assert len(dead_ends(net)) >= 2  # it forks
    assert tunnel_network_graph(60, seed=3).to_dict() == net.to_dict()  # deterministic


def test_spread_team_network_puts_half_the_team_at_the_base():
    from delve.planners.cops.network import dead_ends, spread_team_network
    net = spread_team_network(40, 5, seed=3)
    pos = net.positions()
    assert sum(1 for r in pos if r.startswith("r") and pos[r] == net.base) >= 3
    assert net.frontiers == set(dead_ends(net)) and spread_team_network(40, 5, seed=3).positions() == pos
