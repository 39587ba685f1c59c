"""Problem 1 (pre-exploration), Problem 2 (post-exploration), the horizon search and
one COPS cycle (pre-exploration, exploration, post-exploration) without clustering.

How a horizon is chosen. The integer programs are hard for the solver to *prove*
optimal (a fractional robot smeared along a tunnel is a fine relay chain in the
linear relaxation) but easy to *complete and improve* from a good plan. So every
problem first gets a greedy information-consistent plan (:func:`greedy_pre_plan`,
:func:`greedy_post_plan`: robots holding m walk shortest routes; the greedy plan
fixes the horizon, an upper bound), then one integer program is solved at that
horizon, warm-started from it, with a tiny cost on late actions; the best plan
found within the time limit is cut after its last action. The solver's answer is
never worse than the greedy plan, and its optimality gap is reported in
``plan.meta["gap"]`` (None when unknown).
"""
from __future__ import annotations

import math
import time
from collections import defaultdict, deque
from dataclasses import dataclass, replace
from typing import Iterable, Mapping

import networkx as nx

from .ilp import (ConnectivityProblem, InfeasibleProblem, SolverOptions, SolverTimeout,
                  information_distance, solve_connectivity)
from .network import MCNetwork
from .plan import CyclePlan, ExplorationTask, Plan, Requirement, idle_plan

#: Default minimum exploration time of a cycle, in plan steps (ΔT each).
DEFAULT_MIN_EXPLORATION_STEPS = 4
#: Cost per action (move or message) and step index that makes the solver prefer early
#: actions among equally good plans; small against any real cost (0.1 a message).
TIME_WEIGHT = 1e-5
#: However little of ``total_time_limit_s`` is left, a solve gets at least this long.
MIN_SOLVE_TIME_S = 0.3
#: Share of a cycle's time budget given to pre-exploration (post-exploration gets the rest).
PRE_SHARE = 0.55


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


# ---------------------------------------------------------------------------------------
# time budgets
# ---------------------------------------------------------------------------------------

class _Budget:
    """The time left of ``options.total_time_limit_s`` and the limit of the next solve."""

    def __init__(self, opts: SolverOptions) -> None:
        self.opts = opts
        total = opts.total_time_limit_s
        self.end = None if total is None else time.perf_counter() + total

    def left(self) -> float | None:
        return None if self.end is None else max(self.end - time.perf_counter(), 0.0)

    def limit(self, share: float = 1.0, probe: bool = False) -> float | None:
        """Time limit of the next solve: ``time_limit_s`` (``probe_time_limit_s``), cut to
        ``share`` of the time left (at least :data:`MIN_SOLVE_TIME_S`)."""
        lim = self.opts.probe_time_limit_s if probe else self.opts.time_limit_s
        left = self.left()
        if left is None:
            return lim
        cut = max(MIN_SOLVE_TIME_S, left * share)
        return cut if lim is None else min(lim, cut)

    def options(self, share: float = 1.0) -> SolverOptions:
        """Options for a sub-problem that may use ``share`` of the time left."""
        left = self.left()
        if left is None:
            return self.opts
        return replace(self.opts, total_time_limit_s=max(MIN_SOLVE_TIME_S, left * share))


# ---------------------------------------------------------------------------------------
# greedy plans (warm starts and horizon bounds)
# ---------------------------------------------------------------------------------------

class _Routes:
    """Fewest-move routes over the mobility edges (ties broken by name), from cached
    breadth-first trees; a route's cost is the sum of its mobility costs."""

    def __init__(self, net: MCNetwork) -> None:
        self.net = net
        self.succ = {u: sorted(net.mobility.successors(u)) for u in net.mobility}
        self._trees: dict[str, tuple[dict, dict, dict]] = {}

    def tree(self, src: str):
        if src not in self._trees:
            parent: dict[str, str | None] = {src: None}
            hops, cost = {src: 0}, {src: 0.0}
            queue = deque([src])
            while queue:
                u = queue.popleft()
                for v in self.succ[u]:
                    if v not in parent:
                        parent[v], hops[v] = u, hops[u] + 1
                        cost[v] = cost[u] + self.net.mobility_cost(u, v)
                        queue.append(v)
            self._trees[src] = (parent, hops, cost)
        return self._trees[src]

    def hops(self, src: str, dst: str) -> float:
        return self.tree(src)[1].get(dst, math.inf)

    def cost(self, src: str, dst: str) -> float:
        return self.tree(src)[2].get(dst, math.inf)

    def nearest(self, src: str, targets: Iterable[str]) -> str | None:
        _parent, hops, cost = self.tree(src)
        best = min((t for t in targets if t in hops), key=lambda t: (hops[t], cost[t], t), default=None)
        return best

    def path(self, src: str, dst: str) -> list[str] | None:
        parent = self.tree(src)[0]
        if dst not in parent:
            return None
        out = [dst]
        while out[-1] != src:
            out.append(parent[out[-1]])
        return out[::-1]


