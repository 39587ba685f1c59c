"""Problem 1 (pre-exploration), Problem 2 (post-exploration), the horizon search and
one COPS cycle (pre-exploration, exploration, post-exploration) without clustering.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Iterable, Mapping

import networkx as nx

from .ilp import (ConnectivityProblem, InfeasibleProblem, SolverOptions, SolverTimeout, information_distance,
                  solve_connectivity)
from .network import MCNetwork
from .plan import CyclePlan, ExplorationTask, Plan, Requirement, idle_plan

#: Default minimum exploration time of a cycle, in plan steps (ΔT each).
DEFAULT_MIN_EXPLORATION_STEPS = 4


@dataclass(frozen=True)
class FrontierReward:
    """R(s, k) for k robots at a frontier, with diminishing returns.

    The default is geometric: the k-th robot adds ``first * ratio**(k-1)``, so
    R(k+1) − R(k) < R(k) − R(k−1), i.e. R(k+1) < 2R(k) − R(k−1). ``table`` gives
    R(1), R(2), ... explicitly instead (it must be strictly concave with R(0) = 0).
    """

    first: float = 50.0
    ratio: float = 0.5
    table: tuple[float, ...] | None = None

    def marginals(self, k_max: int) -> tuple[float, ...]:
        """R(s, k) − R(s, k − 1) for k = 1..k_max."""
        if self.table is not None:
            vals = (0.0,) + tuple(float(v) for v in self.table)
            marg = tuple(vals[k] - vals[k - 1] for k in range(1, len(vals)))
            for k in range(1, len(marg)):
                if not marg[k] < marg[k - 1]:
                    raise ValueError(f"frontier reward table {list(self.table)} has no diminishing returns "
                                     f"at k={k + 1}: R(k+1) must be < 2R(k) - R(k-1)")
            return tuple(m for m in marg[:k_max] if m > 0)
        if not 0 < self.ratio < 1 or self.first <= 0:
            raise ValueError("frontier reward needs first > 0 and 0 < ratio < 1 (diminishing returns)")
        return tuple(self.first * self.ratio ** k for k in range(k_max))

    def value(self, k: int) -> float:
        return sum(self.marginals(k))


def _robot_sets(network: MCNetwork, positions: Mapping[str, str] | None, static: Iterable[str] | None,
                explorers: Iterable[str] | None):
    pos = dict(network.positions() if positions is None else positions)
    for r, s in pos.items():
        if s not in network:
            raise ValueError(f"robot '{r}' at unknown location '{s}'")
    st = set(network.static_robots() & set(pos) if static is None else static)
    ex = set((network.explorers() & set(pos)) if explorers is None else explorers) - st
    for name, group in (("static", st), ("explorer", ex)):
        for r in sorted(group):
            if r not in pos:
                raise ValueError(f"{name} robot '{r}' has no position")
    return pos, st, ex


def _masters(network: MCNetwork, pos: Mapping[str, str], masters: Iterable[str] | None) -> set[str]:
    if masters is None:
        if network.base_station is None:
            raise ValueError("no master robot: give masters or a base station")
        masters = {network.base_station}
    ms = set(masters)
    for r in sorted(ms):
        if r not in pos:
            raise ValueError(f"master robot '{r}' has no position")
    return ms


def _m_reachable(network: MCNetwork, pos: Mapping[str, str], masters: set[str]) -> dict[str, int]:
    return information_distance(network, {pos[r] for r in masters})


def _search(make, lo: int, hi: int, improve: bool, patience: int, deadline: float | None):
    """Solve make(T) for T = lo, lo+1, ...: the first feasible plan, then (``improve``)
    while the objective still grows (at most ``patience`` horizons without gain)."""
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
        if deadline is not None and time.perf_counter() > deadline and best is not None:
            break
        T += 1
    if best is None and timed_out is not None:
        raise timed_out
    return best, best_T


def solve_pre_exploration(network: MCNetwork, *, positions: Mapping[str, str] | None = None,
                          frontiers: Iterable[str] | None = None, masters: Iterable[str] | None = None,
                          reward: FrontierReward | None = None, explorers: Iterable[str] | None = None,
                          static: Iterable[str] | None = None, collision_robots: Iterable[str] | None = None,
                          collision_locations: Iterable[str] | None = None, horizon: int | None = None,
                          max_horizon: int | None = None, horizon_patience: int = 1,
                          extra_rewards: Mapping[str, tuple[float, ...]] | None = None,
                          master_sinks: Iterable[str] = (), strict_frontiers: bool = True,
                          options: SolverOptions | None = None, phase: str = "pre") -> Plan:
    """Problem 1: an information-consistent plan, with the base station (or ``masters``)
    as master, that maximises Σ R(s, k) − C(Π) over the frontiers.

    Without ``horizon`` the horizon is searched: from the smallest T at which every
    frontier can be reached by a capable robot, T grows while the objective grows
    (``horizon_patience`` horizons without gain end the search), up to ``max_horizon``.
    ``extra_rewards`` adds rewards at non-frontier locations (evacuation);
    ``master_sinks`` are robots that must receive m (clusters' sub-masters).
    Raises :class:`InfeasibleProblem` when a frontier cannot be reached by any
    capable robot (with ``strict_frontiers=False`` such frontiers are left out).
    """
    opts = options or SolverOptions()
    pos, st, ex = _robot_sets(network, positions, static, explorers)
    ms = _masters(network, pos, masters)
    fr = sorted(network.frontiers if frontiers is None else set(frontiers))
    for s in fr:
        if s not in network:
            raise ValueError(f"frontier '{s}' is not a location")
    rw = reward or FrontierReward()
    mobile_ex = sorted(ex - st)
    mdist = _m_reachable(network, pos, ms)
    lower = 0
    unreachable: set[str] = set()
    for s in fr:
        best = math.inf
        for r in mobile_ex:
            start = pos[r]
            delay = 0 if any(pos[m] == start for m in ms) else mdist.get(start, math.inf)
            try:
                d = nx.shortest_path_length(network.mobility, start, s)
            except nx.NetworkXNoPath:
                continue
            best = min(best, delay + d)
        if best == math.inf:
            if strict_frontiers:
                raise InfeasibleProblem(f"frontier {s} cannot be reached by any capable robot")
            unreachable.add(s)
            continue
        lower = max(lower, int(best))
    fr = [s for s in fr if s not in unreachable]
    sinks = sorted(set(master_sinks) - ms)
    for r in sinks:
        if r not in pos:
            raise ValueError(f"master sink '{r}' has no position")
        d = mdist.get(pos[r], math.inf)
        if d == math.inf:
            raise InfeasibleProblem(f"the plan m cannot reach robot {r}")
        lower = max(lower, int(d))
    rewards = {s: rw.marginals(len(mobile_ex)) for s in fr}
    for s, marg in (extra_rewards or {}).items():
        if s not in network:
            raise ValueError(f"reward location '{s}' is not a location")
        rewards[s] = tuple(marg)
    if not sinks and (not rewards or not mobile_ex):
        return idle_plan(pos, ms, phase)
    hi = max_horizon if max_horizon is not None else max(lower + 2 * horizon_patience + 2, len(network))

    def make(T: int) -> Plan | None:
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=ex,
            location_rewards=rewards, frontiers=set(fr), master_sinks=set(sinks),
            collision_robots=set(network.collision_robots() & set(pos) if collision_robots is None
                                 else collision_robots),
            collision_locations=set(network.collision_locations if collision_locations is None
                                    else collision_locations),
            phase=phase, options=opts))

    if horizon is not None:
        plan = make(horizon)
        if plan is None:
            raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={horizon}")
        return plan
    plan, _ = _search(make, max(lower, 1), max(hi, lower, 1), True, horizon_patience, None)
    if plan is None:
        raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={hi}")
    return plan


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

    Without ``horizon`` the smallest feasible T is searched, from a lower bound up to
    ``max_horizon``. Raises :class:`InfeasibleProblem` naming a robot whose
    information cannot reach the base within the horizon. ``base_station`` may name
    another sink; with ``static_sink=False`` it need not be static.
    """
    opts = options or SolverOptions()
    pos, st, _ = _robot_sets(network, positions, static, ())
    ms = _masters(network, pos, masters)
    base = base_station or network.base_station
    if base is None or base not in pos:
        raise ValueError("post-exploration needs a base station with a position")
    if static_sink and base not in st:
        raise ValueError(f"base station '{base}' must be static")
    srcs = sorted(set(sources) - {base})
    for r in srcs:
        if r not in pos:
            raise ValueError(f"source robot '{r}' has no position")
    hold = {r: set(b) for r, b in (holdings or {}).items()}
    if not srcs:
        return idle_plan(pos, ms, phase, hold)
    base_loc = pos[base]
    mdist = _m_reachable(network, pos, ms)
    if base in st:
        to_base = information_distance(network, [base_loc], reverse=True)
    else:  # a mobile sink (a cluster's sub-master) may meet the information anywhere it can go
        to_base = {v: 0 for v in nx.node_connected_component(network.mobility.to_undirected(as_view=True), base_loc)}
    lower = 0
    bounds = {}
    for r in srcs:
        start = pos[r]
        delay = 0 if any(pos[m] == start for m in ms) else mdist.get(start, math.inf)
        bounds[r] = delay + to_base.get(start, math.inf)
        if to_base.get(start, math.inf) == math.inf:
            raise InfeasibleProblem(f"no route to the base for the information of robot {r}")
        lower = max(lower, bounds[r])
    hi = max_horizon if max_horizon is not None else int(min(lower, len(network)) + len(network) // 2 + 4)
    for r in srcs:
        if bounds[r] > hi:
            raise InfeasibleProblem(f"no route to the base within horizon T={hi} for robot {r}")
    req = [Requirement(tuple(srcs), (base,))]

    def make(T: int, sub: list[str] | None = None, probe: bool = False) -> Plan | None:
        q = req if sub is None else [Requirement(tuple(sub), (base,))]
        o = opts
        if probe:
            o = SolverOptions(time_limit_s=opts.probe_time_limit_s, mip_gap=None, solver=opts.solver,
                              threads=opts.threads, probe_time_limit_s=opts.probe_time_limit_s)
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=set(),
            holdings=hold, requirements=q,
            final_positions={} if sink_final_location is None else {base: sink_final_location},
            collision_robots=set(network.collision_robots() & set(pos) if collision_robots is None
                                 else collision_robots),
            collision_locations=set(network.collision_locations if collision_locations is None
                                    else collision_locations),
            phase=phase, options=o, feasibility_only=probe))

    if horizon is not None:
        plan = make(horizon)
        if plan is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, horizon))
        return plan
    # smallest horizon with a feasible plan (feasibility probes), then least cost there.
    # Sources carrying their own information home bound it from above; bisect below that.
    def probe(T: int) -> Plan | None:
        try:
            return make(T, probe=True)
        except SolverTimeout:
            return None

    carry_home = 0
    und = network.mobility.to_undirected(as_view=True)
    for r in srcs:
        try:
            hops = nx.shortest_path_length(und, pos[r], base_loc)
        except nx.NetworkXNoPath:
            hops = math.inf
        delay = 0 if any(pos[m] == pos[r] for m in ms) else mdist.get(pos[r], math.inf)
        carry_home = max(carry_home, hops + delay if r not in st else bounds[r])
    if sink_final_location is not None:
        try:
            hops = nx.shortest_path_length(und, base_loc, sink_final_location)
        except nx.NetworkXNoPath:
            raise InfeasibleProblem(f"sink {base} cannot reach {sink_final_location}") from None
        delay = 0 if any(pos[m] == base_loc for m in ms) else mdist.get(base_loc, math.inf)
        lower = max(lower, hops + delay)
        carry_home = max(carry_home, hops + delay)
    lo = int(max(lower, 0))
    T = int(min(max(carry_home, lo), hi)) if carry_home < math.inf else hi
    found = probe(T)
    while found is None and T < hi:
        T += 1
        found = probe(T)
    if found is None:
        # probes may have timed out: one full solve at the largest horizon decides
        found = make(hi)  # raises SolverTimeout when even that finds nothing in time
        if found is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, hi))
        return found
    best_T, bad = T, lo - 1
    while best_T - bad > 1:
        mid = (best_T + bad) // 2
        attempt = probe(mid)
        if attempt is None:
            bad = mid
        else:
            best_T, found = mid, attempt
    T = best_T
    try:
        plan = make(T)
    except SolverTimeout:
        plan = None
    if plan is None:  # the probe's plan is feasible, just not cost-optimised
        found.meta.update({"status": "feasible", "gap": None})
        return found
    return plan


