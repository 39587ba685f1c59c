"""Clustering for large networks (the paper's "Clustering for Large-Scale Networks").

1. Idle locations are pruned recursively: a location is idle when it is not a
   frontier, holds no robot, and all its mobility neighbours further from the base
   are idle.
2. The remaining locations are cut into connected clusters of bounded size along the
   shortest-path tree from the base; a piece without mobile robots (or with frontiers
   but no capable robot) is merged into its parent, so every cluster can act on its
   own. Clusters form a tree rooted at the master cluster (the base's).
3. Pre-exploration is planned parent first. A child cluster's sub-master (its robot
   nearest the parent) is a static sink of m in the parent's problem, whose network
   also holds the corridor to it; the child's own problem, with the sub-master as
   master, starts when the parent's plan is done with the sub-master.
4. Post-exploration is planned children first. A child's sub-master collects the
   child's new information; in the parent's problem it is a static source holding
   it, and the child's plan must end before the parent first needs it.
5. The cluster plans are patched together (Figure 3): every cluster starts
   pre-exploration at a common initial time (children once the plan reaches them)
   and every post-exploration ends by a common final time; the cluster with the
   longest pre- plus post-exploration gets the minimum exploration time and the
   others explore longer.
6. A cluster with no frontier and no non-idle child is idle: its robots are given
   evacuation rewards for reaching the parent cluster, where they can contribute.
"""
from __future__ import annotations

import math
import time
from collections import defaultdict, deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Callable, Iterable, Mapping

import networkx as nx

from .budget import PRE_SHARE, Budget
from .errors import InfeasibleProblem, PlanningError
from .greedy import greedy_pre_plan
from .ilp_problem import SolverOptions
from .network import MCNetwork
from .plan import (DEFAULT_MIN_EXPLORATION_STEPS, Communication, CyclePlan, ExplorationTask, Plan, Requirement,
                   worst_gap)
from .post_exploration import solve_post_exploration
from .pre_exploration import solve_pre_exploration
from .rewards import FrontierReward
from .roles import master_robots, robot_sets

#: Default largest number of locations in a cluster before it is cut.
DEFAULT_MAX_CLUSTER_LOCATIONS = 24
#: Reward per robot that an idle cluster's evacuation plan earns at the parent cluster.
DEFAULT_EVACUATION_REWARD = 10.0
#: Estimated problem size (robot classes x horizon x arcs) above which "auto" clusters.
AUTO_CLUSTER_SIZE = 30000


def _tree_distances(network: MCNetwork, base: str) -> dict[str, int]:
    return nx.single_source_shortest_path_length(network.mobility.to_undirected(as_view=True), base)


def idle_locations(network: MCNetwork, positions: Mapping[str, str], frontiers: Iterable[str],
                   base: str) -> set[str]:
    """Locations unlikely to be used: not a frontier, no robot, and every mobility
    neighbour further from the base idle (recursively, from the deepest up)."""
    dist = _tree_distances(network, base)
    fr = set(frontiers)
    occupied = set(positions.values())
    und = network.mobility.to_undirected(as_view=True)
    idle: set[str] = set()
    for v in sorted(dist, key=lambda s: (-dist[s], s)):
        if v == base or v in fr or v in occupied:
            continue
        children = [w for w in und.neighbors(v) if dist.get(w, -1) > dist[v]]
        if all(w in idle for w in children):
            idle.add(v)
    for v in network.locations:  # not connected to the base at all
        if v not in dist and v not in fr and v not in occupied:
            idle.add(v)
    return idle


@dataclass
class Cluster:
    name: str
    root: str                     # location nearest the base
    locations: set[str]
    parent: str | None = None     # parent cluster
    gateway: str | None = None    # parent's location next to ``root``
    children: list[str] = field(default_factory=list)
    robots: list[str] = field(default_factory=list)
    frontiers: set[str] = field(default_factory=set)
    idle: bool = False


