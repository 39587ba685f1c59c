"""delve.planners.cops.post_exploration: Problem 2."""
import pytest

from delve.planners.cops import InfeasibleProblem, SolverOptions, solve_post_exploration, validate_plan

from .cops_networks import cut_off, fork, team


def test_problem2_brings_all_new_information_to_the_base():
    net = fork(team(3))
    pos = {"base": "s0", "r1": "a3", "r2": "b3", "r3": "s0"}
    plan = solve_post_exploration(net, sources=["r1", "r2"], positions=pos, masters=["base", "r1", "r2", "r3"])
    assert validate_plan(net, plan) == []
    got = {c.info for c in plan.communications if c.receiver == "base"}
    assert {"r1", "r2"} <= got
    assert plan.requirements[0].sinks == ("base",)


def test_a_mobile_sink_that_is_its_own_only_source_still_goes_to_its_final_location():
    # a cluster's sub-master that explored itself must still carry its information up
    net = fork(team(1))
    pos = {"base": "s0", "r1": "a3"}
    plan = solve_post_exploration(net, sources=["r1"], positions=pos, masters=["r1"], base_station="r1",
                                  static=["base"], static_sink=False, sink_final_location="s1")
    assert validate_plan(net, plan) == []
    assert plan.trajectories["r1"][-1] == "s1" and plan.horizon == 3


def test_infeasible_problems_say_why_in_one_line():
    net = cut_off()
    with pytest.raises(InfeasibleProblem) as err:
        solve_post_exploration(net, sources=["r1"], masters=["base", "r1"], max_horizon=2,
                               options=SolverOptions(probe_max_work=30.0))
    assert str(err.value) == "no route to the base within horizon T=2 for robot r1"
    with pytest.raises(InfeasibleProblem) as err:
        solve_post_exploration(net, sources=["r2"], masters=["base", "r2"])
    assert "no route to the base" in str(err.value) and "r2" in str(err.value)
    assert "\n" not in str(err.value)
