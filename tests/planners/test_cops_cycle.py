"""delve.planners.cops.cycle: one COPS cycle without clustering."""
from delve.planners.cops import SolverOptions, plan_cycle, validate_plan

from .cops_networks import fork, team


def test_a_cycle_passes_the_validator():
    net = fork(team(2))
    cyc = plan_cycle(net, clustering=False)
    assert validate_plan(net, cyc.pre) == []
    assert validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post) == []
    assert set(cyc.exploration) == set(cyc.pre.explore)
    assert all(task.steps >= 4 for task in cyc.exploration.values())


def test_greedy_plans_bound_the_horizon_and_warm_start_the_solver():
    net = fork(team(4))
    cyc = plan_cycle(net, clustering=False, options=SolverOptions(total_work=4000))
    assert validate_plan(net, cyc.pre) == []
    # trimmed after the last action: the last step moves someone or sends something
    T = cyc.pre.horizon
    last_moves = any(tr[T - 1] != tr[T] for tr in cyc.pre.trajectories.values())
    assert last_moves or any(c.t == T for c in cyc.pre.communications)
    assert cyc.pre.meta["status"] in ("optimal", "feasible")
    assert cyc.meta["solves"] >= 2 and cyc.meta["safety_stops"] == 0 and cyc.meta["work"] >= 0