@dataclass
class ClusterStructure:
    clusters: dict[str, Cluster]
    master: str
    idle_locations: set[str]
    cluster_of: dict[str, str]    # location -> cluster

    def parent_first(self) -> list[str]:
        order, queue = [], deque([self.master])
        while queue:
            c = queue.popleft()
            order.append(c)
            queue.extend(self.clusters[c].children)
        return order

    def children_first(self) -> list[str]:
        return list(reversed(self.parent_first()))


def build_clusters(network: MCNetwork, positions: Mapping[str, str], frontiers: Iterable[str], base: str,
                   static: Iterable[str] = (), explorers: Iterable[str] | None = None,
                   max_cluster_locations: int = DEFAULT_MAX_CLUSTER_LOCATIONS) -> ClusterStructure:
    """Prune idle locations and cut the rest into a tree of clusters."""
    fr = set(frontiers)
    st = set(static)
    ex = set(positions) - st if explorers is None else set(explorers) - st
    idle = idle_locations(network, positions, fr, base)
    active = [v for v in network.locations if v not in idle]
    und = network.mobility.to_undirected(as_view=True).subgraph(active)
    dist = nx.single_source_shortest_path_length(und, base)
    parent: dict[str, str | None] = {base: None}
    for v in sorted(dist, key=lambda s: (dist[s], s)):
        for w in sorted(und.neighbors(v)):
            if w not in parent and dist.get(w) == dist[v] + 1:
                parent[w] = v
    kids: dict[str, list[str]] = defaultdict(list)
    for v, p in parent.items():
        if p is not None:
            kids[p].append(v)
    order = sorted(parent, key=lambda s: (-dist[s], s))
    size: dict[str, int] = {}
    cut: set[str] = {base}
    for v in order:
        size[v] = 1 + sum(size[w] for w in kids[v] if w not in cut)
        while size[v] > max_cluster_locations:
            open_kids = [w for w in kids[v] if w not in cut]
            if not open_kids:
                break
            w = max(open_kids, key=lambda k: (size[k], k))
            cut.add(w)
            size[v] -= size[w]

    mobile_at: dict[str, list[str]] = defaultdict(list)
    for r, s in positions.items():
        if r not in st:
            mobile_at[s].append(r)

    def piece(root: str) -> set[str]:
        out, stack = set(), [root]
        while stack:
            v = stack.pop()
            out.add(v)
            stack.extend(w for w in kids[v] if w not in cut)
        return out

    # merge pieces that cannot act on their own into their parent, deepest first
    changed = True
    while changed:
        changed = False
        for root in sorted(cut - {base}, key=lambda s: (-dist[s], s)):
            locs = piece(root)
            robots = [r for v in locs for r in mobile_at.get(v, [])]
            has_fr = bool(locs & fr)
            if not robots or (has_fr and not any(r in ex for r in robots)):
                cut.discard(root)
                changed = True
                break

    clusters: dict[str, Cluster] = {}
    cluster_of: dict[str, str] = {}
    for root in sorted(cut, key=lambda s: (dist[s], s)):
        name = f"c{len(clusters)}"
        locs = piece(root)
        clusters[name] = Cluster(name, root, locs, frontiers=locs & fr)
        for v in locs:
            cluster_of[v] = name
    for c in clusters.values():
        if c.root != base:
            c.gateway = parent[c.root]
            c.parent = cluster_of[c.gateway]
            clusters[c.parent].children.append(c.name)
    for c in clusters.values():
        c.children.sort()
        c.robots = sorted(r for r, s in positions.items() if s in c.locations)
    master = cluster_of[base]
    struct = ClusterStructure(clusters, master, idle, cluster_of)
    for name in struct.children_first():
        c = clusters[name]
        c.idle = name != master and not c.frontiers and all(clusters[k].idle for k in c.children)
    return struct


