"""Plan extraction: the plan of a solved model. Trajectories come from the class
flows; :func:`reconstruct_communications` turns the location-level information flows
into robot-level tuples (t, r, r', b) through each location's communication leader
(PreIntCom, ExtCom, PostIntCom) and prunes every tuple nobody needs."""
from __future__ import annotations

from collections import defaultdict, deque
from typing import Iterable, Mapping

from .ilp_model import EPS, ConnectivityModel, expression_value, value
from .network import MCNetwork
from .plan import MASTER, Communication, Plan


def extract_plan(model: ConnectivityModel) -> Plan:
    """The plan the solved ``model`` holds (robots sent exploring included)."""
    p, T, net = model.p, model.T, model.net
    # trajectories from class flows
    traj: dict[str, list[str]] = {r: [model.pos[r]] for r in model.robots}
    for c in model.classes:
        if c.static:
            for r in c.robots:
                traj[r] = [c.start] * (T + 1)
            continue
        where = {r: c.start for r in c.robots}
        for t in range(T):
            by_loc: dict[str, list[str]] = defaultdict(list)
            for r in c.robots:
                by_loc[where[r]].append(r)
            for u, rs in by_loc.items():
                rs = sorted(rs)
                outs = [u] + sorted(v for v in net.mobility.successors(u) if (c.idx, t, u, v) in model.x)
                i = 0
                for v in outs:
                    var = model.x.get((c.idx, t, u, v))
                    k = int(round(value(var))) if var is not None else 0
                    for r in rs[i:i + k]:
                        where[r] = v
                    i += k
                # numerical slack: anyone left over stays
            for r in c.robots:
                traj[r].append(where[r])
    m_arcs: dict[int, list[tuple[str, str]]] = defaultdict(list)
    for (t, u, v), (f, _e) in model.m_arcs.items():
        if value(f) > EPS:
            m_arcs[t].append((u, v))
    info_arcs: dict[int, list[tuple[str, str, frozenset[str]]]] = defaultdict(list)
    for k, arcs in zip(model.commodities, model.info_arcs):
        for (t, u, v), f in arcs.items():
            if value(f) > EPS:
                info_arcs[t].append((u, v, k.labels))
    holdings = {r: p.holding(r) for r in model.robots}
    needs: dict[str, set[str]] = defaultdict(set)
    for q in p.requirements:
        for s in q.sinks:
            for b in q.sources:
                if b != s:
                    needs[s] |= p.holding(b)
    for r in model.master_sinks:
        needs[r].add(MASTER)
    explorers = frontier_explorers(model, traj)
    for r in explorers:
        needs[r].add(MASTER)
    comms = reconstruct_communications(net, traj, T, model.masters, holdings, m_arcs, info_arcs, needs)
    return Plan(horizon=T, trajectories={r: traj[r] for r in sorted(traj)}, communications=comms,
                masters=sorted(model.masters),
                holdings={r: sorted(holdings[r]) for r in sorted(holdings) if holdings[r] != {r}},
                requirements=list(p.requirements), explore=explorers, phase=p.phase)


def frontier_explorers(model: ConnectivityModel, traj: Mapping[str, list[str]]) -> dict[str, str]:
    """Rewarded robots that end at a frontier and hold m there: they explore it."""
    p, T = model.p, model.T
    out = {}
    for s in sorted(p.frontiers):
        k_max = sum(1 for (ss, _k), yv in model.y.items() if ss == s and value(yv) > 0.5)
        if k_max == 0:
            continue
        cands = []
        for r in model.robots:
            c = model.class_of[r]
            if not c.rewarded or traj[r][T] != s:
                continue
            moved = any(a != b for a, b in zip(traj[r], traj[r][1:]))
            has_m = (r in model.masters or moved or c.start not in model.gated
                     or expression_value(model.g_at(c.start, T)) > 0.5)
            if has_m:
                cands.append(r)
        for r in sorted(cands)[:k_max]:
            out[r] = s
    return out


