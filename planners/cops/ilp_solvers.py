"""The two solver back-ends of a built model: HiGHS fed the model as arrays, and pulp
(CBC, or HiGHS through pulp). Both write the solution into the model's variables.

HiGHS runs single-threaded with a fixed random seed and presolve's probing off (it
can take most of a solve on these models). Its limits are counted in work
(:class:`~.budget.SolveLimits`): branch-and-bound nodes (``mip_max_nodes``) and
checkpoint work, counted at the calls HiGHS makes to its interrupt callback at
fixed points of the search (after presolve, after each round of cuts at the root,
after each node or dive), so a solve stops at the same point of its search however
busy the machine is. HiGHS gives the callback no iteration count, and its
``simplex_iteration_limit`` does not apply to the LPs of a MIP; the root LP runs
to its end (it is deterministic too), so a warm-started model of more than
``search_max_rows`` rows is not searched at all. Its time limit is the safety stop:
a solve it ends is reported (``Outcome.safety_stop``).

A warm start (trajectories, e.g. a greedy plan) is first completed with the
motion fixed and then handed over as the first incumbent, so a solve stopped by its
limits, or because its plan has stopped improving, returns at least that plan, with
its optimality gap.

CBC (through pulp, the fallback without highspy) is bounded by its node limit
(``maxNodes``, at most :data:`CBC_MAX_NODES`); pulp gives it no checkpoint
callback, so it has no stall stop and its root (cuts, heuristics) is bounded only by
CBC's own rules, and it gets no warm start. Its simplex iterations are read from its
log. Single-threaded with a node limit, CBC gave the same iterations and plan quiet
and under load in our one check (a 25-location pre-exploration with 20 nodes: 25 s
quiet, 57 s with both cores busy); its safety stop (``-sec``) is its only wall-clock
limit.
"""
from __future__ import annotations

import math
import os
import re
import sys
import tempfile
import time
import warnings
from collections import defaultdict
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import pulp

from .budget import SolveLimits
from .ilp_model import ConnectivityModel
from .ilp_problem import SolverOptions

#: HiGHS presolve_rule_off bit that turns probing off.
PRESOLVE_NO_PROBING = 1 << 15
#: CBC's node limit, whatever ``max_nodes`` allows: its nodes cost tens of times
#: HiGHS's on these models (a 25-location cycle: 9 s at the root, 25 s with 20 nodes).
CBC_MAX_NODES = 10


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


def make_solver(opts: SolverOptions, limits: SolveLimits | None = None,
                log_path: str | None = None) -> tuple[str, Any]:
    """The pulp solver for ``opts`` within ``limits`` (default: those of ``opts``):
    (its name, the solver)."""
    name = available_solver(opts.solver)
    lim = limits or SolveLimits.of(opts)
    kw = {"msg": False, "timeLimit": lim.time_limit_s, "gapRel": opts.mip_gap, "threads": opts.threads}
    if name == "highs":
        return name, pulp.HiGHS(**kw)
    if name == "highs_cmd":  # pragma: no cover - only without highspy
        return name, pulp.HiGHS_CMD(**kw)
    kw["maxNodes"] = CBC_MAX_NODES if lim.max_nodes is None else min(int(lim.max_nodes), CBC_MAX_NODES)
    if log_path is not None:
        kw["logPath"] = log_path
    with warnings.catch_warnings():  # the bundled CBC is the documented fallback
        warnings.simplefilter("ignore", DeprecationWarning)
        return name, pulp.PULP_CBC_CMD(**kw)


@dataclass
class Outcome:
    """What one solve of a built model gave: ``status`` is "optimal", "feasible" (an
    incumbent when a limit stopped the solve), "infeasible" or "unknown" (no plan and
    no proof either way: a limit stopped the solve). ``stop`` says which limit
    ended it ("nodes", "work", "stall", "size": too large to search, "safety"; None:
    it ran to its end),
    ``work`` its simplex iterations, ``nodes`` and ``checkpoints`` its search."""

    status: str
    gap: float | None = None
    stop: str | None = None
    work: int = 0
    nodes: int = 0
    checkpoints: int = 0

    @property
    def safety_stop(self) -> bool:
        """Whether the wall-clock safety stop ended the solve."""
        return self.stop == "safety"

    @property
    def timed_out(self) -> bool:
        """Whether a limit ended the solve before it finished."""
        return self.stop is not None


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