def _m_times(net: MCNetwork, traj: Mapping[str, list[str]], masters: Iterable[str], horizon: int,
             comm_succ: Mapping[str, list[str]]) -> dict[str, int]:
    """The step at which each robot first holds m when the robots follow ``traj`` (the
    last location held) and m spreads at every step from its holders over
    communication edges between occupied locations (relay chains included)."""
    got = {r: 0 for r in masters if r in traj}
    for t in range(horizon + 1):
        at: dict[str, list[str]] = defaultdict(list)
        for r, tr in traj.items():
            at[tr[min(t, len(tr) - 1)]].append(r)
        reached = sorted(u for u, rs in at.items() if any(r in got for r in rs))
        seen, queue = set(reached), deque(reached)
        while queue:
            u = queue.popleft()
            for v in comm_succ.get(u, ()):
                if v in at and v not in seen:
                    seen.add(v)
                    queue.append(v)
        for u in seen:
            for r in at[u]:
                got.setdefault(r, t)
    return got


class _Greedy:
    """Bookkeeping of a greedy plan: trajectories grown robot by robot."""

    def __init__(self, net: MCNetwork, pos: Mapping[str, str], masters: set[str], static: set[str]) -> None:
        self.net, self.pos, self.static = net, dict(pos), set(static)
        self.routes = _Routes(net)
        self.comm_succ = {u: sorted(net.communication.successors(u)) for u in net.communication}
        self.comm_pred = {u: sorted(net.communication.predecessors(u)) for u in net.communication}
        self.robots = sorted(pos)
        self.mobile = [r for r in self.robots if r not in self.static]
        self.traj = {r: [pos[r]] for r in self.robots}
        self.masters = set(masters)
        self.got = _m_times(net, self.traj, self.masters, 0, self.comm_succ)
        self.free = {r: (0, pos[r]) for r in self.mobile if r in self.got}  # robot -> (step, location)

    def walk(self, r: str, path: list[str], start: int) -> None:
        tr = self.traj[r]
        while len(tr) < start + 1:
            tr.append(tr[-1])
        tr.extend(path[1:])
        self.free[r] = (len(tr) - 1, tr[-1])

    def horizon(self) -> int:
        return max(len(tr) for tr in self.traj.values()) - 1

    def padded(self, T: int | None = None) -> dict[str, list[str]]:
        T = self.horizon() if T is None else T
        return {r: tr + [tr[-1]] * (T + 1 - len(tr)) for r, tr in self.traj.items()}

    def into_range(self, r: str, location: str) -> tuple[int, list[str]] | None:
        """Route of free robot r to the nearest place it can send to ``location`` from:
        (arrival step, route)."""
        t0, at = self.free[r]
        dst = self.routes.nearest(at, [location] + self.comm_pred.get(location, []))
        if dst is None:
            return None
        path = self.routes.path(at, dst)
        return t0 + len(path) - 1, path

    def deliver_m(self, r: str, location: str, arrival: int, path: list[str]) -> None:
        """Robot r brings m within range of ``location``: the robots there hold it from then."""
        self.walk(r, path, self.free[r][0])
        for q in self.robots:
            if self.pos[q] == location and q not in self.got and len(self.traj[q]) == 1:
                self.got[q] = arrival
                if q not in self.static:
                    self.free[q] = (arrival, location)


