
from delve.planners.cops import SolverOptions, network_from_dict, validate_plan
from delve.planners.cops.clustering import build_clusters, idle_locations, plan_cycle_clustered
from delve.planners.cops.network import spread_team_network


def test_idle_locations_are_pruned_recursively():
    # s0 - s1 - s2 - s3 (dead end, nothing there) and s1 - f1 - f2 (frontier at f2)
    net = network_from_dict({
        "base": "s0", "locations": ["s0", "s1", "s2", "s3", "f1", "f2", "r"],
        "mobility": [["s0", "s1"], ["s1", "s2"], ["s2", "s3"], ["s1", "f1"], ["f1", "f2"], ["s0", "r"]],
        "robots": [{"name": "base", "location": "s0", "static": True}, {"name": "r1", "location": "r"}],
        "base_station": "base", "frontiers": ["f2"]})
    idle = idle_locations(net, net.positions(), net.frontiers, "s0")
    assert idle == {"s2", "s3"}


def test_clusters_form_a_tree_that_covers_the_active_network():
    net = spread_team_network(60, 6, seed=2)
    cs = build_clusters(net, net.positions(), net.frontiers, "s0", net.static_robots(),
                        max_cluster_locations=12)
    assert len(cs.clusters) >= 2
    covered = set().union(*(c.locations for c in cs.clusters.values()))
    assert covered == set(net.locations) - cs.idle_locations
    assert cs.parent_first()[0] == cs.master and sorted(cs.parent_first()) == sorted(cs.clusters)
    for c in cs.clusters.values():
        mobile = [r for r in c.robots if not net.robots[r].static]
        assert mobile, "every cluster has robots that can act"
        if c.parent is not None:
            assert c.gateway in cs.clusters[c.parent].locations
            assert net.mobility.has_edge(c.gateway, c.root)


def test_clustered_cycle_returns_valid_plans_on_a_bigger_network():
    net = spread_team_network(40, 4, seed=3)
    opts = SolverOptions(mip_gap=0.05)
    cyc = plan_cycle_clustered(net, max_cluster_locations=12, options=opts)
    assert cyc.meta["clusters"] >= 2
    assert validate_plan(net, cyc.pre) == []
    post_net = net.with_positions(cyc.pre.final_positions())
    assert validate_plan(post_net, cyc.post) == []
    assert cyc.pre.explore, "robots are sent exploring"
    # Figure 3: every explorer explores at least the minimum time, the tightest exactly that
    steps = [t.steps for t in cyc.exploration.values()]
    assert min(steps) >= cyc.meta["min_exploration_steps"]
    # every explorer's information reaches the base
    base_gets = {c.info for c in cyc.post.communications if c.receiver == "base"}
    assert set(cyc.pre.explore) <= base_gets
