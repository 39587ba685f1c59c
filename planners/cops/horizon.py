"""Horizons: the search over horizons T for a plan, and cutting a plan after its last
action (solves carry a tiny cost per action and step index, :data:`TIME_WEIGHT`, so
that of equally good plans the earliest wins and a generous horizon can be cut)."""
from __future__ import annotations

from typing import Callable, Mapping

from .errors import SolverTimeout
from .plan import Plan

#: Cost per action (move or message) and step index that makes the solver prefer early
#: actions among equally good plans; small against any real cost (0.1 a message).
TIME_WEIGHT = 1e-5


def trim_plan(plan: Plan) -> Plan:
    """Cut ``plan`` after its last action (move or message); nothing changes after it."""
    T = plan.horizon
    last = max((c.t for c in plan.communications), default=0)
    for traj in plan.trajectories.values():
        for t in range(T - 1, last - 1, -1):
            if traj[t] != traj[t + 1]:
                last = t + 1
                break
    if last < T:
        plan.trajectories = {r: traj[:last + 1] for r, traj in plan.trajectories.items()}
        plan.horizon = last
    return plan


def horizon_of(traj: Mapping[str, list[str]] | None) -> int | None:
    """The horizon of trajectories (robot -> locations from t = 0); None for None."""
    if traj is None:
        return None
    return max((len(tr) for tr in traj.values()), default=1) - 1


def search_horizons(make: Callable[[int], Plan | None], lo: int, hi: int, improve: bool, patience: int,
                    spent: Callable[[], bool] | None = None) -> tuple[Plan | None, int | None]:
    """Solve make(T) for T = lo, lo+1, ...: the first feasible plan, then (``improve``)
    while the objective still grows (at most ``patience`` horizons without gain), until
    ``spent()`` says the work budget is spent."""
    best, best_T, stall = None, None, 0
    timed_out = None
    T = lo
    while T <= hi:
        try:
            plan = make(T)
        except SolverTimeout as err:
            timed_out = err
            if best is not None:
                break
            T += 1
            if spent is not None and spent():
                break
            continue
        if plan is not None:
            if best is None or plan.meta["objective"] > best.meta["objective"] + 1e-6:
                best, best_T, stall = plan, T, 0
            else:
                stall += 1
            if not improve or stall >= patience:
                break
        elif best is not None:
            break
        if spent is not None and spent():
            break
        T += 1
    if best is None and timed_out is not None:
        raise timed_out
    return best, best_T
