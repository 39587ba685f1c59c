"""The two solver back-ends of a built model: HiGHS fed the model as arrays, and pulp
(CBC, or HiGHS through pulp). Both write the solution into the model's variables.

HiGHS runs with presolve's probing off (it can take the whole time limit on these
models). A warm start (trajectories, e.g. a greedy plan) is first completed with the
motion fixed and then handed over as the first incumbent, so a solve stopped by its
time limit, or because its plan has stopped improving (``SolverOptions.stall_time_s``),
returns at least that plan, with its optimality gap.
"""
from __future__ import annotations

import math
import time
import warnings
from collections import defaultdict
from dataclasses import dataclass
from typing import Any

import pulp

from .ilp_model import ConnectivityModel
from .ilp_problem import SolverOptions

#: HiGHS presolve_rule_off bit that turns probing off.
PRESOLVE_NO_PROBING = 1 << 15


def available_solver(name: str | None = None) -> str:
    """The solver that will be used: ``"highs"`` when importable (or asked), else ``"cbc"``."""
    if name not in (None, "highs", "cbc"):
        raise ValueError(f"unknown solver '{name}' (use 'highs' or 'cbc')")
    if name in (None, "highs"):
        try:
            if pulp.HiGHS(msg=False).available():
                return "highs"
        except Exception:  # pragma: no cover - pulp without the highs API
            pass
        if name == "highs":
            try:
                if pulp.HiGHS_CMD(msg=False).available():
                    return "highs_cmd"
            except Exception:  # pragma: no cover
                pass
            raise ValueError("solver 'highs' is not installed (pip install highspy)")
    return "cbc"


def make_solver(opts: SolverOptions) -> tuple[str, Any]:
    """The pulp solver for ``opts``: (its name, the solver)."""
    name = available_solver(opts.solver)
    kw = {"msg": False, "timeLimit": opts.time_limit_s, "gapRel": opts.mip_gap, "threads": opts.threads}
    if name == "highs":
        return name, pulp.HiGHS(**kw)
    if name == "highs_cmd":  # pragma: no cover - only without highspy
        return name, pulp.HiGHS_CMD(**kw)
    with warnings.catch_warnings():  # the bundled CBC is the documented fallback
        warnings.simplefilter("ignore", DeprecationWarning)
        return name, pulp.PULP_CBC_CMD(**kw)


@dataclass
class Outcome:
    """What one solve of a built model gave: ``status`` is "optimal", "feasible" (an
    incumbent when the time limit passed), "infeasible" or "unknown" (no plan and no
    proof either way, usually the time limit)."""

    status: str
    gap: float | None = None
    timed_out: bool = False


def warm_values(model: ConnectivityModel) -> dict[int, float] | None:
    """Column values of the motion variables for ``p.warm_start`` (None when the
    trajectories do not fit the model: a robot missing, a move the model pruned)."""
    ws = model.p.warm_start
    if not ws:
        return None
    T = model.T
    out: dict[int, float] = {}
    counts: dict[tuple[int, int, str, str], int] = defaultdict(int)
    for r in model.robots:
        traj = ws.get(r)
        if not traj or traj[0] != model.pos[r] or len(traj) > T + 1:
            return None
        traj = list(traj) + [traj[-1]] * (T + 1 - len(traj))
        c = model.class_of[r]
        if c.static:
            if any(s != c.start for s in traj):
                return None
            continue
        for t in range(T):
            counts[c.idx, t, traj[t], traj[t + 1]] += 1
    for key, n in counts.items():
        var = model.x.get(key)
        if var is None:
            return None
        out[var._cops_col] = float(n)
    for key, var in model.x.items():
        out.setdefault(var._cops_col, 0.0)
    return out