def greedy_pre_plan(network: MCNetwork, positions: Mapping[str, str], masters: Iterable[str],
                    static: Iterable[str], rewarded: Iterable[str],
                    rewards: Mapping[str, tuple[float, ...]],
                    master_sinks: Iterable[str] = ()) -> dict[str, list[str]] | None:
    """A greedy information-consistent pre-exploration: trajectories of equal length
    (None when the greedy rules find no way to bring m to a master sink).

    Robots that hold m bring it within radio range of each master sink (the nearest
    such robot first); then, while a move pays, the robot (holding m) and frontier
    slot with the largest gain R(s, k) − R(s, k−1) − route cost are matched, where a
    robot still without m counts when a robot with m can first bring it m (the
    courier's route is paid too); robots that m reaches along the way join."""
    g = _Greedy(network, positions, set(masters), set(static))
    rew = set(rewarded)
    for s in sorted(master_sinks, key=lambda r: (g.pos[r], r)):
        if s in g.got:
            continue
        best = None
        for r in sorted(g.free):
            got = g.into_range(r, g.pos[s])
            if got is not None and (best is None or (got[0], r) < best[0]):
                best = ((got[0], r), got[1])
        if best is None:
            return None
        (arrival, r), path = best
        g.deliver_m(r, g.pos[s], arrival, path)
    slots = {s: list(m) for s, m in sorted(rewards.items()) if m and s in network}
    busy: dict[str, str] = {}  # robot -> the rewarded place it holds
    gated = sorted({g.pos[r] for r in g.mobile if r in rew and r not in g.free})
    while True:
        best = None  # (key, robot, frontier, courier plan)
        targets = [s for s in slots if slots[s]]
        if not targets:
            break
        for r in sorted(g.free):
            if r in busy or r not in rew:
                continue
            t0, at = g.free[r]
            for s in targets:
                gain = slots[s][0] - g.routes.cost(at, s)
                if gain > 0:
                    key = (-gain, t0 + g.routes.hops(at, s), r, s)
                    if best is None or key < best[0]:
                        best = (key, r, s, None)
        # robots without m: a courier brings m first
        for u in gated:
            waiting = [q for q in g.robots
                       if g.pos[q] == u and q in rew and q not in g.free and len(g.traj[q]) == 1]
            if not waiting:
                continue
            couriers = []
            # an idle robot brings m; failing that, one that holds a rewarded place
            # goes out and comes back (a recall fetches the far robots so)
            for pool in (sorted(r for r in g.free if r not in busy), sorted(busy)):
                for c in pool:
                    got = g.into_range(c, u)
                    if got is not None:
                        cost = sum(network.mobility_cost(a, b) for a, b in zip(got[1], got[1][1:]))
                        if c in busy:
                            cost += g.routes.cost(got[1][-1], busy[c])
                        couriers.append((got[0], cost, c, got[1]))
                if couriers:
                    break
            if not couriers:
                continue
            arrival, c_cost, c, path = min(couriers, key=lambda e: (e[0], e[1], e[2]))
            for s in targets:
                gain = slots[s][0] - c_cost - g.routes.cost(u, s)
                if gain > 0:
                    key = (-gain, arrival + g.routes.hops(u, s), waiting[0], s)
                    if best is None or key < best[0]:
                        best = (key, waiting[0], s, (c, u, arrival, path))
        if best is None:
            break
        _key, r, s, courier = best
        if courier is not None:
            c, u, arrival, path = courier
            g.deliver_m(c, u, arrival, path)
            if c in busy:
                g.walk(c, g.routes.path(path[-1], busy[c]), g.free[c][0])
        t0, at = g.free[r]
        g.walk(r, g.routes.path(at, s), t0)
        busy[r] = s
        slots[s].pop(0)
        # robots that m reached on the way become free too
        T = g.horizon()
        got = _m_times(network, g.padded(T), g.masters, T, g.comm_succ)
        for q in g.mobile:
            if q not in g.free and q in got and len(g.traj[q]) == 1:
                g.free[q] = (got[q], g.pos[q])
                g.got[q] = got[q]
        gated = sorted({g.pos[q] for q in g.mobile if q in rew and q not in g.free})
    return g.padded()


