"""The recall: the last plan of a mission, when no frontier is left.

Every robot that m can reach (robots move only once they hold m, so m travels over
communication edges and with robots that already hold it) is brought to the base.
It is a reward problem like Problem 1: each robot holding m at the base at T earns
``home_reward``, minus the plan's cost C(Π). The horizon grows from the farthest
robot's distance until every robot gets home or two longer horizons bring no more;
the greedy plan of Problem 1 with the base as the only rewarded place (couriers
bring m, robots walk home) warm-starts each solve, so a solve stopped by its limits
is never worse than that. When that plan is within the solver's gap of an upper
bound (every robot's reward less its cheapest way home) it is taken without a
search. ``options.total_work`` bounds the search over horizons.
"""
from __future__ import annotations

import math
from typing import Iterable, Mapping

import networkx as nx

from .budget import Budget
from .errors import InfeasibleProblem, SolverTimeout
from .greedy import greedy_pre_plan
from .horizon import horizon_of
from .ilp import solve_connectivity
from .ilp_problem import ConnectivityProblem, SolverOptions
from .network import MCNetwork
from .plan import MASTER, Communication, Plan, idle_plan

#: Reward for each robot brought home; larger than any route's mobility cost.
DEFAULT_HOME_REWARD = 1000.0


def solve_recall(network: MCNetwork, *, positions: Mapping[str, str], masters: Iterable[str],
                 static: Iterable[str] = (), max_horizon: int | None = None,
                 home_reward: float = DEFAULT_HOME_REWARD, options: SolverOptions | None = None) -> Plan:
    """An information-consistent plan that brings home every robot m can reach, at
    least cost; ``plan.meta["stranded"]`` lists the robots it cannot reach. Its
    horizons grow while ``options.total_work`` lasts (the first is always solved)."""
    base = network.base
    if base is None:
        raise ValueError("the recall needs a base location")
    ms, st = set(masters), set(static)
    mobile = sorted(r for r in positions if r not in st)
    hops = network.hop_distances(base)
    away = [r for r in mobile if positions[r] != base]
    if not away:  # everyone is home: m is handed to each robot there, and that is all
        plan = idle_plan(positions, ms, "recall")
        hand_m_at_base(plan, base, mobile)
        plan.meta["stranded"] = []
        return plan
    for r in away:
        if positions[r] not in hops:
            raise InfeasibleProblem(f"no route to the base for robot {r}")
    upper = max_horizon if max_horizon is not None else 2 * max(hops[positions[r]] for r in away) + 2
    budget = Budget(options or SolverOptions())
    rewards = {base: (home_reward,) * len(mobile)}
    greedy = greedy_pre_plan(network, positions, ms, st, mobile, rewards)
    T_greedy = horizon_of(greedy)

    # no plan earns more than each robot's reward less its cheapest way home
    to_base = nx.single_source_dijkstra_path_length(network.mobility.reverse(copy=False), base, weight="cost")
    bound = sum(max(home_reward - to_base.get(positions[r], math.inf), 0.0) for r in mobile)

    def solve(T: int) -> Plan | None:
        warm = greedy if T_greedy is not None and T_greedy <= T else None
        problem = ConnectivityProblem(network=network, horizon=T, positions=dict(positions), masters=ms, static=st,
                                      explorers=set(mobile), reward_robots=set(mobile), location_rewards=rewards,
                                      phase="recall", options=budget.opts, warm_start=warm,
                                      objective_bound=bound)
        try:
            return solve_connectivity(problem, limits=budget.limits())
        except SolverTimeout:
            return None

    def home(plan: Plan | None) -> int:
        return -1 if plan is None else sum(1 for r in mobile if plan.location(r, plan.horizon) == base)

    lower = max(hops[positions[r]] for r in away)
    if T_greedy is not None and lower < T_greedy <= upper:  # start where the greedy plan ends
        lower = T_greedy
    best, stalled = None, 0  # grow the horizon until everyone is home or it stops helping
    for T in range(lower, upper + 1, 2):
        plan = solve(T)
        if home(plan) > home(best):
            best, stalled = plan, 0
        else:
            stalled += 1
        if home(best) == len(mobile) or stalled >= 2 or budget.spent():
            break
    if best is None:
        raise InfeasibleProblem(f"no recall plan within horizon T={upper}")
    hand_m_at_base(best, base, mobile)
    best.meta.update(budget.meter.figures())
    best.meta["stranded"] = sorted(r for r in mobile if best.location(r, best.horizon) != base)
    best.explore = {}
    return best


def hand_m_at_base(plan: Plan, base: str, mobile: list[str]) -> None:
    """Robots at the base at T that m has not reached get it there at T (a solve
    stopped by its limits may leave out such a reward)."""
    T, holders = plan.horizon, plan.master_receivers()
    giver = next((h for h in sorted(holders) if plan.location(h, T) == base), None)
    if giver is None:
        return
    plan.communications += [Communication(T, giver, r, MASTER) for r in mobile
                            if r not in holders and plan.location(r, T) == base]
