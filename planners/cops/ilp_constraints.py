"""The constraint families of the intermittent-connectivity integer program, one
function each, and :func:`build_model`, which adds them in a fixed order.

At step t robots first communicate at their locations s_t, then move to s_{t+1}.

* :func:`add_motion` (trajectories). Robots with the same start location and
  attributes form a class; x[c, t, u, v] ∈ {0..|c|} counts robots of class c moving
  u -> v (u = v: staying) during step t. Flow conservation per class gives the
  trajectories; static robots have no variables. Mobility cost Σ C̄(u, v) x[c, t, u, v]
  is the first sum of (1).
* :func:`add_master_information` (information consistency). m flows from the
  masters' locations; w[u, t] = 1 when it reaches location u, where robots without m
  wait (the consumers). A class that starts at u may leave only after m reached u
  (Σ_{τ<=t} w[u, τ] >= moves), and a location sends over a communication edge only
  when a robot there holds m: a robot away from its start (it moved, so it has m) or
  a robot at its start after m came.
* :func:`add_information_flows`. Information moves with robots along mobility arcs
  (capacity bounded by the robots that take the arc) and between robots along
  communication arcs of one step (bounded by robots present at both ends, and by a
  sender that holds m). One commodity per connectivity constraint with a single sink
  (every source location supplies one unit per label, the sink absorbs them all: the
  flow's path decomposition routes every source to the sink), one commodity per
  source location otherwise. Conservation at every time-expanded node makes each
  sink's information come from a real source, with no communication cycle. The
  communication cost C̃ is paid per label sent over a communication edge (the second
  sum of (1)).
* :func:`add_final_locations`: robots that must end at a given location.
* :func:`add_frontier_rewards` (Problem 1). y[s, k] = 1 when at least k
  exploration-capable robots that hold m stand at frontier s at T; the objective
  gains ΔR(s, k) = R(s, k) − R(s, k−1). Only capable robots count.
* :func:`add_collisions`. Collision robots never share a collision location nor
  traverse the same edge at once.
"""
from __future__ import annotations

import math
from collections import defaultdict

import pulp

from .distances import information_distance
from .ilp_model import Commodity, ConnectivityModel, RobotClass
from .ilp_problem import ConnectivityProblem
from .plan import MASTER


def build_model(p: ConnectivityProblem) -> ConnectivityModel:
    """The model of ``p``: every constraint family, then the objective (none for a
    feasibility problem)."""
    model = ConnectivityModel(p)
    add_motion(model)
    add_master_information(model)
    add_information_flows(model)
    add_final_locations(model)
    add_frontier_rewards(model)
    add_collisions(model)
    if not p.feasibility_only:
        model.objective = (pulp.lpSum(model.reward_terms) - pulp.lpSum(model.cost_terms)
                           - pulp.lpSum(model.time_terms))
    return model


def add_motion(model: ConnectivityModel) -> None:
    """Flow conservation of every mobile class over the time-expanded network, with the
    mobility cost; then the robots that can carry information along each arc."""
    net, T, succ = model.net, model.T, model.succ
    x, occ_in, movers, static_count = model.x, model.occ_in, model.movers, model.static_count
    for c in model.classes:
        if c.static:
            static_count[c.start] += c.n
            continue
        for t in range(T):
            for u, e in c.earliest.items():
                if e > t:
                    continue
                outs = [u] + [v for v in succ[u] if c.earliest.get(v, math.inf) <= t + 1]
                for v in outs:
                    var = model.var(0, c.n, pulp.LpInteger)
                    x[c.idx, t, u, v] = var
                    occ_in[c.idx, t + 1, v].append(var)
                    movers[t, u, v].append(var)
                    if u != v:
                        cost = net.mobility_cost(u, v)
                        if cost:
                            model.cost_terms.append(cost * var)
                        model.timed(t, var)
                out_terms = [x[c.idx, t, u, v] for v in outs]
                if t == 0:
                    model.eq(out_terms, c.n if u == c.start else 0)
                else:
                    model.eq(out_terms, pulp.lpSum(occ_in[c.idx, t, u]))
    # robots that can carry information along each mobility arc (u = v: staying)
    carry: dict[tuple[int, str, str], list] = {key: list(mv) for key, mv in movers.items()}
    for u, n in static_count.items():
        for t in range(T):
            carry.setdefault((t, u, u), []).append(n)
    model.carry = carry


