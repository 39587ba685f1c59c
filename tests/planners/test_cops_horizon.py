"""delve.planners.cops.horizon: cutting plans after their last action, searching horizons."""
import pytest

from delve.planners.cops import Communication, Plan, SolverTimeout
from delve.planners.cops.horizon import horizon_of, search_horizons, trim_plan


def test_a_plan_is_cut_after_its_last_move_or_message():
    plan = Plan(horizon=5, trajectories={"a": ["s0", "s1", "s1", "s1", "s1", "s1"], "b": ["s2"] * 6},
                communications=[Communication(2, "a", "b", "a")])
    trim_plan(plan)
    assert plan.horizon == 2 and plan.trajectories == {"a": ["s0", "s1", "s1"], "b": ["s2"] * 3}
    assert horizon_of(plan.trajectories) == 2 and horizon_of(None) is None


def test_the_search_stops_when_the_objective_no_longer_grows():
    objective = {3: None, 4: 1.0, 5: 2.0, 6: 2.0, 7: 9.0}
    tried = []

    def make(T):
        tried.append(T)
        return None if objective[T] is None else Plan(T, {}, meta={"objective": objective[T]})

    plan, T = search_horizons(make, 3, 7, True, 1, None)
    assert (T, plan.meta["objective"], tried) == (5, 2.0, [3, 4, 5, 6])
    plan, T = search_horizons(make, 3, 7, False, 1, None)
    assert T == 4 and tried[-1] == 4


def test_the_search_raises_the_timeout_when_no_horizon_gave_a_plan():
    def make(T):
        raise SolverTimeout(f"no plan at T={T}")

    with pytest.raises(SolverTimeout, match="T=4"):
        search_horizons(make, 2, 4, True, 1, None)
