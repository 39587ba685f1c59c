"""delve.planners.cops.ilp_solvers: the HiGHS and pulp back-ends."""
import pytest

from delve.planners.cops import Requirement, SolverOptions, available_solver, solve_connectivity, validate_plan

from .cops_networks import line, problem


def test_solver_is_highs_when_installed_else_cbc():
    assert available_solver() in ("highs", "cbc")
    assert available_solver("cbc") == "cbc"
    with pytest.raises(ValueError):
        available_solver("gurobi")


def test_cbc_gives_the_same_optimum():
    net = line(5, [{"name": "r1", "location": "s4"}, {"name": "r2", "location": "s2"},
                   {"name": "r3", "location": "s1"}])
    kw = dict(masters={"base", "r1", "r2", "r3"}, requirements=[Requirement(("r1",), ("base",))])
    a = solve_connectivity(problem(net, 2, **kw))
    b = solve_connectivity(problem(net, 2, options=SolverOptions(solver="cbc"), **kw))
    assert b.meta["solver"] == "cbc" and validate_plan(net, b) == []
    assert a.meta["objective"] == pytest.approx(b.meta["objective"])