def greedy_post_plan(network: MCNetwork, positions: Mapping[str, str], masters: Iterable[str],
                     static: Iterable[str], sources: Iterable[str], sink: str,
                     sink_final_location: str | None = None) -> dict[str, list[str]] | None:
    """A greedy post-exploration: trajectories of equal length after which every
    source's information can reach ``sink`` (None when the greedy rules fail).

    For each source (nearest the sink first) the cheaper of two ways is taken: a
    relay chain (robots holding m that have nothing else to do walk to the missing
    links of the radio chain from the source to where the sink ends, so the
    information goes over the air), or carrying it: a mobile source holding m walks
    into radio range of the sink, one that cannot walk (static, or without m) is
    fetched by the robot holding m (the sink included) that can pick it up and bring
    it into range earliest. A mobile sink then walks to its final location."""
    g = _Greedy(network, positions, set(masters), set(static))
    final = g.pos[sink] if sink_final_location is None else sink_final_location
    if final != g.pos[sink] and sink not in g.free:
        return None
    deliver = [final] + g.comm_pred.get(final, [])
    srcs = sorted(set(sources) - {sink})
    # radio chains towards the sink: chain[v] is the next location of the fewest-link chain
    chain: dict[str, str | None] = {final: None}
    queue = deque([final])
    while queue:
        x = queue.popleft()
        for w in g.comm_pred.get(x, []):
            if w not in chain:
                chain[w] = x
                queue.append(w)
    idle = [r for r in sorted(g.free) if r not in srcs and r != sink]
    staffed: set[str] = {final} if final == g.pos[sink] else set()
    for r in g.robots:
        if r in g.static and r in g.got:
            staffed.add(g.pos[r])

    def relay_plan(u: str):
        """Robots to send to the missing links of u's chain: (cost, [(robot, location)])."""
        if u not in chain:
            return None
        links, x = [], chain[u]
        while x is not None and x != final:
            if x not in staffed:
                links.append(x)
            x = chain[x]
        if final not in staffed and final != g.pos[sink]:
            return None  # the sink is not there before the end: carry instead
        free = list(idle)
        total, moves = 0.0, []
        for x in links:
            best = min(free, key=lambda r: (g.routes.cost(g.free[r][1], x), r), default=None)
            if best is None or g.routes.cost(g.free[best][1], x) == math.inf:
                return None
            total += g.routes.cost(g.free[best][1], x)
            moves.append((best, x))
            free.remove(best)
        return total, moves

    carried: list[str] = []
    groups: dict[tuple[str, bool], list[str]] = defaultdict(list)
    for b in srcs:
        groups[g.pos[b], b in g.free].append(b)
    collected: set[str] = set()
    # farthest first: one source of a place walks (a collector) and picks up on its way
    # the information of every source it passes in radio range of
    for (u, walks), bs in sorted(groups.items(), key=lambda kv: (-g.routes.hops(kv[0][0], final), kv[0])):
        bs = [b for b in bs if b not in collected]
        if not bs:
            continue
        if not walks and not all(b in g.got for b in bs):
            return None  # it cannot even send its information
        # where the collector walks to (a place on its way; a source that cannot walk
        # stays), then a relay chain from there: the cheapest total
        way = (g.routes.path(u, g.routes.nearest(u, deliver) or u) or [u]) if walks else [u]
        best = None
        for i, x in enumerate(way):
            walk_cost = sum(network.mobility_cost(a, b) for a, b in zip(way[:i], way[1:i + 1]))
            relay = (0.0, []) if x in deliver or x == final else relay_plan(x)
            if relay is None:
                continue
            key = (walk_cost + relay[0], i)
            if best is None or key < best[0]:
                best = (key, i, relay[1])
        if best is None:
            if walks:
                return None
            carried.extend(bs)
            continue
        _key, i, moves = best
        for r, x in moves:
            t0, at = g.free[r]
            g.walk(r, g.routes.path(at, x), t0)
            idle.remove(r)
            staffed.add(x)
        if walks and i:
            t0, at = g.free[bs[0]]
            g.walk(bs[0], way[:i + 1], t0)
        staffed.add(way[i])
        passed = set(way[:i + 1])
        collected |= set(bs)
        for b in srcs:
            v = g.pos[b]
            if b not in collected and b in g.got and len(g.traj[b]) == 1 and \
                    (v in passed or passed & set(g.comm_succ.get(v, []))):
                collected.add(b)
    for b in carried:
        meet = [g.pos[b]] + g.comm_succ.get(g.pos[b], [])
        best = None
        for r in sorted(g.free):
            t0, at = g.free[r]
            m1 = g.routes.nearest(at, meet)
            if m1 is None:
                continue
            m2 = final if r == sink else g.routes.nearest(m1, deliver)
            if m2 is None:
                continue
            key = (t0 + g.routes.hops(at, m1) + g.routes.hops(m1, m2), r)
            if best is None or key < best[0]:
                best = (key, r, m1, m2)
        if best is None:
            return None
        _key, r, m1, m2 = best
        t0, at = g.free[r]
        g.walk(r, g.routes.path(at, m1), t0)
        if r != sink:
            g.walk(r, g.routes.path(m1, m2), g.free[r][0])
    if sink in g.free and g.free[sink][1] != final:
        t0, at = g.free[sink]
        path = g.routes.path(at, final)
        if path is None:
            return None
        g.walk(sink, path, t0)
    return g.padded()


