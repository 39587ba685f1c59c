"""One COPS cycle: Problem 1 (pre-exploration), the exploration phase, and Problem 2
(post-exploration) from where the explorers return; large networks are planned
cluster by cluster (:mod:`.clustering`)."""
from __future__ import annotations

import time
from typing import Iterable, Mapping

from .budget import PRE_SHARE, Budget
from .clustering import plan_cycle_clustered, should_cluster
from .ilp_problem import SolverOptions
from .network import MCNetwork
from .plan import DEFAULT_MIN_EXPLORATION_STEPS, CyclePlan, ExplorationTask, Plan, worst_gap
from .post_exploration import solve_post_exploration
from .pre_exploration import solve_pre_exploration
from .rewards import FrontierReward
from .roles import master_robots, robot_sets


def exploration_tasks(pre: Plan, start_step: Mapping[str, int] | int, steps: Mapping[str, int] | int,
                      return_step: Mapping[str, int] | int = 0) -> dict[str, ExplorationTask]:
    """Exploration tasks for the robots ``pre`` sends exploring (Algorithm 1 indices)."""
    def get(v: Mapping[str, int] | int, r: str) -> int:
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
    (:mod:`delve.planners.cops.clustering`). ``options.total_work`` bounds the whole
    cycle (pre-exploration gets :data:`PRE_SHARE` of it), ``options.total_time_limit_s``
    is its safety stop; ``meta["gap"]`` is the worst optimality gap of its integer
    programs (None: unknown), ``meta["work"]`` their simplex iterations,
    ``meta["solves"]`` their number and ``meta["safety_stops"]`` how many safety stops
    fired (``options.meter`` counts them too)."""
    t0 = time.perf_counter()
    budget = Budget(options or SolverOptions())
    opts = budget.opts
    pos, st, ex = robot_sets(network, positions, static, explorers)
    ms = master_robots(network, pos, masters)
    use = should_cluster(network, pos, ms, frontiers=frontiers, static=st, explorers=ex, reward=reward) \
        if clustering == "auto" else bool(clustering)
    if use:
        kw = {} if max_cluster_locations is None else {"max_cluster_locations": max_cluster_locations}
        cyc = plan_cycle_clustered(network, positions=pos, frontiers=frontiers, masters=ms, reward=reward,
                                   explorers=ex, static=st, min_exploration_steps=min_exploration_steps,
                                   max_horizon=max_horizon, options=opts, **kw)
        cyc.meta["solve_time_s"] = round(time.perf_counter() - t0, 4)
        cyc.meta.update(budget.meter.figures())
        return cyc
    pre = solve_pre_exploration(network, positions=pos, frontiers=frontiers, masters=ms, reward=reward,
                                explorers=ex, static=st, max_horizon=max_horizon,
                                options=budget.options(PRE_SHARE))
    post_pos = pre.final_positions()
    post = solve_post_exploration(network, sources=sorted(pre.explore), positions=post_pos,
                                  masters=sorted(pre.master_receivers()), static=st,
                                  max_horizon=max_horizon, options=budget.options())
    tasks = exploration_tasks(pre, pre.horizon, min_exploration_steps, 0)
    return CyclePlan(pre, post, tasks, meta={
        "clustered": False, "clusters": 1, "min_exploration_steps": min_exploration_steps,
        "solve_time_s": round(time.perf_counter() - t0, 4),
        "gap": worst_gap([pre, post]), **budget.meter.figures()})