def should_cluster(network: MCNetwork, positions: Mapping[str, str], masters: Iterable[str], *,
                   frontiers: Iterable[str] | None = None, static: Iterable[str] | None = None,
                   explorers: Iterable[str] | None = None, reward: FrontierReward | None = None) -> bool:
    """Whether the one-shot problem looks too large: robot classes (occupied
    locations) x horizon x arcs, the horizon that of a greedy pre-exploration plan
    (the depth of the network when there is none)."""
    st = set(network.static_robots() if static is None else static) & set(positions)
    occupied = {s for r, s in positions.items() if r not in st}
    if network.base is None or network.base not in network:
        return False
    ex = set(network.explorers() if explorers is None else explorers) & set(positions) - st
    fr = [s for s in sorted(network.frontiers if frontiers is None else frontiers) if s in network]
    marg = (reward or FrontierReward()).marginals(len(ex))
    greedy = None
    if fr and ex:
        greedy = greedy_pre_plan(network, positions, set(masters) & set(positions), st, ex,
                                 {s: marg for s in fr})
    if greedy is not None:
        horizon = max(len(tr) for tr in greedy.values()) - 1
    else:
        horizon = max(_tree_distances(network, network.base).values(), default=0)
    arcs = network.mobility.number_of_edges() + len(network)
    return len(occupied) * max(horizon, 1) * arcs > AUTO_CLUSTER_SIZE


def _nearest(network: MCNetwork, robots: list[str], positions: Mapping[str, str], target: str,
             allowed: set[str], prefer: set[str]) -> str | None:
    if not robots:
        return None
    und = network.mobility.to_undirected(as_view=True).subgraph(allowed)
    dist = nx.single_source_shortest_path_length(und, target)
    return min(robots, key=lambda r: (r not in prefer, dist.get(positions[r], math.inf), r))


def _corridor(network: MCNetwork, locs: set[str], a: str, b: str) -> list[str]:
    und = network.mobility.to_undirected(as_view=True).subgraph(locs)
    return nx.shortest_path(und, a, b)


def _shift(plan: Plan, offset: int, horizon: int, robots: Iterable[str], positions: Mapping[str, str]):
    traj = {}
    for r in robots:
        local = plan.trajectories.get(r, [positions[r]] * (plan.horizon + 1))
        traj[r] = [local[0]] * offset + list(local) + [local[-1]] * (horizon - offset - plan.horizon)
    comms = [Communication(c.t + offset, c.sender, c.receiver, c.info) for c in plan.communications]
    return traj, comms


