"""Topologies: merging what robots learnt, and the planning network over them."""
import pytest

from delve.planners.cops import validate_plan
from delve.planners.cops.greedy import greedy_pre_plan
from delve.planners.cops.plan import MASTER, Communication, Plan
from delve.planners.cops.recall import hand_m_at_base, solve_recall
from delve.planners.cops.topology import Topology, team_network


def chain(n, explored):
    t = Topology()
    for i in range(n):
        t.add_location(f"s{i}", (50.0 * i, 0, 0), explored=i < explored)
    for i in range(n - 1):
        t.add_mobility_edge(f"s{i}", f"s{i + 1}")
        t.add_communication_edge(f"s{i}", f"s{i + 1}")
    return t


def test_frontiers_are_explored_locations_next_to_unexplored_ones():
    t = chain(5, 3)
    assert t.frontiers() == {"s2"}
    net = t.network("s0", spacing_m=50.0)
    assert sorted(net.locations) == ["s0", "s1", "s2"] and net.frontiers == {"s2"}
    assert net.mobility_cost("s0", "s1") == pytest.approx(1.0)


def test_merge_is_a_union_and_round_trips_as_plain_data():
    a, b = chain(3, 1), chain(5, 4)
    assert a.merge(b) and not a.merge(b)
    assert a.explored == {"s0", "s1", "s2", "s3"}
    assert Topology.from_dict(a.to_dict()).to_dict() == a.to_dict()


def test_bad_topologies_are_rejected():
    with pytest.raises(ValueError, match="unknown location"):
        Topology.from_dict({"locations": {"a": [0, 0, 0]}, "mobility": [["a", "b"]]})
    with pytest.raises(ValueError, match="finite"):
        Topology().add_location("a", (0, float("nan"), 0))
    with pytest.raises(ValueError, match="not been explored"):
        chain(3, 1).network("s2")


def test_team_network_places_the_base_station_static():
    net = team_network(chain(4, 4), "s0", "base", {"r1": "s3"})
    assert net.robots["base"].static and net.base_station == "base"
    with pytest.raises(ValueError, match="not an explored location"):
        team_network(chain(4, 2), "s0", "base", {"r1": "s3"})


def test_recall_brings_home_every_robot_m_can_reach():
    net = team_network(chain(6, 6), "s0", "base", {"r1": "s1", "r2": "s4"})
    plan = solve_recall(net, positions=net.positions(), masters={"base"}, static={"base"})
    assert not validate_plan(net, plan)
    assert plan.location("r1", plan.horizon) == plan.location("r2", plan.horizon) == "s0"
    assert plan.meta["stranded"] == []


def test_recall_reports_robots_m_cannot_reach():
    t = chain(6, 6)
    t.communication = {("s0", "s1")}
    net = team_network(t, "s0", "base", {"r1": "s4"})
    plan = solve_recall(net, positions=net.positions(), masters={"base"}, static={"base"})
    assert plan.meta["stranded"] == ["r1"] and not validate_plan(net, plan)


def test_recall_hands_m_to_robots_already_home():
    net = team_network(chain(3, 3), "s0", "base", {"r1": "s0"})
    plan = solve_recall(net, positions=net.positions(), masters={"base"}, static={"base"})
    assert plan.horizon == 0 and "r1" in plan.master_receivers() and not validate_plan(net, plan)


def test_recall_fetches_a_robot_out_of_reach_with_one_already_home():
    """The only robot holding m is home already: it walks out with m and back again."""
    net = team_network(chain(9, 9), "s0", "base", {"r1": "s0", "r2": "s8"})
    greedy = greedy_pre_plan(net, net.positions(), {"base"}, {"base"}, ["r1", "r2"], {"s0": (1000.0, 1000.0)})
    assert greedy["r1"][0] == greedy["r1"][-1] == "s0" and "s7" in greedy["r1"]
    assert greedy["r2"][-1] == "s0"
    plan = solve_recall(net, positions=net.positions(), masters={"base"}, static={"base"})
    assert plan.meta["stranded"] == [] and not validate_plan(net, plan)


def test_recall_hands_m_at_the_end_to_robots_home_without_it():
    """A solve stopped by its time limit may leave a robot at the base without m."""
    net = team_network(chain(4, 4), "s0", "base", {"r1": "s0", "r2": "s1"})
    plan = Plan(horizon=3, trajectories={"base": ["s0"] * 4, "r1": ["s0"] * 4, "r2": ["s1", "s0", "s0", "s0"]},
                communications=[Communication(0, "base", "r2", MASTER)], masters=["base"], phase="recall")
    hand_m_at_base(plan, "s0", ["r1", "r2"])
    assert plan.communications[-1] == Communication(3, "base", "r1", MASTER)
    assert plan.master_receivers() == {"base", "r1", "r2"} and not validate_plan(net, plan)


def test_an_unreachable_location_is_no_frontier_target_and_travels_with_the_topology():
    t = chain(5, 3)
    t.unreachable.add("s3")
    assert t.frontiers() == set() and t.unexplored_exits("s2") == []
    other = chain(5, 1)
    assert other.merge(t) and other.unreachable == {"s3"}
    assert Topology.from_dict(t.to_dict()).unreachable == {"s3"}
    with pytest.raises(ValueError, match="unreachable location 'x'"):
        Topology.from_dict({"locations": {"a": [0, 0, 0]}, "unreachable": ["x"]})