def _trim(plan: Plan) -> Plan:
    """Cut ``plan`` after its last action (move or message); nothing changes after it."""
    T = plan.horizon
    last = max((c.t for c in plan.communications), default=0)
    for traj in plan.trajectories.values():
        for t in range(T - 1, last - 1, -1):
            if traj[t] != traj[t + 1]:
                last = t + 1
                break
    if last < T:
        plan.trajectories = {r: traj[:last + 1] for r, traj in plan.trajectories.items()}
        plan.horizon = last
    return plan


def horizon_of(traj: Mapping[str, list[str]] | None) -> int | None:
    if traj is None:
        return None
    return max((len(tr) for tr in traj.values()), default=1) - 1


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
            if deadline is not None and time.perf_counter() > deadline:
                break
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
        if deadline is not None and time.perf_counter() > deadline:
            break
        T += 1
    if best is None and timed_out is not None:
        raise timed_out
    return best, best_T


# ---------------------------------------------------------------------------------------
# Problem 1
# ---------------------------------------------------------------------------------------

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
    budget = _Budget(opts)
    pos, st, ex = _robot_sets(network, positions, static, explorers)
    ms = _masters(network, pos, masters)
    fr = sorted(network.frontiers if frontiers is None else set(frontiers))
    for s in fr:
        if s not in network:
            raise ValueError(f"frontier '{s}' is not a location")
    rw = reward or FrontierReward()
    mobile_ex = sorted(ex - st)
    mdist = _m_reachable(network, pos, ms)
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
    holders = _m_times(network, {r: [s] for r, s in pos.items()}, ms, 0,
                       {u: sorted(network.communication.successors(u)) for u in network.communication})
    if not sinks and not any(r in holders for r in pos if r not in st):
        return idle_plan(pos, ms, phase)
    greedy = None
    if not (col_r and col_s):  # the greedy rules know nothing of collisions
        greedy = greedy_pre_plan(network, pos, ms, st, ex, rewards, sinks)
    T_h = horizon_of(greedy)
    hi = max_horizon if max_horizon is not None else max(lower + 2 * horizon_patience + 2, len(network),
                                                         (T_h or 0) + horizon_patience)

    def make(T: int, warm=None, tw: float = 0.0, limit: float | None = None) -> Plan | None:
        if warm is not None and horizon_of(warm) > T:
            warm = None
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=ex,
            location_rewards=rewards, frontiers=set(fr), master_sinks=set(sinks),
            collision_robots=col_r, collision_locations=col_s, phase=phase, options=opts,
            warm_start=warm, time_weight=tw), time_limit_s=budget.limit() if limit is None else limit)

    if horizon is not None:
        plan = make(horizon, greedy)
        if plan is None:
            raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={horizon}")
        return plan
    if greedy is not None and T_h <= hi:
        T = min(max(T_h + max(horizon_patience, 0), 1), hi)
        plan = make(T, greedy, TIME_WEIGHT)
        if plan is not None:
            return _trim(plan)
    deadline = None if budget.end is None else budget.end
    plan, _ = _search(lambda T: make(T), max(lower, 1), max(hi, lower, 1), True, horizon_patience, deadline)
    if plan is None:
        raise InfeasibleProblem(f"no information-consistent pre-exploration plan within horizon T={hi}")
    return plan


