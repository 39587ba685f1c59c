"""plan_cycle on the shapes an exploring team meets: a small known network with the
whole team at the base, a larger one with the team spread, and one network growing
cycle after cycle. Every plan must pass the validator. (How long a cycle takes, with
tighter limits, is measured by bench/hot_paths.py, not asserted here.)"""
import random

import pytest

from delve.planners.cops import Robot, SolverOptions, plan_cycle, tunnel_network_graph, validate_plan
from delve.planners.cops.clustering import should_cluster
from delve.planners.cops.network import dead_ends

FULL = tunnel_network_graph(100, seed=4)
# The default work limits: a busy machine slows the tests down but does not change
# their outcome (with the former 3 s a cycle, the 10-robot network found no plan at
# all under a load of 5 on 2 cores).
OPTS = SolverOptions()


def known_network(known, robots):
    """The part of FULL that has been explored: frontiers are explored locations with
    an unexplored neighbour; ``robots`` maps robot -> location."""
    net = FULL.subnetwork(known)
    net.robots = {"base": FULL.robots["base"]}
    net.base_station = "base"
    for r, s in robots.items():
        net.add_robot(Robot(r, s))
    und = FULL.mobility.to_undirected(as_view=True)
    net.frontiers = {v for v in known if any(w not in known for w in und.neighbors(v))}
    return net


def grow(n_known, seed=0):
    rng = random.Random(seed)
    und = FULL.mobility.to_undirected(as_view=True)
    known = {"s0"}
    while len(known) < n_known:
        known.add(rng.choice(sorted({w for v in known for w in und.neighbors(v)} - known)))
    return known


def check(net, cyc):
    assert validate_plan(net, cyc.pre) == []
    assert validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post) == []
    base_gets = {c.info for c in cyc.post.communications if c.receiver == "base"}
    assert set(cyc.pre.explore) <= base_gets | {"base"}


def cycle(net):
    cyc = plan_cycle(net, masters={"base"}, explorers=set(net.robots) - {"base"}, static={"base"},
                     clustering="auto", options=OPTS)
    check(net, cyc)
    return cyc


def test_twenty_robots_at_the_base_of_a_small_known_network():
    known = grow(5, seed=1)
    net = known_network(known, {f"r{i}": "s0" for i in range(1, 21)})
    assert len(net.frontiers) >= 2
    cyc = cycle(net)
    assert set(cyc.pre.explore.values()) == net.frontiers, "every frontier gets robots"
    sizes = [len(rs) for rs in cyc.pre.frontier_assignment().values()]
    assert max(sizes) > 1 and sum(sizes) < 20, "diminishing returns: several robots, not the whole team"


@pytest.mark.slow  # 5-10 s on a quiet machine, half a minute on a busy one
def test_ten_robots_spread_over_a_larger_known_network():
    known = sorted(grow(60, seed=2))
    rng = random.Random(2)
    robots = {f"r{i}": ("s0" if i <= 3 else rng.choice(known)) for i in range(1, 11)}
    net = known_network(set(known), robots)
    assert len(net.frontiers) >= 6
    cyc = cycle(net)
    assert len(cyc.pre.explore) >= 3


def test_robots_spread_out_of_reach_of_the_plan_stay_put():
    # nobody holds m and nobody is in radio range of the base: nobody can move
    known = grow(60, seed=2)
    far = [s for s in sorted(known) if s not in ("s0",) and not FULL.communication.has_edge("s0", s)][:4]
    net = known_network(known, {f"r{i}": s for i, s in enumerate(far, 1)})
    cyc = cycle(net)
    assert cyc.pre.explore == {} and cyc.pre.horizon == 0


@pytest.mark.parametrize("team", [1, 20])
def test_cycles_on_a_growing_network(team):
    """The executive's loop: the known network grows from the base; robots start the
    next cycle where the last post-exploration left them."""
    positions = {f"r{i}": "s0" for i in range(1, team + 1)}
    known = {"s0"}
    und = FULL.mobility.to_undirected(as_view=True)
    for _ in range(4):
        net = known_network(known, positions)
        cyc = cycle(net)
        positions = {r: s for r, s in cyc.post.final_positions().items() if r != "base"}
        # exploring reveals the frontiers' unexplored neighbours, and theirs
        for s in set(cyc.pre.explore.values()):
            new = {w for w in und.neighbors(s) if w not in known}
            known |= new | {x for w in new for x in und.neighbors(w)}
    assert len(known) > 10


def test_auto_clusters_a_large_network_with_a_spread_team():
    net = tunnel_network_graph(100, seed=1)
    rng = random.Random(1)
    others = [s for s in net.locations if s != "s0"]
    for i in range(10):
        net.add_robot(Robot(f"r{i + 1}", "s0" if i < 5 else rng.choice(others)))
    net.frontiers = set(dead_ends(net))
    assert should_cluster(net, net.positions(), {"base"})
    # a team all at the base is one class of robots: no need to cut the network
    net.robots = {"base": net.robots["base"]}
    for i in range(10):
        net.add_robot(Robot(f"r{i + 1}", "s0"))
    assert not should_cluster(net.subnetwork(grow(20)), {r: "s0" for r in net.robots}, {"base"})
