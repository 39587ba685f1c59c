"""Problem 1 (pre-exploration): an information-consistent plan that sends robots to
the frontiers, maximising the frontier rewards minus the plan's cost.

The horizon comes from a greedy plan (an upper bound), at which one integer program
is solved warm-started from it, with a tiny cost on late actions; the best plan
found within the solve's work limits is cut after its last action. The solver's answer is
never worse than the greedy plan.
"""
from __future__ import annotations

import math
from typing import Iterable, Mapping

from .budget import Budget
from .distances import m_distance
from .errors import InfeasibleProblem
from .greedy import greedy_pre_plan, m_times
from .horizon import TIME_WEIGHT, horizon_of, search_horizons, trim_plan
from .ilp import solve_connectivity
from .ilp_problem import ConnectivityProblem, SolverOptions
from .network import MCNetwork
from .plan import Plan, idle_plan
from .rewards import FrontierReward
from .roles import master_robots, robot_sets


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

    Without ``horizon`` the horizon comes from a greedy plan (:func:`greedy_pre_plan`)
    plus ``horizon_patience`` steps of slack; the integer program, warm-started from
    the greedy plan, is solved once there and its plan cut after the last action (up
    to ``max_horizon``). When no greedy plan exists, horizons are searched from the
    smallest T at which every frontier can be reached by a capable robot, while the
    objective grows. ``extra_rewards`` adds rewards at non-frontier locations
    (evacuation); ``master_sinks`` are robots that must receive m (clusters'
    sub-masters). Raises :class:`InfeasibleProblem` when a frontier cannot be reached
    by any capable robot (with ``strict_frontiers=False`` such frontiers are left out).
    """
    opts = options or SolverOptions()
    budget = Budget(opts)
    pos, st, ex = robot_sets(network, positions, static, explorers)
    ms = master_robots(network, pos, masters)
    fr = sorted(network.frontiers if frontiers is None else set(frontiers))
    for s in fr:
        if s not in network:
            raise ValueError(f"frontier '{s}' is not a location")
    rw = reward or FrontierReward()
    mobile_ex = sorted(ex - st)
    mdist = m_distance(network, pos, ms)
    hops_from: dict[str, dict[str, int]] = {}
    lower = 0
    unreachable: set[str] = set()
    for s in fr:
        best = math.inf
        for r in mobile_ex:
            start = pos[r]
            delay = 0 if any(pos[m] == start for m in ms) else mdist.get(start, math.inf)
            if start not in hops_from:
                hops_from[start] = network.hop_distances(start)
            d = hops_from[start].get(s, math.inf)
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
    col_r = set(network.collision_robots() & set(pos) if collision_robots is None else collision_robots)
    col_s = set(network.collision_locations if collision_locations is None else collision_locations)
    # nobody moves without m: when no robot that can move holds it at t = 0, nothing happens
    holders = m_times(network, {r: [s] for r, s in pos.items()}, ms, 0,
                       {u: sorted(network.communication.successors(u)) for u in network.communication})
    if not sinks and not any(r in holders for r in pos if r not in st):
        return idle_plan(pos, ms, phase)
    greedy = None
    if not (col_r and col_s):  # the greedy rules know nothing of collisions
        greedy = greedy_pre_plan(network, pos, ms, st, ex, rewards, sinks)
    T_h = horizon_of(greedy)
    hi = max_horizon if max_horizon is not None else max(lower + 2 * horizon_patience + 2, len(network),
                                                         (T_h or 0) + horizon_patience)

    def make(T: int, warm: Mapping[str, list[str]] | None = None, tw: float = 0.0) -> Plan | None:
        if warm is not None and horizon_of(warm) > T:
            warm = None
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=ex,
            location_rewards=rewards, frontiers=set(fr), master_sinks=set(sinks),
            collision_robots=col_r, collision_locations=col_s, phase=phase, options=budget.opts,
            warm_start=warm, time_weight=tw), limits=budget.limits())

    if horizon is not None:
        plan = make(horizon, greedy)
        if plan is None:
            raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={horizon}")
        return plan
    if greedy is not None and T_h <= hi:
        T = min(max(T_h + max(horizon_patience, 0), 1), hi)
        plan = make(T, greedy, TIME_WEIGHT)
        if plan is not None:
            return trim_plan(plan)
    plan, _ = search_horizons(lambda T: make(T), max(lower, 1), max(hi, lower, 1), True, horizon_patience,
                              budget.spent)
    if plan is None:
        raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={hi}")
    return plan