# ---------------------------------------------------------------------------------------
# Problem 2
# ---------------------------------------------------------------------------------------

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
    (:func:`greedy_post_plan`); feasibility probes (each within
    ``probe_time_limit_s``) bisect below it while time allows, and the least-cost
    plan is solved at the smallest horizon found feasible, warm-started, then cut
    after its last action. Without a greedy plan the smallest feasible T is searched
    from a lower bound up to ``max_horizon``. Raises :class:`InfeasibleProblem` naming
    a robot whose information cannot reach the base within the horizon.
    ``base_station`` may name another sink; with ``static_sink=False`` it need not be
    static, and ``sink_final_location`` is where it must end.
    """
    opts = options or SolverOptions()
    budget = _Budget(opts)
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
    if sink_final_location is not None and sink_final_location not in network:
        raise ValueError(f"sink final location '{sink_final_location}' is not a location")
    hold = {r: set(b) for r, b in (holdings or {}).items()}
    base_loc = pos[base]
    moving_sink = sink_final_location is not None and sink_final_location != base_loc
    if not srcs and not moving_sink:
        return idle_plan(pos, ms, phase, hold)
    mdist = _m_reachable(network, pos, ms)
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

    def make(T: int, sub: list[str] | None = None, probe: bool = False, warm=None, tw: float = 0.0,
             limit: float | None = None) -> Plan | None:
        q = req if sub is None else [Requirement(tuple(sub), (base,))]
        o = replace(opts, mip_gap=None) if probe else opts
        if warm is not None and horizon_of(warm) > T:
            warm = None
        return solve_connectivity(ConnectivityProblem(
            network=network, horizon=T, positions=pos, masters=ms, static=st, explorers=set(),
            holdings=hold, requirements=q, final_positions=final,
            collision_robots=col_r, collision_locations=col_s,
            phase=phase, options=o, feasibility_only=probe, warm_start=warm, time_weight=tw),
            time_limit_s=(budget.limit(probe=probe) if limit is None else limit))

    if horizon is not None:
        plan = make(horizon, warm=greedy)
        if plan is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, horizon))
        return plan

    def probe(T: int) -> Plan | None:
        try:
            return make(T, probe=True, limit=budget.limit(share=0.25, probe=True))
        except SolverTimeout:
            return None

    lo = int(max(lower, 0))
    if greedy is not None and T_h <= hi:
        # bisect below the greedy horizon with feasibility probes while time allows,
        # then the least-cost plan at the best horizon, warm-started
        best_T, bad, warm = T_h, lo - 1, greedy
        while best_T - bad > 1 and (budget.left() is None or budget.left() > 4 * MIN_SOLVE_TIME_S):
            mid = (best_T + bad) // 2
            try:
                found = make(mid, probe=True, limit=budget.limit(share=0.25, probe=True))
            except SolverTimeout:
                break  # too hard to tell in time: larger horizons are harder still
            if found is None:
                bad = mid
            else:
                best_T, warm = mid, found.trajectories
        try:
            plan = make(best_T, warm=warm, tw=TIME_WEIGHT)
        except SolverTimeout:
            plan = None
        if plan is not None:
            return _trim(plan)
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
    while found is None and T < hi and (budget.left() is None or budget.left() > MIN_SOLVE_TIME_S):
        T += 1
        found = probe(T)
    if found is None:
        # probes may have timed out: one full solve at the largest horizon decides
        found = make(hi)  # raises SolverTimeout when even that finds nothing in time
        if found is None:
            raise InfeasibleProblem(_diagnose_post(make, srcs, bounds, hi))
        return found
    best_T, bad = T, lo - 1
    while best_T - bad > 1 and (budget.left() is None or budget.left() > 4 * MIN_SOLVE_TIME_S):
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
    (:mod:`delve.planners.cops.clustering`). ``options.total_time_limit_s`` bounds the
    whole cycle (pre-exploration gets :data:`PRE_SHARE` of it); ``meta["gap"]`` is the
    worst optimality gap of its integer programs (None: unknown)."""
    from .clustering import plan_cycle_clustered, should_cluster

    t0 = time.perf_counter()
    opts = options or SolverOptions()
    pos, st, ex = _robot_sets(network, positions, static, explorers)
    ms = _masters(network, pos, masters)
    use = should_cluster(network, pos, ms, frontiers=frontiers, static=st, explorers=ex, reward=reward) \
        if clustering == "auto" else bool(clustering)
    if use:
        kw = {} if max_cluster_locations is None else {"max_cluster_locations": max_cluster_locations}
        cyc = plan_cycle_clustered(network, positions=pos, frontiers=frontiers, masters=ms, reward=reward,
                                   explorers=ex, static=st, min_exploration_steps=min_exploration_steps,
                                   max_horizon=max_horizon, options=opts, **kw)
        cyc.meta["solve_time_s"] = round(time.perf_counter() - t0, 4)
        return cyc
    budget = _Budget(opts)
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
        "gap": _max_gap([pre, post])})


def _max_gap(plans: Iterable[Plan]):
    gaps = [p.meta.get("gap") for p in plans]
    if any(g is None for g in gaps):
        return None
    return max(gaps, default=0.0)
