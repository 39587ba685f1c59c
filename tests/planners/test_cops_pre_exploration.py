"""delve.planners.cops.pre_exploration: Problem 1."""
import pytest

from delve.planners.cops import InfeasibleProblem, solve_pre_exploration, validate_plan

from .cops_networks import cut_off, fork, team


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


def test_only_capable_robots_explore():
    net = fork(team(1) + [{"name": "carrier", "location": "s0", "explorer": False}], frontiers=("a3",))
    plan = solve_pre_exploration(net)
    assert validate_plan(net, plan) == []
    assert plan.explore == {"r1": "a3"}


def test_infeasible_problems_say_why_in_one_line():
    with pytest.raises(InfeasibleProblem) as err:
        solve_pre_exploration(cut_off())
    assert str(err.value) == "frontier x2 cannot be reached by any capable robot"