def plan_cycle_clustered(network: MCNetwork, *, positions: Mapping[str, str] | None = None,
                         frontiers: Iterable[str] | None = None, masters: Iterable[str] | None = None,
                         reward: FrontierReward | None = None, explorers: Iterable[str] | None = None,
                         static: Iterable[str] | None = None,
                         min_exploration_steps: int = DEFAULT_MIN_EXPLORATION_STEPS,
                         max_cluster_locations: int = DEFAULT_MAX_CLUSTER_LOCATIONS,
                         evacuation_reward: float = DEFAULT_EVACUATION_REWARD,
                         max_horizon: int | None = None, options: SolverOptions | None = None) -> CyclePlan:
    """One COPS cycle planned cluster by cluster and patched together.

    When a cluster's post-exploration cannot be planned on its own (for example no
    robot is left in a cluster its children report through), post-exploration is
    planned on the whole network instead (``meta["post_clustered"]`` is False).
    """
    t0 = time.perf_counter()
    pos, st, ex = robot_sets(network, positions, static, explorers)
    ms = master_robots(network, pos, masters)
    fr = set(network.frontiers if frontiers is None else frontiers)
    base_station = network.base_station
    if base_station is None or base_station not in pos:
        raise ValueError("clustering needs a base station with a position")
    mobile_ex = [r for r in ex if r not in st]
    for s in sorted(fr):
        if s not in network:
            raise ValueError(f"frontier '{s}' is not a location")
        if not any(nx.has_path(network.mobility, pos[r], s) for r in mobile_ex):
            raise InfeasibleProblem(f"frontier {s} cannot be reached by any capable robot")
    cs = build_clusters(network, pos, fr, pos[base_station], st, ex, max_cluster_locations)
    budget = Budget(options or SolverOptions())
    pre, pre_done = _clustered_pre(network, cs, pos, ms, st, ex, reward, evacuation_reward, max_horizon,
                                   budget.options(PRE_SHARE))
    post_pos = pre.final_positions()
    post_masters = pre.master_receivers()
    try:
        post, post_join = _clustered_post(network, cs, pre, post_pos, post_masters, st, base_station,
                                          max_horizon, budget.options())
        post_clustered = True
    except PlanningError:
        post = solve_post_exploration(network, sources=sorted(pre.explore), positions=post_pos,
                                      masters=sorted(post_masters), static=st, max_horizon=max_horizon,
                                      options=budget.options())
        post_join = {r: 0 for r in pos}
        post_clustered = False
    # exploration times (Figure 3): the tightest cluster gets the minimum exploration time
    offset = 0
    for r in pos:
        offset = max(offset, pre_done[r] + (min_exploration_steps if r in pre.explore else 0) - post_join[r])
    tasks: dict[str, ExplorationTask] = {}
    for s, rs in pre.frontier_assignment().items():
        for i, r in enumerate(rs):
            tasks[r] = ExplorationTask(s, i, pre_done[r], offset + post_join[r] - pre_done[r], post_join[r])
    C = cs.clusters
    return CyclePlan(pre, post, tasks, meta={
        "clustered": True, "clusters": len(C), "idle_locations": len(cs.idle_locations),
        "idle_clusters": sorted(k for k in C if C[k].idle), "post_clustered": post_clustered,
        "min_exploration_steps": min_exploration_steps, "post_start_step": offset,
        "solve_time_s": round(time.perf_counter() - t0, 4),
        "gap": worst_gap([pre, post])})


def _solve_all(jobs: list[tuple[str, float, Callable[[SolverOptions], Plan]]],
               opts: SolverOptions) -> dict[str, Plan]:
    """Run independent cluster problems, ``opts.workers`` at once (the solver releases
    the interpreter while it works). A job (name, weight, solve) may use the share of
    the work budget that its weight has among all jobs, decided before any starts, so
    that plans do not depend on which job finishes first (nor on ``workers``); raises
    the first job's error, if any."""
    budget = Budget(opts)
    workers = max(1, min(int(opts.workers or 1), len(jobs)))
    total = sum(w for _name, w, _fn in jobs) or 1.0
    shares = {name: budget.options(w / total) for name, w, _fn in jobs}
    if workers == 1:
        return {name: fn(shares[name]) for name, _w, fn in jobs}
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {name: pool.submit(fn, shares[name]) for name, _w, fn in jobs}
        return {name: f.result() for name, f in futures.items()}


