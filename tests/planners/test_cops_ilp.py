"""delve.planners.cops.ilp: one connectivity problem solved at its horizon."""
import pytest

from delve.planners.cops import Requirement, plan_cost, solve_connectivity, validate_plan

from .cops_networks import line, problem


def test_relay_chain_when_the_base_is_out_of_direct_range():
    net = line(5, [{"name": "r1", "location": "s4"}, {"name": "r2", "location": "s2"},
                   {"name": "r3", "location": "s1"}])
    p = problem(net, 1, masters={"base", "r1", "r2", "r3"}, requirements=[Requirement(("r1",), ("base",))])
    plan = solve_connectivity(p)
    assert plan is not None and validate_plan(net, plan) == []
    assert plan.trajectories["r1"] == ["s4", "s3"]
    chain = [(c.sender, c.receiver) for c in plan.communications if c.info == "r1"]
    assert chain == [("r1", "r2"), ("r2", "r3"), ("r3", "base")]
    assert all(c.t == 1 for c in plan.communications)
    assert plan.meta["cost"] == pytest.approx(plan_cost(net, plan)) == pytest.approx(1 + 3 * 0.1)
    # at T=0 no chain reaches: infeasible
    assert solve_connectivity(problem(net, 0, masters={"base", "r1", "r2", "r3"},
                                      requirements=[Requirement(("r1",), ("base",))])) is None
