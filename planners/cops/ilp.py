"""Solving one intermittent-connectivity problem: the integer program over its
time-expanded network.

Given a mobility-communication network N, robots at initial locations s^r_0,
master robots R_m holding the plan m, a horizon T, intermittent-connectivity
constraints (src, snk), frontier rewards R(s, k), and the extensions (static
robots, collision constraints, exploration-capable robots), :func:`solve_connectivity`
finds an information-consistent plan Π = (Πt, Πc) that maximises
Σ R(s, k) − C(Π) with C(Π) the cost of equation (1).

The problem (:mod:`.ilp_problem`) becomes a model (:mod:`.ilp_model`, one function
per constraint family in :mod:`.ilp_constraints`), a back-end solves it
(:mod:`.ilp_solvers`) and the plan is read out of the solution
(:mod:`.plan_extraction`).
"""
from __future__ import annotations

import time

import pulp

from .errors import SolverTimeout
from .ilp_constraints import build_model
from .ilp_model import value
from .ilp_problem import ConnectivityProblem
from .ilp_solvers import Outcome, available_solver, solve_highs, solve_pulp
from .network import MCNetwork
from .plan import Plan
from .plan_extraction import extract_plan

#: However long building the model took, the solver gets at least this long (s).
MIN_SOLVER_TIME_S = 0.2


def solve_connectivity(p: ConnectivityProblem, *, time_limit_s: float | None = None) -> Plan | None:
    """Solve ``p`` at its horizon: the plan, or None when infeasible at this horizon.

    ``time_limit_s`` overrides ``p.options.time_limit_s`` for this call (building the
    model included; the solver gets at least a fraction of a second). When the
    limit passes with a plan in hand, that plan is returned (``meta["status"]`` is
    "feasible" and ``meta["gap"]`` its optimality gap, None when unknown). Raises
    :class:`SolverTimeout` when the limit passes before any plan is found.
    """
    t0 = time.perf_counter()
    for r, s in p.positions.items():
        if s not in p.network:
            raise ValueError(f"robot '{r}' at unknown location '{s}'")
    model = build_model(p)
    if model.infeasible_reason:
        return None
    limit = p.options.time_limit_s if time_limit_s is None else time_limit_s
    if limit is not None:  # the limit bounds the whole call, model building included
        limit = max(limit - (time.perf_counter() - t0), min(limit, MIN_SOLVER_TIME_S))
    solver_name = available_solver(p.options.solver)
    if not model.vars:
        out = Outcome("optimal", 0.0)
    elif solver_name == "highs":
        out = solve_highs(model, p.options, limit)
    else:
        out = solve_pulp(model, p.options, limit)
    if out.status == "infeasible":
        return None
    if out.status == "unknown":
        if out.timed_out:
            raise SolverTimeout(f"no plan found within the time limit of {limit:g} s (horizon T={p.horizon})")
        return None
    plan = extract_plan(model)
    reward = sum(value(v) * c for v, c in _terms(model.reward_terms))
    cost = sum(value(v) * c for v, c in _terms(model.cost_terms))
    plan.meta.update({
        "status": out.status,
        "gap": None if out.gap is None else round(out.gap, 6),
        "objective": round(reward - cost, 6),
        "reward": round(reward, 6),
        "cost": round(plan_cost(p.network, plan), 6),
        "ilp_cost": round(cost, 6),
        "solver": solver_name,
        "solve_time_s": round(time.perf_counter() - t0, 4),
        "variables": len(model.vars),
        "constraints": len(model.rows),
    })
    return plan


def _terms(terms: list) -> list[tuple[pulp.LpVariable, float]]:
    """(variable, coefficient) of every term of the expressions ``terms``."""
    out = []
    for t in terms:
        for v, c in t.items():
            out.append((v, c))
    return out


def plan_cost(net: MCNetwork, plan: Plan) -> float:
    """C(Π) of equation (1): mobility costs plus communication costs of every tuple."""
    cost = 0.0
    for traj in plan.trajectories.values():
        for a, b in zip(traj, traj[1:]):
            if a != b:
                cost += net.mobility_cost(a, b)
    for c in plan.communications:
        cost += net.communication_cost(plan.location(c.sender, c.t), plan.location(c.receiver, c.t))
    return cost