def reconstruct_communications(net: MCNetwork, traj: Mapping[str, list[str]], T: int, masters: Iterable[str],
                               holdings: Mapping[str, set[str]],
                               m_arcs: Mapping[int, list[tuple[str, str]]],
                               info_arcs: Mapping[int, list[tuple[str, str, frozenset[str]]]],
                               needs: Mapping[str, set[str]]) -> list[Communication]:
    """Robot-level tuples (t, r, r', b) that realise location-level information flows.

    At every step each location with robots has a communication leader (a robot
    holding m when there is one). m spreads over the chosen communication arcs
    leader to leader; at locations that hold m the leader collects what the robots
    there hold (PreIntCom), the leaders pass the labels over the chosen arcs (ExtCom),
    and each leader hands what it has to the robots at its location (PostIntCom).
    A backward pass then keeps only tuples whose receiver uses the label: sends it
    on, moves (m), explores (m) or is a sink that needs it.
    """
    robots = sorted(traj)
    H = {r: set(holdings.get(r, {r})) for r in robots}
    masters = set(masters)
    for r in masters:
        H[r].add(MASTER)
    comms: list[Communication] = []

    def send(t: int, a: str, b: str, label: str) -> None:
        comms.append(Communication(t, a, b, label))
        H[b].add(label)

    for t in range(T + 1):
        present: dict[str, list[str]] = defaultdict(list)
        for r in robots:
            present[traj[r][t]].append(r)
        leader, has_m = {}, set()
        for u, rs in present.items():
            holders = [r for r in rs if MASTER in H[r]]
            leader[u] = holders[0] if holders else rs[0]
            if holders:
                has_m.add(u)
        # m over the chosen communication arcs
        m_out: dict[str, list[str]] = defaultdict(list)
        for u, v in m_arcs.get(t, []):
            m_out[u].append(v)
        queue = deque(sorted(has_m))
        while queue:
            u = queue.popleft()
            for v in sorted(m_out.get(u, [])):
                if v in present and v not in has_m:
                    send(t, leader[u], leader[v], MASTER)
                    has_m.add(v)
                    queue.append(v)
        # PreIntCom: leaders of locations holding m collect
        for u in sorted(has_m):
            lead = leader[u]
            for r in present[u]:
                if r == lead:
                    continue
                extra = sorted(H[r] - H[lead] - {MASTER})
                if extra and MASTER not in H[r]:
                    send(t, lead, r, MASTER)
                for b in extra:
                    send(t, r, lead, b)
        # ExtCom: labels over the chosen arcs, leader to leader, until nothing changes
        arcs = sorted(info_arcs.get(t, []), key=lambda a: (a[0], a[1], sorted(a[2])))
        changed = True
        while changed:
            changed = False
            for u, v, labels in arcs:
                if u not in has_m or v not in present:
                    continue
                for b in sorted((labels & H[leader[u]]) - H[leader[v]] - {MASTER}):
                    send(t, leader[u], leader[v], b)
                    changed = True
        # PostIntCom: leaders hand out
        for u in sorted(has_m):
            lead = leader[u]
            for r in present[u]:
                if r == lead:
                    continue
                if MASTER not in H[r]:
                    send(t, lead, r, MASTER)
                for b in sorted(H[lead] - H[r]):
                    send(t, lead, r, b)

    # backward pass: keep what is used
    need: dict[tuple[str, str], int] = {}
    for r in robots:
        for t in range(T):
            if traj[r][t] != traj[r][t + 1]:
                need[r, MASTER] = t
                break
        for b in needs.get(r, ()):
            need[r, b] = min(need.get((r, b), T), T)
    keep = []
    for c in reversed(comms):
        if (c.receiver, c.info) in need and need[c.receiver, c.info] >= c.t:
            keep.append(c)
            for key in ((c.sender, c.info), (c.sender, MASTER)):
                need[key] = min(need.get(key, T), c.t)
    keep.reverse()
    return keep
