"""delve.planners.cops.plan_extraction: robot-level tuples from location-level flows."""
from delve.planners.cops import MASTER, Communication, reconstruct_communications, solve_connectivity

from .cops_networks import line, problem


def test_a_flow_becomes_the_tuples_that_carry_it_through_the_leaders():
    net = line(2, [{"name": "r1", "location": "s1"}])
    traj = {"base": ["s0", "s0"], "r1": ["s1", "s1"]}
    holdings = {"base": {"base"}, "r1": {"r1"}}
    m_arcs = {0: [("s0", "s1")]}
    info_arcs = {0: [("s1", "s0", frozenset({"r1"}))]}
    comms = reconstruct_communications(net, traj, 1, {"base"}, holdings, m_arcs, info_arcs, {"base": {"r1"}})
    # m first reaches s1, whose leader may then send over the chosen arc
    assert comms == [Communication(0, "base", "r1", MASTER), Communication(0, "r1", "base", "r1")]
    # nobody needs r1's information and r1 does not move: every tuple is pruned
    assert reconstruct_communications(net, traj, 1, {"base"}, holdings, m_arcs, info_arcs, {}) == []


def test_robots_rewarded_at_a_frontier_are_sent_exploring_it():
    net = line(3, [{"name": "r1", "location": "s0"}, {"name": "r2", "location": "s0", "explorer": False}],
               frontiers=["s2"])
    plan = solve_connectivity(problem(net, 3, location_rewards={"s2": (50.0,)}, frontiers={"s2"}))
    assert plan.explore == {"r1": "s2"} and plan.trajectories["r1"][-1] == "s2"