def add_master_information(model: ConnectivityModel) -> None:
    """m flows from the masters to every gated location (one with robots waiting for
    it); classes there leave only after it came; master sinks receive it."""
    if not model.gated:
        return
    net, T, x, w = model.net, model.T, model.x, model.w
    gated, occupiable = model.gated, model.occupiable
    U = len(gated)
    to_gated = information_distance(net, gated, reverse=True)

    def m_possible(v: str, t: int) -> bool:
        return model.m_dist.get(v, math.inf) <= t and v in occupiable[t]

    def m_useful(v: str, t: int) -> bool:
        return to_gated.get(v, math.inf) <= T - t

    inflow: dict[tuple[str, int], list] = defaultdict(list)
    outflow: dict[tuple[str, int], list] = defaultdict(list)
    for u in gated:
        lo = model.m_dist.get(u, math.inf)
        for t in range(T + 1):
            if t >= lo and u in occupiable[t]:
                w[u, t] = model.var(0, 1, pulp.LpBinary)
                outflow[u, t].append(w[u, t])
        if any((u, t) in w for t in range(T + 1)):
            model.le([w[u, t] for t in range(T + 1) if (u, t) in w], 1)
    model.carry_arcs(model.carry, lambda t, u, v: m_possible(u, t) and m_useful(v, t + 1), U, inflow, outflow)
    for t in range(T + 1):
        for u, v in model.comm_edges:
            if not (m_possible(u, t) and v in occupiable[t] and m_useful(v, t)):
                continue
            f = model.var(0, U)
            e = model.var(0, 1, pulp.LpBinary)
            model.le([f], U * e)
            model.le([e], model.total_occ(t, v))
            model.le([e], model.mholder(t, u))
            cost = net.communication_cost(u, v)
            if cost:
                model.cost_terms.append(cost * e)
            model.timed(t, e)
            outflow[u, t].append(f)
            inflow[v, t].append(f)
            model.m_arcs[t, u, v] = (f, e)
    for key in sorted(set(inflow) | set(outflow), key=lambda k: (k[1], k[0])):
        v, t = key
        supply = U if (t == 0 and v in model.master_locs) else 0
        # in + supply >= out + absorbed (m may be dropped, never created)
        model.le(outflow.get(key, []), pulp.lpSum(inflow.get(key, [])) + supply)
    # a class waits at its start until m arrives there
    for c in model.classes:
        if c.static or c.start not in model.gated_set:
            continue
        for t in range(T):
            leave = [x[c.idx, t, c.start, v] for v in model.succ[c.start]
                     if (c.idx, t, c.start, v) in x]
            if leave:
                model.le(leave, c.n * model.g_at(c.start, t))
    for r in sorted(model.master_sinks):
        u = model.pos[r]
        if u in model.gated_set:
            model.eq([w[u, t] for t in range(T + 1) if (u, t) in w], 1)


def add_information_flows(model: ConnectivityModel) -> None:
    """One commodity per connectivity constraint with a single sink, one per source
    location otherwise; each flows with robots and over communication edges from its
    sources to its sinks, conserved at every time-expanded node."""
    p, net, T, pos = model.p, model.net, model.T, model.pos
    commodities = model.commodities
    for q in p.requirements:
        qsinks = sorted(set(q.sinks))
        by_loc: dict[str, list[str]] = defaultdict(list)
        for b in q.sources:
            if p.holding(b):
                by_loc[pos[b]].append(b)
        if len(qsinks) == 1:
            # one sink: a single commodity, one unit per label; every unit leaves its
            # source and ends at the sink, so the flow's path decomposition gives each
            # source a route to the sink (and the model is |sources| times smaller)
            snk = qsinks[0]
            supply = {}
            for u in sorted(by_loc):
                labels_u = set().union(*(p.holding(b) for b in by_loc[u] if b != snk)) - {MASTER}
                if any(b != snk for b in by_loc[u]):
                    supply[u] = max(1, len(labels_u))
            if supply:
                labels = frozenset().union(*(p.holding(b) for u in supply for b in by_loc[u] if b != snk))
                commodities.append(_commodity(model, labels, supply, {snk: sum(supply.values())}, True,
                                              unit_labels=1))
            continue
        for u in sorted(by_loc):
            need = [s for s in qsinks if any(b != s for b in by_loc[u])]
            if not need:
                continue
            labels = frozenset().union(*(p.holding(b) for b in by_loc[u]))
            commodities.append(_commodity(model, labels, {u: len(need)}, {s: 1 for s in need},
                                          len(need) == 1))
    carry, occupiable = model.carry, model.occupiable
    for k in commodities:
        U = k.bound

        def possible(v: str, t: int) -> bool:
            if t < k.earliest.get(v, math.inf) or v not in occupiable[t]:
                return False
            return k.latest_slack is None or k.latest_slack.get(v, math.inf) <= T - t

        inflow: dict[tuple[str, int], list] = defaultdict(list)
        outflow: dict[tuple[str, int], list] = defaultdict(list)
        model.carry_arcs(carry, lambda t, u, v: possible(u, t) and possible(v, t + 1), U, inflow, outflow)
        arcs = {}
        for t in range(T + 1):
            for u, v in model.comm_edges:
                if not (possible(u, t) and possible(v, t)):
                    continue
                f = model.var(0, U)
                model.le([f], U * model.total_occ(t, v))
                model.le([f], U * model.mholder(t, u))
                cost = net.communication_cost(u, v) * k.unit_labels
                if k.single_sink:
                    if cost:
                        model.cost_terms.append(cost * f)
                    model.timed(t, f)
                else:
                    e = model.var(0, 1, pulp.LpBinary)
                    model.le([f], U * e)
                    if cost:
                        model.cost_terms.append(cost * e)
                    model.timed(t, e)
                outflow[u, t].append(f)
                inflow[v, t].append(f)
                arcs[t, u, v] = f
        model.info_arcs.append(arcs)
        nodes = set(inflow) | set(outflow) | {(u, 0) for u in k.supply}
        demand_terms: dict[tuple[str, int], list] = defaultdict(list)
        for s, amount in k.demand.items():
            c = model.class_of[s]
            for v, e in c.earliest.items():
                if e <= T:
                    demand_terms[v, T].append(amount * model.occ(c, T, v))
                    nodes.add((v, T))
        for key in sorted(nodes, key=lambda k: (k[1], k[0])):
            v, t = key
            supply = k.supply.get(v, 0) if t == 0 else 0
            model.eq(inflow.get(key, []) + [supply],
                     pulp.lpSum(outflow.get(key, [])) + pulp.lpSum(demand_terms.get(key, [])))