@contextmanager
def _stdout_silenced():
    """Point the process's standard output (file descriptor 1) at /dev/null for the
    block: highspy's ``Highs()`` prints HiGHS's banner from C++ while it is built,
    before ``output_flag`` can be set (ERGO-Code/HiGHS#1702, #2749)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)

def solve_highs(model: ConnectivityModel, opts: SolverOptions, limits: SolveLimits) -> Outcome:
    """Hand the model to HiGHS as arrays (much faster than pulp's column-by-column
    transfer), solve it within ``limits`` and copy the solution back into the pulp
    variables."""
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
    with _stdout_silenced():
        h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", int(opts.threads or 1))
    h.setOptionValue("random_seed", 0)
    if opts.mip_gap is not None:
        h.setOptionValue("mip_rel_gap", float(opts.mip_gap))
    # presolve's probing can take most of a solve on these models (HiGHS's own advice)
    h.setOptionValue("presolve_rule_off", PRESOLVE_NO_PROBING)
    h.passModel(lp)
    M = highspy.HighsModelStatus
    t_start = time.perf_counter()

    def safety_left() -> float:  # the safety stop, whatever HiGHS's clock counts from
        lim = limits.time_limit_s
        return 1e30 if lim is None else float(max(lim - (time.perf_counter() - t_start), 0.01))

    h.setOptionValue("time_limit", safety_left())
    work = nodes = 0
    warm = warm_values(model)
    start = None
    if warm:
        # complete the given trajectories first (motion fixed: an easy problem), then hand
        # the whole solution to the real solve as its first incumbent
        idx = np.fromiter(warm.keys(), dtype=np.int32, count=len(warm))
        val = np.fromiter(warm.values(), dtype=float, count=len(warm))
        h.changeColsBounds(len(warm), idx, val, val)
        h.setOptionValue("mip_max_nodes", _int_limit(limits.max_nodes))
        h.run()
        info = h.getInfo()
        work, nodes = work + max(info.simplex_iteration_count, 0), nodes + max(info.mip_node_count, 0)
        if h.getModelStatus() == M.kTimeLimit:
            return Outcome("unknown", stop="safety", work=work, nodes=nodes)
        if info.primal_solution_status == 2:
            start = list(h.getSolution().col_value)
            bound = model.p.objective_bound
            if bound is not None and opts.mip_gap is not None:
                gap = (bound - info.objective_function_value) / max(abs(bound), 1e-9)
                if gap <= opts.mip_gap:  # good enough: no search
                    for v, x in zip(cols, start):
                        v.varValue = x
                    return Outcome("optimal", max(gap, 0.0), work=work, nodes=nodes)
            if limits.max_rows is not None and len(model.rows) > limits.max_rows:
                # too large to search: its root LP alone, which no callback can stop, takes long
                for v, x in zip(cols, start):
                    v.varValue = x
                return Outcome("feasible", None, stop="size", work=work, nodes=nodes)
        h.changeColsBounds(len(warm), idx, col_lower[idx], col_upper[idx])
    h.setOptionValue("mip_max_nodes", _int_limit(limits.max_nodes))
    h.setOptionValue("time_limit", safety_left())
    if start is not None:
        sol = highspy.HighsSolution()
        sol.col_value = start
        sol.value_valid = True
        h.setSolution(sol)
    stall = limits.stall_work if not model.p.feasibility_only else None
    max_work = limits.max_work
    weight = checkpoint_weight(len(model.rows))
    # checkpoints, their work, work at the last improvement (None: no plan yet), why it stopped
    state = {"n": 0, "work": 0.0, "last": 0.0 if start is not None else None, "stop": None}

    def improved(_event) -> None:
        state["last"] = state["work"]

    def check(event) -> None:
        state["n"] += 1
        if math.isfinite(event.data_out.mip_dual_bound):  # the checkpoints before the root LP cost little
            state["work"] += weight
        w, last = state["work"], state["last"]
        if max_work is not None and w >= max_work:
            state["stop"] = "work"
            event.interrupt()
        elif stall and last is not None and w - last >= max(stall, 0.5 * last):
            state["stop"] = "stall"
            event.interrupt()

    h.cbMipImprovingSolution.subscribe(improved)
    h.cbMipInterrupt.subscribe(check)
    h.run()
    status = h.getModelStatus()
    info = h.getInfo()
    work, nodes = work + max(info.simplex_iteration_count, 0), nodes + max(info.mip_node_count, 0)
    stop = {M.kTimeLimit: "safety", M.kInterrupt: state["stop"]}.get(status)
    if stop is None and status not in (M.kOptimal, M.kInfeasible, M.kUnboundedOrInfeasible):
        stop = "nodes"  # node limit (HiGHS reports an iteration or solution limit)
    done = {"work": work, "nodes": nodes, "checkpoints": state["n"], "stop": stop}
    if status in (M.kInfeasible, M.kUnboundedOrInfeasible):
        return Outcome("infeasible", **done)
    values = None
    gap = float(info.mip_gap) if math.isfinite(info.mip_gap) else None
    if info.primal_solution_status == 2:
        values = h.getSolution().col_value
    elif start is not None:  # nothing better than the completed warm start
        values, gap = start, None
    if values is None:
        return Outcome("unknown", **done)
    for v, x in zip(cols, values):
        v.varValue = x
    if status == M.kOptimal:
        return Outcome("optimal", 0.0 if gap is None else gap, **done)
    return Outcome("feasible", gap, **done)


def checkpoint_weight(rows: int) -> float:
    """The work of one checkpoint of a model with ``rows`` rows: (rows / 2000)², at least
    0.5. A round of cuts or a node re-solves the LP: each simplex iteration costs more on
    a larger model, and a larger model takes more of them (measured on COPS models:
    about 10 ms a checkpoint at 500 rows, 25 ms at 2000, 0.1 s at 5000, 0.5 s at
    10 000)."""
    return max(0.5, (rows / 2000.0) ** 2)


def _int_limit(n: int | None) -> int:
    """A HiGHS integer limit (its default, 2^31 - 1, for none)."""
    return 2147483647 if n is None else int(n)


def solve_pulp(model: ConnectivityModel, opts: SolverOptions, limits: SolveLimits) -> Outcome:
    """Hand the model to a pulp solver (CBC, or HiGHS's command line) row by row,
    within ``limits`` (CBC: its node limit and the safety stop)."""
    for row in model.rows:
        model.lp += row
    model.lp += model.objective
    fd, log_path = tempfile.mkstemp(prefix="cops_cbc_", suffix=".log")
    os.close(fd)
    try:
        _name, solver = make_solver(opts, limits, log_path)
        model.lp.solve(solver)
        with open(log_path, errors="replace") as f:
            log = f.read()
    finally:
        os.unlink(log_path)
    work, nodes, stop = _cbc_figures(log)
    status, sol_status = model.lp.status, model.lp.sol_status
    done = {"work": work, "nodes": nodes, "stop": stop}
    if sol_status == pulp.LpSolutionInfeasible or status == pulp.LpStatusInfeasible:
        return Outcome("infeasible", **done)
    if sol_status == pulp.LpSolutionOptimal:
        return Outcome("optimal", 0.0, **done)
    if stop is None:
        stop = done["stop"] = "nodes"
    if sol_status == pulp.LpSolutionIntegerFeasible:
        return Outcome("feasible", None, **done)
    return Outcome("unknown", **done)


def _cbc_figures(log: str) -> tuple[int, int, str | None]:
    """Simplex iterations, nodes and the limit that stopped CBC, from its log."""
    its = re.findall(r"Total iterations:\s*(\d+)", log)
    nodes = re.findall(r"Enumerated nodes:\s*(\d+)", log)
    stopped = re.search(r"Result - Stopped on (\w+)", log)  # "time limit", "node limit", ...
    stop = None if stopped is None else "safety" if stopped.group(1) == "time" else "nodes"
    return (int(its[-1]) if its else 0), (int(nodes[-1]) if nodes else 0), stop
