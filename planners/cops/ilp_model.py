"""The model of one connectivity problem over its time-expanded network (steps
t = 0..T): robot classes, the pulp variables and rows, and the occupancy and
m-holding expressions that the constraint families (:mod:`.ilp_constraints`) share.

Every iteration over the network is in name order, so the same problem gives the
same model whatever order its graphs were built in.
"""
from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass
from typing import Any, Callable

import pulp

from .distances import information_distance
from .ilp_problem import ConnectivityProblem

#: Slack of a constant row (a constraint without variables) and of a flow read as used.
EPS = 1e-6


@dataclass
class RobotClass:
    """Robots with the same start location and attributes; their motion is one flow."""

    idx: int
    start: str
    static: bool
    explorer: bool
    rewarded: bool
    collision: bool
    robots: list[str]
    earliest: dict[str, int]  # location -> earliest step the class can be there

    @property
    def n(self) -> int:
        return len(self.robots)


@dataclass
class Commodity:
    """Information that flows from source locations to sink robots as one flow."""

    labels: frozenset[str]
    supply: dict[str, int]          # location -> units at t = 0
    demand: dict[str, int]          # sink robot -> units at T
    bound: int
    single_sink: bool
    earliest: dict[str, int]
    latest_slack: dict[str, int] | None  # location -> min steps still needed to reach a sink
    unit_labels: int = 1                # labels one unit of flow stands for (its message cost)


def value(v: pulp.LpVariable) -> float:
    """The solution's value of variable ``v`` (0 when it has none)."""
    x = v.varValue
    return 0.0 if x is None else float(x)


def expression_value(e: Any) -> float:
    """The solution's value of an expression (or of a constant)."""
    if isinstance(e, (int, float)):
        return float(e)
    return float(pulp.value(e) or 0.0)


