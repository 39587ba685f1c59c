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
from dataclasses import replace

import pulp

from .budget import SolveLimits
from .errors import SolverTimeout
from .ilp_constraints import build_model
from .ilp_model import value
from .ilp_problem import ConnectivityProblem
from .ilp_solvers import Outcome, available_solver, solve_highs, solve_pulp
from .network import MCNetwork
from .plan import Plan
from .plan_extraction import extract_plan

def solve_connectivity(p: ConnectivityProblem, *, time_limit_s: float | None = None,
                       limits: SolveLimits | None = None) -> Plan | None:
    """Solve ``p`` at its horizon: the plan, or None when infeasible at this horizon.

    The solve is bounded by ``limits`` (default: those of ``p.options``, a feasibility
    probe's for ``p.feasibility_only``): nodes and checkpoint work, and a wall-clock
    safety stop, which ``time_limit_s`` overrides. When a limit stops the
    solve with a plan in hand, that plan is returned (``meta["status"]`` is
    "feasible" and ``meta["gap"]`` its optimality gap, None when unknown);
    ``meta["work"]`` is its simplex iterations and ``meta["stop"]`` the limit that
    ended it. Raises :class:`SolverTimeout` when a limit stops the solve before any
    plan is found. The work and any safety stop are counted in ``p.options.meter``.
    """
    t0 = time.perf_counter()
    for r, s in p.positions.items():
        if s not in p.network:
            raise ValueError(f"robot '{r}' at unknown location '{s}'")
    model = build_model(p)
    if model.infeasible_reason:
        return None
    lim = limits or SolveLimits.of(p.options, probe=p.feasibility_only)
    if time_limit_s is not None:
        lim = replace(lim, time_limit_s=time_limit_s)
    solver_name = available_solver(p.options.solver)
    if not model.vars:
        out = Outcome("optimal", 0.0)
    elif solver_name == "highs":
        out = solve_highs(model, p.options, lim)
    else:
        out = solve_pulp(model, p.options, lim)
    if p.options.meter is not None:
        p.options.meter.add(out.work, 1, f"{p.phase} solve at T={p.horizon} ran past its safety stop of "
                                         f"{lim.time_limit_s:g} s" if out.safety_stop else None)
    if out.status == "infeasible":
        return None
    if out.status == "unknown":
        if out.safety_stop:
            raise SolverTimeout(f"no plan found within the safety stop of {lim.time_limit_s:g} s "
                                f"(horizon T={p.horizon})")
        raise SolverTimeout(f"no plan found within the work limit ({_limit_text(lim, out)}, "
                            f"horizon T={p.horizon})")
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
        "work": out.work,
        "stop": out.stop,
        "variables": len(model.vars),
        "constraints": len(model.rows),
    })
    return plan


def _limit_text(lim: SolveLimits, out: Outcome) -> str:
    if out.stop == "work":
        return f"{lim.max_work:g} checkpoint work"
    if out.stop == "nodes":
        return f"{lim.max_nodes} nodes"
    return f"{out.stop or 'a limit'}"


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