def solve_highs(model: ConnectivityModel, opts: SolverOptions, time_limit: float | None) -> Outcome:
    """Hand the model to HiGHS as arrays (much faster than pulp's column-by-column
    transfer) and copy the solution back into the pulp variables."""
    import highspy
    import numpy as np

    inf = highspy.kHighsInf
    cols = model.vars
    for i, v in enumerate(cols):
        v._cops_col = i
    n = len(cols)
    lp = highspy.HighsLp()
    lp.num_col_ = n
    lp.num_row_ = len(model.rows)
    cost = np.zeros(n)
    for v, a in model.objective.items():
        cost[v._cops_col] += a
    lp.col_cost_ = cost
    lp.offset_ = float(model.objective.constant or 0.0)
    col_lower = np.array([-inf if v.lowBound is None else float(v.lowBound) for v in cols], dtype=float)
    col_upper = np.array([inf if v.upBound is None else float(v.upBound) for v in cols], dtype=float)
    lp.col_lower_, lp.col_upper_ = col_lower, col_upper
    starts, index, value, lower, upper = [0], [], [], [], []
    for row in model.rows:
        for v, a in row.items():
            if a:
                index.append(v._cops_col)
                value.append(a)
        starts.append(len(index))
        rhs = -float(row.constant or 0.0)
        if row.sense == pulp.LpConstraintEQ:
            lower.append(rhs)
            upper.append(rhs)
        elif row.sense == pulp.LpConstraintLE:
            lower.append(-inf)
            upper.append(rhs)
        else:
            lower.append(rhs)
            upper.append(inf)
    lp.row_lower_ = np.array(lower, dtype=float)
    lp.row_upper_ = np.array(upper, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
    lp.a_matrix_.num_col_ = n
    lp.a_matrix_.num_row_ = len(model.rows)
    lp.a_matrix_.start_ = np.array(starts, dtype=np.int32)
    lp.a_matrix_.index_ = np.array(index, dtype=np.int32)
    lp.a_matrix_.value_ = np.array(value, dtype=float)
    kint, kcont = highspy.HighsVarType.kInteger, highspy.HighsVarType.kContinuous
    lp.integrality_ = [kint if v.cat == pulp.LpInteger else kcont for v in cols]
    lp.sense_ = highspy.ObjSense.kMaximize
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", int(opts.threads or 1))
    h.setOptionValue("random_seed", 0)
    if opts.mip_gap is not None:
        h.setOptionValue("mip_rel_gap", float(opts.mip_gap))
    # presolve's probing can take the whole time limit on these models (HiGHS's own advice)
    h.setOptionValue("presolve_rule_off", PRESOLVE_NO_PROBING)
    h.passModel(lp)
    M = highspy.HighsModelStatus
    t_start = time.perf_counter()

    def remaining() -> float | None:
        return None if time_limit is None else max(time_limit - (time.perf_counter() - t_start), 0.01)

    warm = warm_values(model)
    start = None
    if warm:
        # complete the given trajectories first (motion fixed: an easy problem), then hand
        # the whole solution to the real solve as its first incumbent
        idx = np.fromiter(warm.keys(), dtype=np.int32, count=len(warm))
        val = np.fromiter(warm.values(), dtype=float, count=len(warm))
        h.changeColsBounds(len(warm), idx, val, val)
        lim = remaining()
        h.setOptionValue("time_limit", 1e30 if lim is None else float(max(0.5 * lim, 0.01)))
        h.run()
        if h.getInfo().primal_solution_status == 2:
            start = list(h.getSolution().col_value)
        h.changeColsBounds(len(warm), idx, col_lower[idx], col_upper[idx])
    lim = remaining()
    h.setOptionValue("time_limit", 1e30 if lim is None else float(lim))
    if start is not None:
        sol = highspy.HighsSolution()
        sol.col_value = start
        sol.value_valid = True
        h.setSolution(sol)
    stall = opts.stall_time_s if not model.p.feasibility_only else None
    if stall:
        last = [time.perf_counter() if start is not None else None]

        def improved(_event) -> None:
            last[0] = time.perf_counter()

        def check(event) -> None:
            t = last[0]
            if t is not None and time.perf_counter() - t > max(stall, 0.5 * (t - t_start)):
                event.interrupt()

        h.cbMipImprovingSolution.subscribe(improved)
        h.cbMipInterrupt.subscribe(check)
        h.cbSimplexInterrupt.subscribe(check)
    h.run()
    status = h.getModelStatus()
    info = h.getInfo()
    if status in (M.kInfeasible, M.kUnboundedOrInfeasible):
        return Outcome("infeasible")
    values = None
    gap = float(info.mip_gap) if math.isfinite(info.mip_gap) else None
    if info.primal_solution_status == 2:
        values = h.getSolution().col_value
    elif start is not None:  # nothing better than the completed warm start in time
        values, gap, status = start, None, M.kTimeLimit
    if values is None:
        return Outcome("unknown", timed_out=status == M.kTimeLimit)
    for v, x in zip(cols, values):
        v.varValue = x
    if status == M.kOptimal:
        return Outcome("optimal", 0.0 if gap is None else gap)
    return Outcome("feasible", gap, timed_out=status == M.kTimeLimit)


def solve_pulp(model: ConnectivityModel, opts: SolverOptions, time_limit: float | None) -> Outcome:
    """Hand the model to a pulp solver (CBC, or HiGHS's command line) row by row."""
    o = SolverOptions(time_limit_s=time_limit, mip_gap=opts.mip_gap, solver=opts.solver, threads=opts.threads)
    _name, solver = make_solver(o)
    for row in model.rows:
        model.lp += row
    model.lp += model.objective
    t0 = time.perf_counter()
    model.lp.solve(solver)
    status, sol_status = model.lp.status, model.lp.sol_status
    if sol_status == pulp.LpSolutionInfeasible or status == pulp.LpStatusInfeasible:
        return Outcome("infeasible")
    if sol_status == pulp.LpSolutionOptimal:
        return Outcome("optimal", 0.0)
    timed_out = time_limit is not None and time.perf_counter() - t0 >= 0.9 * time_limit
    if sol_status == pulp.LpSolutionIntegerFeasible:
        return Outcome("feasible", None, timed_out)
    return Outcome("unknown", timed_out=timed_out)
