"""delve.planners.cops.ilp_solvers: the HiGHS and pulp back-ends, their work limits and
safety stop."""
import pytest

from delve.planners.cops import (ConnectivityProblem, FrontierReward, Requirement, SolverOptions,
                                 SolverTimeout, available_solver, solve_connectivity, validate_plan)
from delve.planners.cops.budget import SolveLimits
from delve.planners.cops.meter import Meter
from delve.planners.cops.greedy import greedy_pre_plan
from delve.planners.cops.horizon import horizon_of
from delve.planners.cops.ilp_solvers import _cbc_figures
from delve.planners.cops.network import spread_team_network

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
    assert b.meta["solver"] == "cbc" and validate_plan(net, b) == [] and b.meta["stop"] is None
    assert a.meta["objective"] == pytest.approx(b.meta["objective"])


def plan_network():
    return spread_team_network(25, 4, 1)


def spread_problem(**kw):
    """Pre-exploration of 25 locations with four robots, warm-started by the greedy plan:
    large enough that a search does not finish at the root (about 7000 rows)."""
    net = plan_network()
    pos, static = net.positions(), net.static_robots()
    explorers = net.explorers() - static
    rewards = {s: FrontierReward().marginals(len(explorers)) for s in net.frontiers}
    greedy = greedy_pre_plan(net, pos, {"base"}, static, explorers, rewards)
    return ConnectivityProblem(network=net, horizon=horizon_of(greedy) + 1, positions=pos,
                               masters={"base"}, static=static, explorers=explorers,
                               location_rewards=rewards, frontiers=set(net.frontiers),
                               warm_start=greedy, **kw)


def test_work_limits_stop_a_solve_at_the_same_point_every_time():
    limits = SolveLimits(max_nodes=500, max_work=40.0, stall_work=20.0, time_limit_s=300.0)
    a, b = (solve_connectivity(spread_problem(), limits=limits) for _ in range(2))
    assert a.meta["stop"] in ("work", "stall") and a.meta["status"] == "feasible"
    assert (a.meta["work"], a.meta["objective"], a.trajectories, a.communications) == \
        (b.meta["work"], b.meta["objective"], b.trajectories, b.communications)


def test_a_safety_stop_that_fires_is_counted_and_named():
    meter = Meter()
    with pytest.raises(SolverTimeout, match="safety stop"):
        solve_connectivity(spread_problem(options=SolverOptions(meter=meter)), time_limit_s=1e-6)
    assert meter.figures() == {"work": 0, "solves": 1, "safety_stops": 1}
    assert "ran past its safety stop" in meter.safety_stops[0]


def test_a_warm_start_within_the_gap_of_a_known_bound_is_taken_without_a_search():
    p = spread_problem(options=SolverOptions(max_work=3.0))
    warm = solve_connectivity(p)  # stopped at once: the completed greedy plan
    searched = solve_connectivity(spread_problem(options=SolverOptions(max_work=20.0)))
    bounded = solve_connectivity(spread_problem(objective_bound=warm.meta["objective"] * 1.005))
    assert searched.meta["work"] > 0 and bounded.meta["work"] == 0 and bounded.meta["stop"] is None
    assert bounded.meta["objective"] == warm.meta["objective"] and bounded.meta["status"] == "optimal"


def test_cbc_reports_its_work_and_the_limit_that_stopped_it():
    log = "Result - Stopped on node limit\nEnumerated nodes: 2\nTotal iterations: 10922\n"
    assert _cbc_figures(log) == (10922, 2, "nodes")
    assert _cbc_figures("Result - Stopped on time limit\n")[2] == "safety"
    optimal = "Result - Optimal solution found\nEnumerated nodes: 0\nTotal iterations: 7\n"
    assert _cbc_figures(optimal) == (7, 0, None)


def test_a_model_too_large_to_search_gives_its_completed_warm_start():
    plan = solve_connectivity(spread_problem(options=SolverOptions(search_max_rows=100)))
    assert plan.meta["stop"] == "size" and plan.meta["status"] == "feasible" and plan.meta["gap"] is None
    assert validate_plan(plan_network(), plan) == []


def test_a_highs_solve_prints_nothing(capfd):
    net = line(4, [{"name": "r1", "location": "s3"}, {"name": "r2", "location": "s1"}])
    kw = dict(masters={"base", "r1", "r2"}, requirements=[Requirement(("r1",), ("base",))])
    capfd.readouterr()
    solve_connectivity(problem(net, 2, options=SolverOptions(solver="highs"), **kw))
    print("after")
    assert capfd.readouterr().out == "after\n"