def _clustered_pre(network, cs: ClusterStructure, pos, ms, st, ex, reward, evacuation_reward, max_horizon, opts):
    C = cs.clusters
    all_locs = set(network.locations)
    sub_pre: dict[str, str] = {}
    for name in cs.parent_first():
        c = C[name]
        if c.parent is not None:
            mobile = [r for r in c.robots if r not in st]
            sub_pre[name] = _nearest(network, mobile or c.robots, pos, c.root, c.locations, ms)
    # a cluster's problem does not depend on its parent's plan, only when it starts does:
    # all are solved at once, then patched together
    cmasters: dict[str, set[str]] = {cs.master: ms & set(C[cs.master].robots)}
    for name in cs.parent_first():
        for k in C[name].children:
            cmasters[k] = {sub_pre[k]} | (ms & set(C[k].robots))
    jobs = []
    for name in cs.parent_first():
        c = C[name]
        locs = set(c.locations)
        sub_pos = {r: pos[r] for r in c.robots}
        sinks = []
        for k in c.children:
            sm = sub_pre[k]
            locs |= set(_corridor(network, C[k].locations, C[k].root, pos[sm]))
            sub_pos[sm] = pos[sm]
            sinks.append(sm)
        extra = {}
        if c.idle and c.gateway is not None:
            locs.add(c.gateway)
            n_mobile = sum(1 for r in c.robots if r not in st)
            extra = {c.gateway: tuple([evacuation_reward] * max(n_mobile, 1))}
        mobile = sum(1 for r in sub_pos if r not in st and r not in sinks)

        def solve(o: SolverOptions, locs=locs, sub_pos=sub_pos, sinks=sinks, extra=extra, c=c) -> Plan:
            return solve_pre_exploration(
                network.subnetwork(locs & all_locs), positions=sub_pos, frontiers=c.frontiers,
                masters=cmasters[c.name], reward=reward, explorers=ex & set(c.robots),
                static=(st & set(sub_pos)) | set(sinks), extra_rewards=extra, master_sinks=sinks,
                strict_frontiers=False, max_horizon=max_horizon, options=o, phase="pre")

        jobs.append((name, float(max(mobile, 1) * len(locs)), solve))
    plans = _solve_all(jobs, opts)
    start: dict[str, int] = {cs.master: 0}
    for name in cs.parent_first():
        plan = plans[name]
        for k in C[name].children:
            sm = sub_pre[k]
            involved = [x.t for x in plan.communications if sm in (x.sender, x.receiver)]
            start[k] = start[name] + (max(involved) if involved else plan.horizon)
    end = {k: start[k] + plans[k].horizon for k in plans}
    H = max(end.values())
    traj: dict[str, list[str]] = {}
    comms: list[tuple[int, int, Communication]] = []
    explore: dict[str, str] = {}
    done: dict[str, int] = {r: 0 for r in pos}
    rank = {k: i for i, k in enumerate(cs.parent_first())}
    for name, plan in plans.items():
        tr, cm = _shift(plan, start[name], H, C[name].robots, pos)
        traj.update(tr)
        comms += [(x.t, rank[name], x) for x in cm]
        explore.update({r: s for r, s in plan.explore.items() if r in C[name].robots})
        for r in C[name].robots:
            done[r] = end[name]
    for r in pos:
        traj.setdefault(r, [pos[r]] * (H + 1))
    pre = Plan(horizon=H, trajectories={r: traj[r] for r in sorted(traj)},
               communications=[x for _, _, x in sorted(comms, key=lambda e: (e[0], e[1]))],
               masters=sorted(ms), explore=dict(sorted(explore.items())), phase="pre",
               meta=_merged_meta(plans.values()))
    return pre, done


