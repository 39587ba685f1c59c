"""Problem 2 (post-exploration): an information-consistent plan in which the base
station (or another sink) receives the information of every source robot, at least
cost.

The horizon is bounded by a greedy plan; feasibility probes bisect below it while
the call's work budget lasts, and the least-cost plan is solved at the smallest
horizon found feasible, warm-started, then cut after its last action.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable, Iterable, Mapping

import networkx as nx

from .budget import Budget
from .distances import information_distance, m_distance
from .errors import InfeasibleProblem, SolverTimeout
from .greedy import greedy_post_plan
from .horizon import TIME_WEIGHT, horizon_of, trim_plan
from .ilp import solve_connectivity
from .ilp_problem import ConnectivityProblem, SolverOptions
from .network import MCNetwork
from .plan import Plan, Requirement, idle_plan
from .roles import master_robots, robot_sets

#: Work (simplex iterations) that must be left of the budget for another probe of the
#: bisection to start; the least-cost solve at the horizon found gets the rest.
PROBE_RESERVE = 2000


def solve_post_exploration(network: MCNetwork, *, sources: Iterable[str], positions: Mapping[str, str] | None = None,
                           masters: Iterable[str] | None = None, base_station: str | None = None,
                           static: Iterable[str] | None = None, collision_robots: Iterable[str] | None = None,
                           collision_locations: Iterable[str] | None = None,
                           holdings: Mapping[str, Iterable[str]] | None = None,
                           horizon: int | None = None, max_horizon: int | None = None,
                           static_sink: bool = True, sink_final_location: str | None = None,
                           options: SolverOptions | None = None,
                           phase: str = "post") -> Plan:
    """Problem 2: an information-consistent plan, with ``masters`` (R_m) as masters, in
    which the base station receives the information of every robot in ``sources``
    (R_f), at least cost C(Π).

    Without ``horizon`` the horizon is bounded by a greedy plan
    (:func:`greedy_post_plan`); feasibility probes (each within the probe limits of
    ``options``) bisect below it while the work budget lasts, and the least-cost
    plan is solved at the smallest horizon found feasible, warm-started, then cut
    after its last action. Without a greedy plan the smallest feasible T is searched
    from a lower bound up to ``max_horizon``. Raises :class:`InfeasibleProblem` naming
    a robot whose information cannot reach the base within the horizon.
    ``base_station`` may name another sink; with ``static_sink=False`` it need not be
    static, and ``sink_final_location`` is where it must end.
    """
    opts = options or SolverOptions()
    budget = Budget(opts)
    pos, st, _ = robot_sets(network, positions, static, ())
    ms = master_robots(network, pos, masters)
    base = base_station or network.base_station
    if base is None or base not in pos:
        raise ValueError("post-exploration needs a base station with a position")
    if static_sink and base not in st:
        raise ValueError(f"base station '{base}' must be static")
    srcs = sorted(set(sources) - {base})
    for r in srcs:
        if r not in pos:
            raise ValueError(f"source robot '{r}' has no position")
    if sink_final_location is not None and sink_final_location not in network:
        raise ValueError(f"sink final location '{sink_final_location}' is not a location")
    hold = {r: set(b) for r, b in (holdings or {}).items()}
    base_loc = pos[base]
    moving_sink = sink_final_location is not None and sink_final_location != base_loc
    if not srcs and not moving_sink:
        return idle_plan(pos, ms, phase, hold)
    mdist = m_distance(network, pos, ms)
    und = network.mobility.to_undirected(as_view=True)
    sink_delay = 0
    if moving_sink:
        if not nx.has_path(network.mobility, base_loc, sink_final_location):
            raise InfeasibleProblem(f"sink {base} cannot reach {sink_final_location}")
        sink_delay = (0 if any(pos[m] == base_loc for m in ms) else mdist.get(base_loc, math.inf)) \
            + nx.shortest_path_length(network.mobility, base_loc, sink_final_location)
    if base in st or moving_sink:  # the information must reach where the sink ends
        to_base = information_distance(network, [sink_final_location or base_loc], reverse=True)
    else:  # a mobile sink that may end anywhere meets the information anywhere it can go
        to_base = {v: 0 for v in nx.node_connected_component(und, base_loc)}
    lower = int(sink_delay) if sink_delay < math.inf else 0
    bounds = {}
    for r in srcs:
        start = pos[r]
        delay = 0 if any(pos[m] == start for m in ms) else mdist.get(start, math.inf)
        bounds[r] = delay + to_base.get(start, math.inf)
        if to_base.get(start, math.inf) == math.inf:
            raise InfeasibleProblem(f"no route to the base for the information of robot {r}")
        lower = max(lower, bounds[r])
    col_r = set(network.collision_robots() & set(pos) if collision_robots is None else collision_robots)
    col_s = set(network.collision_locations if collision_locations is None else collision_locations)
    greedy = None
    if not (col_r and col_s):
        greedy = greedy_post_plan(network, pos, ms, st, srcs, base,
                                  sink_final_location if moving_sink else None)
    T_h = horizon_of(greedy)
    hi = max_horizon if max_horizon is not None else \
        max(int(min(lower, len(network)) + len(network) // 2 + 4), T_h or 0)
    for r in srcs:
        if bounds[r] > hi:
            raise InfeasibleProblem(f"no route to the base within horizon T={hi} for robot {r}")
    req = [Requirement(tuple(srcs), (base,))] if srcs else []
    final = {} if sink_final_location is None else {base: sink_final_location}

    def make(T: int, sub: list[str] | None = None, probe: bool = False,
             warm: Mapping[str, list[str]] | None = None, tw: float = 0.0) -> Plan | None:
        q = req if sub is None else [Requirement(tuple(sub), (base,))]
        o = replace(budget.opts, mip_gap=None) if probe else budget.opts
        if warm is not None and horizon_of(warm) > T:
            warm = None
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=set(),
            holdings=hold, requirements=q, final_positions=final,
            collision_robots=col_r, collision_locations=col_s,
            phase=phase, options=o, feasibility_only=probe, warm_start=warm, time_weight=tw),
            limits=budget.limits(probe=probe))

    if horizon is not None:
        plan = make(horizon, warm=greedy)
        if plan is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, horizon))
        return plan

    def probe(T: int) -> Plan | None:
        try:
            return make(T, probe=True)
        except SolverTimeout:
            return None

    lo = int(max(lower, 0))
    if greedy is not None and T_h <= hi:
        # bisect below the greedy horizon with feasibility probes while the work budget
        # lasts, then the least-cost plan at the best horizon, warm-started
        best_T, bad, warm = T_h, lo - 1, greedy
        while best_T - bad > 1 and not budget.spent(PROBE_RESERVE):
            mid = (best_T + bad) // 2
            try:
                found = make(mid, probe=True)
            except SolverTimeout:
                break  # too hard to tell within the probe's limits: larger horizons are harder still
            if found is None:
                bad = mid
            else:
                best_T, warm = mid, found.trajectories
        try:
            plan = make(best_T, warm=warm, tw=TIME_WEIGHT)
        except SolverTimeout:
            plan = None
        if plan is not None:
            return trim_plan(plan)
    # smallest horizon with a feasible plan (feasibility probes), then least cost there.
    # Sources carrying their own information home bound it from above; bisect below that.
    carry_home = 0
    for r in srcs:
        try:
            h = nx.shortest_path_length(und, pos[r], sink_final_location or base_loc)
        except nx.NetworkXNoPath:
            h = math.inf
        delay = 0 if any(pos[m] == pos[r] for m in ms) else mdist.get(pos[r], math.inf)
        carry_home = max(carry_home, h + delay if r not in st else bounds[r])
    carry_home = max(carry_home, lo)
    T = int(min(max(carry_home, lo), hi)) if carry_home < math.inf else hi
    found = probe(T)
    while found is None and T < hi and not budget.spent():
        T += 1
        found = probe(T)
    if found is None:
        # probes may have stopped at their limits: one full solve at the largest horizon decides
        found = make(hi)  # raises SolverTimeout when even that finds nothing within its limits
        if found is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, hi))
        return found
    best_T, bad = T, lo - 1
    while best_T - bad > 1 and not budget.spent(PROBE_RESERVE):
        mid = (best_T + bad) // 2
        attempt = probe(mid)
        if attempt is None:
            bad = mid
        else:
            best_T, found = mid, attempt
    try:
        plan = make(best_T, warm=found.trajectories)
    except SolverTimeout:
        plan = None
    if plan is None:  # the probe's plan is feasible, just not cost-optimised
        found.meta.update({"status": "feasible", "gap": None})
        return found
    return plan


def _diagnose_post(make: Callable[..., Plan | None], srcs: list[str], bounds: Mapping[str, float],
                   T: int) -> str:
    """One line saying why no plan brings the sources' information home within T."""
    for r in srcs:
        if bounds[r] > T:
            return f"no route to the base within horizon T={T} for robot {r}"
    for r in srcs:
        try:
            alone = make(T, [r], probe=True)
        except SolverTimeout:
            continue
        if alone is None:
            return f"no route to the base within horizon T={T} for robot {r}"
    return f"no information-consistent plan brings all new information to the base within horizon T={T}"