def _commodity(model: ConnectivityModel, labels: frozenset[str], supply: dict[str, int],
               demand: dict[str, int], single_sink: bool, unit_labels: int | None = None) -> Commodity:
    """A commodity with the bounds that prune its arcs: the earliest step it can be at
    each location, and (when every sink ends at a known place) the steps it still needs."""
    start = {u: (0 if u in model.master_locs else int(min(model.m_dist.get(u, math.inf), model.T + 1)))
             for u in supply}
    earliest = information_distance(model.net, list(supply), start=start)
    for u in supply:
        earliest[u] = 0
    sink_locs = []
    all_static = True
    for s in demand:
        c = model.class_of[s]
        if c.static:
            sink_locs.append(c.start)
        elif s in model.p.final_positions:  # the sink ends there, so must its information
            sink_locs.append(model.p.final_positions[s])
        else:
            all_static = False
    slack = information_distance(model.net, sink_locs, reverse=True) if all_static else None
    bound = max(1, sum(demand.values()))
    per_unit = len(labels - {MASTER}) if unit_labels is None else unit_labels
    return Commodity(labels, supply, demand, bound, single_sink, earliest, slack, per_unit)


def add_final_locations(model: ConnectivityModel) -> None:
    """Robots with a required final location end there (the model is infeasible when
    one cannot reach it within the horizon)."""
    T = model.T
    for r, v in sorted(model.p.final_positions.items()):
        c = model.class_of[r]
        if c.earliest.get(v, math.inf) > T:
            model.infeasible_reason = f"robot {r} cannot reach {v} within horizon T={T}"
            continue
        model.eq([model.occ(c, T, v)], 1)


def add_frontier_rewards(model: ConnectivityModel) -> None:
    """y[s, k] = 1 when at least k rewarded robots holding m stand at s at T; the
    objective gains the marginal reward R(s, k) − R(s, k−1) for each."""
    p, net, T = model.p, model.net, model.T
    for s, marg in sorted(p.location_rewards.items()):
        if s not in net:
            continue
        cls = [c for c in model.classes if c.rewarded and not c.static and c.earliest.get(s, math.inf) <= T]
        cls += [c for c in model.classes if c.rewarded and c.static and c.start == s]
        K = min(len(marg), sum(c.n for c in cls))
        if K == 0:
            continue
        count = []
        for c in cls:
            if c.start == s and s in model.gated_set:
                hx = model.var(0, c.n)
                model.le([hx], c.n * model.g_at(s, T))
                model.le([hx], model.occ(c, T, s))
                count.append(hx)
            else:
                count.append(model.occ(c, T, s))
        ys = [model.var(0, 1, pulp.LpBinary) for _ in range(K)]
        for k_, yv in enumerate(ys):
            model.y[s, k_ + 1] = yv
            model.reward_terms.append(float(marg[k_]) * yv)
            if k_:
                model.le([yv], ys[k_ - 1])
        model.le(ys, pulp.lpSum(count))


def add_collisions(model: ConnectivityModel) -> None:
    """Collision robots never share a collision location (robots that start there
    together may stay) nor traverse an edge at one at once."""
    p, net, T, x = model.p, model.net, model.T, model.x
    col: list[RobotClass] = [c for c in model.classes if c.collision]
    if not (col and p.collision_locations):
        return
    for v in sorted(p.collision_locations):
        n0 = sum(c.n for c in col if c.start == v)
        for t in range(1, T + 1):
            terms = [model.occ(c, t, v) for c in col if c.earliest.get(v, math.inf) <= t]
            if not terms:
                continue
            if n0 >= 2:  # robots that start together may stay; nobody else may come
                arrivals = [x[c.idx, t - 1, u, v] for c in col
                            for u in sorted(net.mobility.predecessors(v)) if (c.idx, t - 1, u, v) in x]
                if arrivals:
                    model.le(arrivals, 0)
            else:
                model.le(terms, 1)
    done: set[tuple[str, str]] = set()
    for u, v in sorted(net.mobility.edges):
        if (v, u) in done or not (u in p.collision_locations or v in p.collision_locations):
            continue
        done.add((u, v))
        for t in range(T):
            terms = [x[c.idx, t, a, b] for c in col for a, b in ((u, v), (v, u)) if (c.idx, t, a, b) in x]
            if len(terms) > 1:
                model.le(terms, 1)
