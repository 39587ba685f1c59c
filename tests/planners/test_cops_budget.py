"""delve.planners.cops.budget: work limits of each solve within a call's budget, the
meter of work and safety stops, and the safety stop of a call."""
import time

from delve.planners.cops import SolverOptions
from delve.planners.cops.budget import MIN_SAFETY_S, MIN_SOLVE_WORK, Budget, SolveLimits
from delve.planners.cops.meter import Meter


def test_without_a_total_every_solve_gets_its_own_limits():
    opts = SolverOptions(max_work=70.0, probe_max_work=20.0, total_work=None, time_limit_s=7.0,
                         probe_time_limit_s=2.0, total_time_limit_s=None)
    budget = Budget(opts)
    assert budget.left() is None and not budget.spent()
    assert budget.limits() == SolveLimits(opts.max_nodes, 70.0, opts.stall_work, 7.0, opts.search_max_rows)
    assert budget.limits(probe=True) == SolveLimits(opts.probe_max_nodes, 20.0, None, 2.0, opts.search_max_rows)
    assert budget.options(0.5).total_work is None


def test_work_counts_in_every_enclosing_meter_and_shares_what_is_left():
    budget = Budget(SolverOptions(total_work=1000, max_work=50.0))
    sub = Budget(budget.options(0.5))
    assert sub.total == 500
    sub.opts.meter.add(work=300, solves=1)
    assert (sub.left(), budget.left(), budget.meter.solves) == (200, 700, 1)
    assert sub.spent(reserve=200) and not budget.spent(reserve=200)
    sub.opts.meter.add(work=400, solves=1)
    assert sub.left() == 0 and sub.limits().max_work == MIN_SOLVE_WORK  # a solve that must run still runs
    assert budget.meter.figures() == {"work": 700, "solves": 2, "safety_stops": 0}


def test_a_call_past_its_safety_stop_stops_its_search_and_says_so():
    outer = Meter()
    budget = Budget(SolverOptions(total_time_limit_s=0.01, time_limit_s=100.0, meter=outer))
    time.sleep(0.02)
    assert budget.spent() and budget.spent()
    assert len(outer.safety_stops) == 1 and "safety stop of 0.01 s" in outer.safety_stops[0]
    assert budget.limits().time_limit_s == MIN_SAFETY_S  # its solves get the safety stop's minimum
