import pytest

from delve.planners.cops import (FrontierReward, InfeasibleProblem, SolverOptions, network_from_dict,
                                 plan_cycle, solve_post_exploration, solve_pre_exploration, validate_plan)


def fork(robots, frontiers=("a3", "b3"), comm="adjacent"):
    """Base s0 - s1, then two branches a1..a3 and b1..b3."""
    locs = ["s0", "s1", "a1", "a2", "a3", "b1", "b2", "b3"]
    mob = [["s0", "s1"], ["s1", "a1"], ["a1", "a2"], ["a2", "a3"], ["s1", "b1"], ["b1", "b2"], ["b2", "b3"]]
    return network_from_dict({
        "base": "s0", "locations": locs, "mobility": mob,
        "communication": mob if comm == "adjacent" else comm,
        "robots": [{"name": "base", "location": "s0", "static": True}] + robots,
        "base_station": "base", "frontiers": list(frontiers)})


def team(n, **kw):
    return [dict({"name": f"r{i}", "location": "s0"}, **kw) for i in range(1, n + 1)]


def test_problem1_sends_robots_to_frontiers_with_diminishing_returns():
    net = fork(team(3))
    plan = solve_pre_exploration(net)
    assert validate_plan(net, plan) == []
    sizes = sorted(len(rs) for rs in plan.frontier_assignment().values())
    # R = 50, 75, 87.5: two at one frontier and one at the other beats three at one
    assert sizes == [1, 2]
    assert plan.meta["reward"] == pytest.approx(50 + 25 + 50)
    for r, s in plan.explore.items():
        assert plan.trajectories[r][-1] == s
    assert plan.horizon >= 4


def test_reward_tables_must_have_diminishing_returns():
    assert FrontierReward(table=(10, 15, 17)).marginals(3) == (10, 5, 2)
    with pytest.raises(ValueError, match="diminishing returns"):
        FrontierReward(table=(10, 15, 25)).marginals(3)
    r = FrontierReward()
    assert r.value(3) < 2 * r.value(2) - r.value(1)


def test_only_capable_robots_explore():
    net = fork(team(1) + [{"name": "carrier", "location": "s0", "explorer": False}], frontiers=("a3",))
    plan = solve_pre_exploration(net)
    assert validate_plan(net, plan) == []
    assert plan.explore == {"r1": "a3"}


def test_problem2_brings_all_new_information_to_the_base():
    net = fork(team(3))
    pos = {"base": "s0", "r1": "a3", "r2": "b3", "r3": "s0"}
    plan = solve_post_exploration(net, sources=["r1", "r2"], positions=pos, masters=["base", "r1", "r2", "r3"])
    assert validate_plan(net, plan) == []
    got = {c.info for c in plan.communications if c.receiver == "base"}
    assert {"r1", "r2"} <= got
    assert plan.requirements[0].sinks == ("base",)


def test_a_cycle_passes_the_validator():
    net = fork(team(2))
    cyc = plan_cycle(net, clustering=False)
    assert validate_plan(net, cyc.pre) == []
    assert validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post) == []
    assert set(cyc.exploration) == set(cyc.pre.explore)
    assert all(task.steps >= 4 for task in cyc.exploration.values())


def test_infeasible_problems_say_why_in_one_line():
    net = network_from_dict({
        "base": "s0", "locations": ["s0", "s1", "s2", "s3", "s4", "s5", "x1", "x2"],
        "mobility": [["s0", "s1"], ["s1", "s2"], ["s2", "s3"], ["s3", "s4"], ["s4", "s5"], ["x1", "x2"]],
        "communication": [["s0", "s1"]],
        "robots": [{"name": "base", "location": "s0", "static": True}, {"name": "r1", "location": "s5"},
                   {"name": "r2", "location": "x1", "explorer": False}],
        "base_station": "base", "frontiers": ["x2"]})
    with pytest.raises(InfeasibleProblem) as err:
        solve_pre_exploration(net)
    assert str(err.value) == "frontier x2 cannot be reached by any capable robot"
    with pytest.raises(InfeasibleProblem) as err:
        solve_post_exploration(net, sources=["r1"], masters=["base", "r1"], max_horizon=2,
                               options=SolverOptions(probe_time_limit_s=2))
    assert str(err.value) == "no route to the base within horizon T=2 for robot r1"
    with pytest.raises(InfeasibleProblem) as err:
        solve_post_exploration(net, sources=["r2"], masters=["base", "r2"])
    assert "no route to the base" in str(err.value) and "r2" in str(err.value)
    assert "\n" not in str(err.value)


def test_a_mobile_sink_that_is_its_own_only_source_still_goes_to_its_final_location():
    # a cluster's sub-master that explored itself must still carry its information up
    net = fork(team(1))
    pos = {"base": "s0", "r1": "a3"}
    plan = solve_post_exploration(net, sources=["r1"], positions=pos, masters=["r1"], base_station="r1",
                                  static=["base"], static_sink=False, sink_final_location="s1")
    assert validate_plan(net, plan) == []
    assert plan.trajectories["r1"][-1] == "s1" and plan.horizon == 3


def test_greedy_plans_bound_the_horizon_and_warm_start_the_solver():
    net = fork(team(4))
    cyc = plan_cycle(net, clustering=False, options=SolverOptions(time_limit_s=2, total_time_limit_s=4))
    assert validate_plan(net, cyc.pre) == []
    # trimmed after the last action: the last step moves someone or sends something
    T = cyc.pre.horizon
    last_moves = any(tr[T - 1] != tr[T] for tr in cyc.pre.trajectories.values())
    assert last_moves or any(c.t == T for c in cyc.pre.communications)
    assert cyc.pre.meta["status"] in ("optimal", "feasible") and cyc.meta["solve_time_s"] < 8
