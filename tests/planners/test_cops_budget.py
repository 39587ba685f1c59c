"""delve.planners.cops.budget: the time limit of each solve within a call's budget."""
from delve.planners.cops import SolverOptions
from delve.planners.cops.budget import MIN_SOLVE_TIME_S, Budget


def test_without_a_total_every_solve_gets_its_own_limit():
    opts = SolverOptions(time_limit_s=7.0, probe_time_limit_s=2.0, total_time_limit_s=None)
    budget = Budget(opts)
    assert budget.left() is None and budget.options(0.5) is opts
    assert budget.limit() == 7.0 and budget.limit(share=0.1, probe=True) == 2.0


def test_a_solve_gets_at_most_its_share_of_the_time_left_but_never_nothing():
    opts = SolverOptions(time_limit_s=1000.0, probe_time_limit_s=1.0, total_time_limit_s=100.0)
    budget = Budget(opts)
    assert budget.limit(probe=True) == 1.0
    assert budget.limit(share=0.5) <= 50.0 and budget.options(0.5).total_time_limit_s <= 50.0
    assert budget.limit(share=0.0) == MIN_SOLVE_TIME_S