def _clustered_post(network, cs: ClusterStructure, pre: Plan, post_pos, post_masters, st, base_station,
                    max_horizon, opts):
    C = cs.clusters
    member = {r: cs.cluster_of.get(s, cs.master) for r, s in post_pos.items()}
    members: dict[str, list[str]] = defaultdict(list)
    for r in sorted(member):
        members[member[r]].append(r)
    carries: dict[str, set[str]] = {}
    sub_post: dict[str, str] = {}
    final_pos: dict[str, str] = {}
    jobs = []
    # every cluster's problem is known before any is solved: a child's sub-master ends
    # at the child's root (or stays, when static) holding what its sources held
    for name in cs.children_first():
        c = C[name]
        child_subs = {k: sub_post[k] for k in c.children if k in sub_post}
        sources = sorted(r for r in members[name] if r in pre.explore) + sorted(child_subs.values())
        if not sources:
            continue
        if c.parent is None:
            sink = base_station
        else:
            cand = [r for r in members[name] if r not in child_subs.values()]
            if not cand:
                raise InfeasibleProblem(f"no robot left in cluster {name} to carry information up")
            sink = _nearest(network, cand, post_pos, c.root, c.locations, post_masters)
        locs = set(c.locations)
        sub_positions = {r: post_pos[r] for r in members[name]}
        holdings = {}
        for k, sm in child_subs.items():
            locs |= set(_corridor(network, set(cs.cluster_of), C[k].root, final_pos[sm]))
            sub_positions[sm] = final_pos[sm]
            holdings[sm] = carries[k]
        statics = (st & set(sub_positions)) | set(child_subs.values())
        if c.parent is None:
            statics.add(sink)
        final = None if c.parent is None or sink in statics else c.root
        sub_post[name] = sink
        final_pos[sink] = final or sub_positions[sink]
        labels = set(holdings.get(sink, {sink}))
        for r in sources:
            labels |= set(holdings.get(r, {r}))
        carries[name] = labels

        def solve(o: SolverOptions, locs=locs, sources=sources, sub_positions=sub_positions,
                  holdings=holdings, statics=statics, sink=sink, final=final, c=c) -> Plan:
            return solve_post_exploration(
                network.subnetwork(locs), sources=sources, positions=sub_positions,
                masters=(post_masters & set(sub_positions)) | set(holdings), base_station=sink,
                static=statics, holdings=holdings, max_horizon=max_horizon, static_sink=c.parent is None,
                sink_final_location=final, options=o, phase="post")

        jobs.append((name, float(len(sources) * len(locs)), solve))
    plans = _solve_all(jobs, opts)
    # a child's plan ends before its parent first uses the child's sub-master
    start: dict[str, int] = {}
    for name in cs.parent_first():
        if name not in plans:
            continue
        c = C[name]
        if c.parent is None or c.parent not in plans:
            start[name] = 0
            continue
        sm = sub_post[name]
        par = plans[c.parent]
        used = [x.t for x in par.communications if sm in (x.sender, x.receiver)]
        start[name] = start[c.parent] + (min(used) if used else par.horizon) - plans[name].horizon
    if start:
        low = min(start.values())
        start = {k: v - low for k, v in start.items()}
    H = max((start[k] + plans[k].horizon for k in plans), default=0)
    traj: dict[str, list[str]] = {}
    comms: list[tuple[int, int, Communication]] = []
    rank = {k: i for i, k in enumerate(cs.children_first())}
    join = {r: 0 for r in post_pos}
    for name, plan in plans.items():
        tr, cm = _shift(plan, start[name], H, members[name], post_pos)
        traj.update(tr)
        comms += [(x.t, rank[name], x) for x in cm]
        for r in members[name]:
            join[r] = start[name]
    for r in post_pos:
        traj.setdefault(r, [post_pos[r]] * (H + 1))
    sources = sorted(pre.explore)
    post = Plan(horizon=H, trajectories={r: traj[r] for r in sorted(traj)},
                communications=[x for _, _, x in sorted(comms, key=lambda e: (e[0], e[1]))],
                masters=sorted(post_masters),
                requirements=[Requirement(tuple(sources), (base_station,))] if sources else [],
                phase="post", meta=_merged_meta(plans.values()))
    return post, join


def _merged_meta(plans: Iterable[Plan]) -> dict:
    plans = list(plans)
    return {"clusters": len(plans),
            "cost": round(sum(p.meta.get("cost", 0.0) for p in plans), 6),
            "reward": round(sum(p.meta.get("reward", 0.0) for p in plans), 6),
            "objective": round(sum(p.meta.get("objective", 0.0) for p in plans), 6),
            "gap": worst_gap(plans),
            "status": "optimal" if all(p.meta.get("status") in ("optimal", "trivial") for p in plans) else "feasible",
            "solve_time_s": round(sum(p.meta.get("solve_time_s", 0.0) for p in plans), 4),
            "solver": next((p.meta.get("solver") for p in plans if p.meta.get("solver")), None)}
