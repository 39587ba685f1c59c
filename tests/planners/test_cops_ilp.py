import pytest

from delve.planners.cops import (ConnectivityProblem, Requirement, SolverOptions, available_solver,
                                 network_from_dict, plan_cost, solve_connectivity, validate_plan)


def line(n, robots, comm=None, **extra):
    names = [f"s{i}" for i in range(n)]
    d = {"base": "s0", "locations": names,
         "mobility": [[a, b] for a, b in zip(names, names[1:])],
         "communication": comm if comm is not None else [[a, b] for a, b in zip(names, names[1:])],
         "robots": [{"name": "base", "location": "s0", "static": True}] + robots,
         "base_station": "base"}
    d.update(extra)
    return network_from_dict(d)


def problem(net, T, **kw):
    kw.setdefault("positions", net.positions())
    kw.setdefault("masters", {"base"})
    kw.setdefault("static", net.static_robots())
    kw.setdefault("explorers", net.explorers())
    return ConnectivityProblem(network=net, horizon=T, **kw)


def test_solver_is_highs_when_installed_else_cbc():
    assert available_solver() in ("highs", "cbc")
    assert available_solver("cbc") == "cbc"
    with pytest.raises(ValueError):
        available_solver("gurobi")


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


def test_a_robot_without_m_waits_until_the_plan_reaches_it():
    # r2 stands at s2, out of radio range of the base; r1 must carry m to it first
    net = line(5, [{"name": "r1", "location": "s0", "explorer": False}, {"name": "r2", "location": "s2"}],
               comm=[["s0", "s1"]], frontiers=["s4"])
    p = problem(net, 4, location_rewards={"s4": (50.0,)}, frontiers={"s4"})
    plan = solve_connectivity(p)
    assert validate_plan(net, plan) == []
    assert plan.explore == {"r2": "s4"}
    got_m = min(c.t for c in plan.communications if c.receiver == "r2" and c.info == "m")
    first_move = next(t for t in range(plan.horizon) if plan.trajectories["r2"][t] != plan.trajectories["r2"][t + 1])
    assert got_m <= first_move
    assert got_m >= 1  # the plan could not reach r2 at t=0


def test_static_robots_stay_and_collision_robots_never_meet():
    net = line(4, [{"name": "r1", "location": "s0", "collision": True},
                   {"name": "r2", "location": "s0", "collision": True},
                   {"name": "relay", "location": "s1", "static": True, "explorer": False}],
               collision_locations=["s1", "s2"], frontiers=["s3"])
    p = problem(net, 6, location_rewards={"s3": (50.0, 40.0)}, frontiers={"s3"},
                collision_robots={"r1", "r2"}, collision_locations={"s1", "s2"})
    plan = solve_connectivity(p)
    assert validate_plan(net, plan, collision_robots={"r1", "r2"}) == []
    assert set(plan.trajectories["relay"]) == {"s1"}
    assert sorted(plan.explore) == ["r1", "r2"]
    for t in range(plan.horizon + 1):
        a, b = plan.trajectories["r1"][t], plan.trajectories["r2"][t]
        assert not (a == b and a in {"s1", "s2"})


def test_cbc_gives_the_same_optimum():
    net = line(5, [{"name": "r1", "location": "s4"}, {"name": "r2", "location": "s2"},
                   {"name": "r3", "location": "s1"}])
    kw = dict(masters={"base", "r1", "r2", "r3"}, requirements=[Requirement(("r1",), ("base",))])
    a = solve_connectivity(problem(net, 2, **kw))
    b = solve_connectivity(problem(net, 2, options=SolverOptions(solver="cbc"), **kw))
    assert b.meta["solver"] == "cbc" and validate_plan(net, b) == []
    assert a.meta["objective"] == pytest.approx(b.meta["objective"])
