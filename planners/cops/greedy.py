"""Greedy information-consistent plans: warm starts for the integer programs and
upper bounds on their horizons. Robots holding m walk fewest-move routes (ties
broken by name); robots without m wait until m reaches them."""
from __future__ import annotations

import math
from collections import defaultdict, deque
from typing import Iterable, Mapping

from .network import MCNetwork


class Routes:
    """Fewest-move routes over the mobility edges (ties broken by name), from cached
    breadth-first trees; a route's cost is the sum of its mobility costs."""

    def __init__(self, net: MCNetwork) -> None:
        self.net = net
        self.succ = {u: sorted(net.mobility.successors(u)) for u in net.mobility}
        self._trees: dict[str, tuple[dict, dict, dict]] = {}

    def tree(self, src: str) -> tuple[dict, dict, dict]:
        """(parent, hops, cost) of the breadth-first tree from ``src``."""
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


def m_times(net: MCNetwork, traj: Mapping[str, list[str]], masters: Iterable[str], horizon: int,
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


class GreedyPlan:
    """Bookkeeping of a greedy plan: trajectories grown robot by robot."""

    def __init__(self, net: MCNetwork, pos: Mapping[str, str], masters: set[str], static: set[str]) -> None:
        self.net, self.pos, self.static = net, dict(pos), set(static)
        self.routes = Routes(net)
        self.comm_succ = {u: sorted(net.communication.successors(u)) for u in net.communication}
        self.comm_pred = {u: sorted(net.communication.predecessors(u)) for u in net.communication}
        self.robots = sorted(pos)
        self.mobile = [r for r in self.robots if r not in self.static]
        self.traj = {r: [pos[r]] for r in self.robots}
        self.masters = set(masters)
        self.got = m_times(net, self.traj, self.masters, 0, self.comm_succ)
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
    g = GreedyPlan(network, positions, set(masters), set(static))
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
        got = m_times(network, g.padded(T), g.masters, T, g.comm_succ)
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
    g = GreedyPlan(network, positions, set(masters), set(static))
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

    def relay_plan(u: str) -> tuple[float, list[tuple[str, str]]] | None:
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