class ConnectivityModel:
    """The pulp model of ``p``; keeps the variables needed to read the solution.

    Built empty with the problem's sets and robot classes; the constraint families
    add its variables and rows (:func:`.ilp_constraints.build_model`).
    """

    def __init__(self, p: ConnectivityProblem) -> None:
        self.p = p
        self.net = p.network
        self.T = p.horizon
        self.lp = pulp.LpProblem("cops", pulp.LpMaximize)
        self.nvar = 0
        self.vars: list[pulp.LpVariable] = []
        self.rows: list = []
        self.infeasible_reason: str | None = None
        self.objective = pulp.LpAffineExpression()
        self.cost_terms: list = []
        self.reward_terms: list = []
        self.time_terms: list = []
        net, T = self.net, self.T
        robots = sorted(p.positions)
        pos = dict(p.positions)
        self.robots, self.pos = robots, pos
        masters = set(p.masters) & set(robots)
        self.masters = masters
        self.master_locs = {pos[r] for r in masters}
        self.rewarded = set(p.explorers if p.reward_robots is None else p.reward_robots)
        self.sinks = {s for q in p.requirements for s in q.sinks}
        self.m_dist = information_distance(net, self.master_locs)
        self.gated = sorted({pos[r] for r in robots if r not in masters} - self.master_locs)
        self.gated_set = set(self.gated)
        self.master_sinks = (set(p.master_sinks) | self.sinks) - masters
        # canonical orders (by name): the model, and so the solver's path, do not depend
        # on the order in which the network's graphs were built
        self.succ = {u: sorted(net.mobility.successors(u)) for u in net.mobility}
        self.comm_edges = sorted(net.communication.edges)
        self.classes = self._robot_classes()
        self.class_of = {r: c for c in self.classes for r in c.robots}
        self.home_classes: dict[str, list[RobotClass]] = defaultdict(list)
        for c in self.classes:
            self.home_classes[c.start].append(c)
        self.occupiable: list[set[str]] = []
        for t in range(T + 1):
            self.occupiable.append({v for c in self.classes for v, e in c.earliest.items() if e <= t})
        # filled by the constraint families
        self.x: dict[tuple[int, int, str, str], pulp.LpVariable] = {}
        self.occ_in: dict[tuple[int, int, str], list] = defaultdict(list)
        self.movers: dict[tuple[int, str, str], list] = defaultdict(list)
        self.static_count: dict[str, int] = defaultdict(int)
        self.carry: dict[tuple[int, str, str], list] = {}
        self.w: dict[tuple[str, int], pulp.LpVariable] = {}
        self.m_arcs: dict[tuple[int, str, str], tuple] = {}
        self.commodities: list[Commodity] = []
        self.info_arcs: list[dict[tuple[int, str, str], pulp.LpVariable]] = []
        self.y: dict[tuple[str, int], pulp.LpVariable] = {}
        self._total_occ: dict[tuple[int, str], object] = {}
        self._mholder: dict[tuple[str, int], object] = {}

    def _robot_classes(self) -> list[RobotClass]:
        """Robots grouped by start location and attributes (a robot that is a sink, a
        master sink or has a final location is a class of its own), with the earliest
        step each class can be at each location."""
        p, net, T, pos = self.p, self.net, self.T, self.pos
        groups: dict[tuple, list[str]] = defaultdict(list)
        for r in self.robots:
            single = r if (r in self.sinks or r in self.master_sinks or r in p.final_positions) else None
            key = (pos[r], r in p.static, r in p.explorers, r in self.rewarded, r in p.collision_robots,
                   single)
            groups[key].append(r)
        hop_cache: dict[str, dict[str, int]] = {}
        classes: list[RobotClass] = []
        for key in sorted(groups, key=lambda k: (k[0], k[1], k[2], k[3], k[4], k[5] or "")):
            start, static, expl, rew, col, _ = key
            if static:
                earliest = {start: 0}
            else:
                delay = 0 if start in self.master_locs else self.m_dist.get(start, math.inf)
                if delay > T:
                    earliest = {start: 0}
                else:
                    if start not in hop_cache:
                        hop_cache[start] = net.hop_distances(start)
                    earliest = {v: h + int(delay) for v, h in hop_cache[start].items() if h + delay <= T}
                    earliest[start] = 0
                    earliest = dict(sorted(earliest.items()))
            classes.append(RobotClass(len(classes), start, static, expl, rew, col, sorted(groups[key]),
                                      earliest))
        return classes

    # ---- variables and rows --------------------------------------------------------
    def var(self, lo: float = 0, hi: float | None = None, cat: str = pulp.LpContinuous) -> pulp.LpVariable:
        self.nvar += 1
        if cat == pulp.LpInteger and lo == 0 and hi == 1:
            cat = pulp.LpBinary
        if hasattr(self.lp, "add_variable"):
            v = self.lp.add_variable(f"v{self.nvar}", lo, hi, cat=cat)
        else:  # pragma: no cover - older pulp
            v = pulp.LpVariable(f"v{self.nvar}", lo, hi, cat)
        self.vars.append(v)
        return v

    def timed(self, t: int, var: Any) -> None:
        """A tiny cost on an action at step t (``time_weight``): of equally good plans,
        the one that acts earliest wins, so the plan can be cut short after its last action."""
        if self.p.time_weight:
            self.time_terms.append((self.p.time_weight * (t + 1)) * var)

    def carry_arcs(self, carry: dict, keep: Callable[[int, str, str], bool], U: float,
                   inflow: dict, outflow: dict) -> None:
        """Flow arcs of information carried by moving robots: one per move (t, u, v) that
        ``keep(t, u, v)`` admits, bounded by the robots making it."""
        for (t, u, v), cap in carry.items():
            if keep(t, u, v):
                f = self.var(0, U)
                self.le([f], U * pulp.lpSum(cap))
                outflow[u, t].append(f)
                inflow[v, t + 1].append(f)

    def add(self, constraint: Any) -> None:
        if isinstance(constraint, bool):
            if not constraint:
                self.infeasible_reason = self.infeasible_reason or "constant constraint violated"
            return
        self.rows.append(constraint)

    def le(self, terms: list, rhs: Any) -> None:
        """Σ terms <= rhs with rhs a constant or an expression."""
        expr = pulp.lpSum(terms) - rhs
        if isinstance(expr, (int, float)):
            self.add(expr <= EPS)
        elif not expr.keys():
            self.add(expr.constant <= EPS)
        else:
            self.add(expr <= 0)

    def eq(self, terms: list, rhs: Any) -> None:
        expr = pulp.lpSum(terms) - rhs
        if isinstance(expr, (int, float)):
            self.add(abs(expr) <= EPS)
        elif not expr.keys():
            self.add(abs(expr.constant) <= EPS)
        else:
            self.add(expr == 0)

    # ---- expressions the constraint families share ---------------------------------
    def occ(self, c: RobotClass, t: int, v: str) -> Any:
        """Robots of class c at v at step t."""
        if c.static or t == 0:
            return c.n if v == c.start else 0
        return pulp.lpSum(self.occ_in[c.idx, t, v])

    def total_occ(self, t: int, v: str) -> Any:
        """Robots at v at step t."""
        key = (t, v)
        if key not in self._total_occ:
            self._total_occ[key] = pulp.lpSum([self.occ(c, t, v) for c in self.classes
                                               if c.earliest.get(v, math.inf) <= t])
        return self._total_occ[key]

    def home_occ(self, t: int, v: str) -> Any:
        """Robots at v at step t that started there."""
        return pulp.lpSum([self.occ(c, t, v) for c in self.home_classes.get(v, [])])

    def g_at(self, u: str, t: int) -> Any:
        """1 when m has reached location u by step t (always, where nobody waits for it)."""
        if u not in self.gated_set:
            return 1
        return pulp.lpSum([self.w[u, tau] for tau in range(t + 1) if (u, tau) in self.w])

    def mholder(self, t: int, u: str) -> Any:
        """Robots at u at t that hold m (an upper bound usable in constraints)."""
        if u not in self.gated_set:
            return self.total_occ(t, u)
        key = (u, t)
        if key not in self._mholder:
            n_home = sum(c.n for c in self.home_classes[u])
            hv = self.var(0, n_home)
            self.le([hv], n_home * self.g_at(u, t))
            self.le([hv], self.home_occ(t, u))
            self._mholder[key] = self.total_occ(t, u) - self.home_occ(t, u) + hv
        return self._mholder[key]