def _diagnose_post(make, srcs: list[str], bounds: Mapping[str, float], T: int) -> str:
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


# ---------------------------------------------------------------------------------------
# one cycle
# ---------------------------------------------------------------------------------------

def exploration_tasks(pre: Plan, start_step: Mapping[str, int] | int, steps: Mapping[str, int] | int,
                      return_step: Mapping[str, int] | int = 0) -> dict[str, ExplorationTask]:
    """Exploration tasks for the robots ``pre`` sends exploring (Algorithm 1 indices)."""
    def get(v, r):
        return v[r] if isinstance(v, Mapping) else v
    out = {}
    for s, rs in pre.frontier_assignment().items():
        for i, r in enumerate(rs):
            out[r] = ExplorationTask(s, i, int(get(start_step, r)), int(get(steps, r)), int(get(return_step, r)))
    return out


def plan_cycle(network: MCNetwork, *, positions: Mapping[str, str] | None = None,
               frontiers: Iterable[str] | None = None, masters: Iterable[str] | None = None,
               reward: FrontierReward | None = None, explorers: Iterable[str] | None = None,
               static: Iterable[str] | None = None, min_exploration_steps: int = DEFAULT_MIN_EXPLORATION_STEPS,
               clustering: bool | str = "auto", max_cluster_locations: int | None = None,
               max_horizon: int | None = None, options: SolverOptions | None = None) -> CyclePlan:
    """Plan one cycle: Problem 1, then Problem 2 from where the explorers return (their
    frontiers), with the robots that received m as masters and the explorers as
    sources. ``clustering`` ("auto", True, False) splits large networks into clusters
    (:mod:`delve.planners.cops.clustering`)."""
    from .clustering import plan_cycle_clustered, should_cluster

    t0 = time.perf_counter()
    pos, st, ex = _robot_sets(network, positions, static, explorers)
    ms = _masters(network, pos, masters)
    use = should_cluster(network, pos, ms) if clustering == "auto" else bool(clustering)
    if use:
        kw = {} if max_cluster_locations is None else {"max_cluster_locations": max_cluster_locations}
        cyc = plan_cycle_clustered(network, positions=pos, frontiers=frontiers, masters=ms, reward=reward,
                                   explorers=ex, static=st, min_exploration_steps=min_exploration_steps,
                                   max_horizon=max_horizon, options=options, **kw)
        cyc.meta["solve_time_s"] = round(time.perf_counter() - t0, 4)
        return cyc
    pre = solve_pre_exploration(network, positions=pos, frontiers=frontiers, masters=ms, reward=reward,
                                explorers=ex, static=st, max_horizon=max_horizon, options=options)
    post_pos = pre.final_positions()
    post = solve_post_exploration(network, sources=sorted(pre.explore), positions=post_pos,
                                  masters=sorted(pre.master_receivers()), static=st,
                                  max_horizon=max_horizon, options=options)
    tasks = exploration_tasks(pre, pre.horizon, min_exploration_steps, 0)
    return CyclePlan(pre, post, tasks, meta={
        "clustered": False, "clusters": 1, "min_exploration_steps": min_exploration_steps,
        "solve_time_s": round(time.perf_counter() - t0, 4),
        "gap": _max_gap([pre, post])})


def _max_gap(plans: Iterable[Plan]):
    gaps = [p.meta.get("gap") for p in plans]
    if any(g is None for g in gaps):
        return None
    return max(gaps, default=0.0)
