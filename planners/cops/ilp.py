"""The intermittent-connectivity integer program over a time-expanded network.

Given a mobility-communication network N, robots at initial locations s^r_0,
master robots R_m holding the plan m, a horizon T, intermittent-connectivity
constraints (src, snk), frontier rewards R(s, k), and the extensions (static
robots, collision constraints, exploration-capable robots), :func:`solve_connectivity`
finds an information-consistent plan Π = (Πt, Πc) that maximises
Σ R(s, k) − C(Π) with C(Π) the cost of equation (1).

Model (time-expanded network, steps t = 0..T; at step t robots first communicate at
their locations s_t, then move to s_{t+1}):

* Trajectories. Robots with the same start location and attributes form a class;
  x[c, t, u, v] ∈ {0..|c|} counts robots of class c moving u -> v (u = v: staying)
  during step t. Flow conservation per class gives the trajectories; static robots
  have no variables. Mobility cost Σ C̄(u, v) x[c, t, u, v] is the first sum of (1).
* Information flows. Information moves with robots along mobility arcs (capacity
  bounded by the robots that take the arc) and between robots along communication
  arcs of one step (bounded by robots present at both ends, and by a sender that
  holds m). One commodity per connectivity constraint with a single sink (every
  source location supplies one unit per label, the sink absorbs them all: the flow's
  path decomposition routes every source to the sink), one commodity per source
  location otherwise. Conservation at every time-expanded node makes each sink's
  information come from a real source, with no communication cycle. The
  communication cost C̃ is paid per label sent over a communication edge (the
  second sum of (1)).
* Information consistency. m flows from the masters' locations; w[u, t] = 1 when
  it reaches location u, where robots without m wait (the consumers). A class that
  starts at u may leave only after m reached u (Σ_{τ<=t} w[u, τ] >= moves), and a
  location sends over a communication edge only when a robot there holds m: a robot
  away from its start (it moved, so it has m) or a robot at its start after m came.
* Problem 1 rewards: y[s, k] = 1 when at least k exploration-capable robots that
  hold m stand at frontier s at T; the objective gains ΔR(s, k) = R(s, k) − R(s, k−1).
* Extensions: static robots have fixed locations; collision robots never share a
  collision location nor traverse the same edge at once; only capable robots count
  for frontier rewards.

Solving. With HiGHS the model goes to the solver as arrays, with presolve's probing
off (it can take the whole time limit on these models). A warm start (trajectories,
e.g. a greedy plan) is first completed with the motion fixed and then handed over as
the first incumbent, so a solve stopped by its time limit, or because its plan has
stopped improving (``SolverOptions.stall_time_s``), returns at least that plan, with
its optimality gap. Every iteration over the network is in name order, so the same
problem gives the same model whatever order its graphs were built in.

The solver returns location-level flows; :func:`reconstruct_communications` turns them
into robot-level tuples (t, r, r', b) through each location's communication leader
(PreIntCom, ExtCom, PostIntCom) and prunes every tuple nobody needs.
"""
from __future__ import annotations

import math
import time
import warnings
from collections import defaultdict, deque
from dataclasses import dataclass, field
from typing import Iterable, Mapping

import pulp

from .network import MCNetwork
from .plan import MASTER, Communication, Plan, Requirement

_EPS = 1e-6
#: HiGHS presolve_rule_off bit that turns probing off.
_PRESOLVE_NO_PROBING = 1 << 15
#: However long building the model took, the solver gets at least this long (s).
_MIN_SOLVER_TIME_S = 0.2


class PlanningError(Exception):
    """A COPS problem that has no plan; ``str(err)`` is a one-line reason."""


class InfeasibleProblem(PlanningError):
    """No information-consistent plan exists (within the horizon searched)."""


class SolverTimeout(PlanningError):
    """The solver found no plan within its time limit."""


@dataclass(frozen=True)
class SolverOptions:
    """How each integer program is solved.

    ``solver``: ``"highs"``, ``"cbc"`` or None (HiGHS when installed, else CBC).
    ``time_limit_s`` bounds every solve (the best plan found so far is returned, with
    its optimality gap); ``mip_gap`` is the relative gap at which a solve stops;
    ``probe_time_limit_s`` bounds each feasibility probe of the horizon search.
    ``total_time_limit_s`` bounds one call of ``plan_cycle`` (or of
    ``solve_pre_exploration`` / ``solve_post_exploration``): every solve's limit is
    cut to its share of the time left, so the call returns about then with the best
    plans found (model building and a last short solve may overrun it a little);
    None for no bound. ``workers``: independent problems (clusters) solved at once.
    ``stall_time_s``: a solve that holds a plan stops when the plan has not improved
    for this long (nor for half the time it took to find it); None to disable.
    """

    time_limit_s: float | None = 30.0
    mip_gap: float | None = 0.01
    solver: str | None = None
    threads: int = 1
    probe_time_limit_s: float | None = 5.0
    total_time_limit_s: float | None = 10.0
    workers: int = 2
    stall_time_s: float | None = 2.0


def available_solver(name: str | None = None) -> str:
    """The solver that will be used: ``"highs"`` when importable (or asked), else ``"cbc"``."""
    if name not in (None, "highs", "cbc"):
        raise ValueError(f"unknown solver '{name}' (use 'highs' or 'cbc')")
    if name in (None, "highs"):
        try:
            if pulp.HiGHS(msg=False).available():
                return "highs"
        except Exception:  # pragma: no cover - pulp without the highs API
            pass
        if name == "highs":
            try:
                if pulp.HiGHS_CMD(msg=False).available():
                    return "highs_cmd"
            except Exception:  # pragma: no cover
                pass
            raise ValueError("solver 'highs' is not installed (pip install highspy)")
    return "cbc"


def _make_solver(opts: SolverOptions):
    name = available_solver(opts.solver)
    kw = {"msg": False, "timeLimit": opts.time_limit_s, "gapRel": opts.mip_gap, "threads": opts.threads}
    if name == "highs":
        return name, pulp.HiGHS(**kw)
    if name == "highs_cmd":  # pragma: no cover - only without highspy
        return name, pulp.HiGHS_CMD(**kw)
    with warnings.catch_warnings():  # the bundled CBC is the documented fallback
        warnings.simplefilter("ignore", DeprecationWarning)
        return name, pulp.PULP_CBC_CMD(**kw)


@dataclass
class ConnectivityProblem:
    """An intermittent-connectivity problem at a fixed horizon.

    ``holdings`` gives the information labels each robot holds at t = 0 (default:
    its own name). ``location_rewards[s]`` are the marginal rewards
    R(s, 1) − R(s, 0), R(s, 2) − R(s, 1), ... for robots of ``reward_robots``
    (default: ``explorers``) holding m at s at T; robots so rewarded at a location of
    ``frontiers`` are sent exploring. ``master_sinks`` must hold m by T.

    ``warm_start`` gives trajectories (robot -> locations from t = 0, the last one
    held to T) of a plan believed feasible; the solver completes it and starts from
    it, so a solve stopped by its time limit returns at least that plan.
    ``time_weight`` is a tiny cost per action and step index: of equally good plans
    the earliest wins, which lets a search solve once at a generous horizon and cut
    the plan after its last action.
    """

    network: MCNetwork
    horizon: int
    positions: Mapping[str, str]
    masters: set[str]
    static: set[str] = field(default_factory=set)
    explorers: set[str] = field(default_factory=set)
    holdings: dict[str, set[str]] = field(default_factory=dict)
    requirements: list[Requirement] = field(default_factory=list)
    master_sinks: set[str] = field(default_factory=set)
    location_rewards: dict[str, tuple[float, ...]] = field(default_factory=dict)
    reward_robots: set[str] | None = None
    frontiers: set[str] = field(default_factory=set)
    collision_robots: set[str] = field(default_factory=set)
    collision_locations: set[str] = field(default_factory=set)
    final_positions: dict[str, str] = field(default_factory=dict)
    phase: str = "plan"
    options: SolverOptions = field(default_factory=SolverOptions)
    feasibility_only: bool = False
    warm_start: Mapping[str, list[str]] | None = None
    time_weight: float = 0.0

    def holding(self, r: str) -> set[str]:
        return set(self.holdings.get(r, {r}))


# ---------------------------------------------------------------------------------------
# distances used to prune the time-expanded network
# ---------------------------------------------------------------------------------------

def information_distance(net: MCNetwork, sources: Iterable[str], reverse: bool = False,
                         start: Mapping[str, int] | None = None) -> dict[str, int]:
    """Lower bound on the steps information needs from ``sources``: a move costs one
    step, a communication edge none (0-1 BFS). With ``reverse``, distances *to* sources."""
    dist: dict[str, int] = {}
    dq: deque[tuple[int, str]] = deque()
    for s in sources:
        d0 = 0 if start is None else start.get(s, 0)
        if d0 < dist.get(s, math.inf):
            dist[s] = d0
    for s, d in sorted(dist.items(), key=lambda kv: kv[1]):
        dq.append((d, s))
    mob = net.mobility.reverse(copy=False) if reverse else net.mobility
    com = net.communication.reverse(copy=False) if reverse else net.communication
    while dq:
        d, u = dq.popleft()
        if d > dist.get(u, math.inf):
            continue
        for v in com.successors(u):
            if d < dist.get(v, math.inf):
                dist[v] = d
                dq.appendleft((d, v))
        for v in mob.successors(u):
            if d + 1 < dist.get(v, math.inf):
                dist[v] = d + 1
                dq.append((d + 1, v))
    return dist


@dataclass
class _Class:
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
class _Commodity:
    labels: frozenset[str]
    supply: dict[str, int]          # location -> units at t = 0
    demand: dict[str, int]          # sink robot -> units at T
    bound: int
    single_sink: bool
    earliest: dict[str, int]
    latest_slack: dict[str, int] | None  # location -> min steps still needed to reach a sink
    unit_labels: int = 1                # labels one unit of flow stands for (its message cost)


class _Model:
    """Builds the pulp model; keeps the variables needed to read the solution."""

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

    def timed(self, t: int, var) -> None:
        """A tiny cost on an action at step t (``time_weight``): of equally good plans,
        the one that acts earliest wins, so the plan can be cut short after its last action."""
        if self.p.time_weight:
            self.time_terms.append((self.p.time_weight * (t + 1)) * var)

    def carry_arcs(self, carry: dict, keep, U: float, inflow: dict, outflow: dict) -> None:
        """Flow arcs of information carried by moving robots: one per move (t, u, v) that
        ``keep(t, u, v)`` admits, bounded by the robots making it."""
        for (t, u, v), cap in carry.items():
            if keep(t, u, v):
                f = self.var(0, U)
                self.le([f], U * pulp.lpSum(cap))
                outflow[u, t].append(f)
                inflow[v, t + 1].append(f)

    def add(self, constraint) -> None:
        if isinstance(constraint, bool):
            if not constraint:
                self.infeasible_reason = self.infeasible_reason or "constant constraint violated"
            return
        self.rows.append(constraint)

    def le(self, terms: list, rhs) -> None:
        """Σ terms <= rhs with rhs a constant or an expression."""
        expr = pulp.lpSum(terms) - rhs
        if isinstance(expr, (int, float)):
            self.add(expr <= _EPS)
        elif not expr.keys():
            self.add(expr.constant <= _EPS)
        else:
            self.add(expr <= 0)

    def eq(self, terms: list, rhs) -> None:
        expr = pulp.lpSum(terms) - rhs
        if isinstance(expr, (int, float)):
            self.add(abs(expr) <= _EPS)
        elif not expr.keys():
            self.add(abs(expr.constant) <= _EPS)
        else:
            self.add(expr == 0)

    # -------------------------------------------------------------------------------
    def build(self) -> None:
        p, net, T = self.p, self.net, self.T
        robots = sorted(p.positions)
        pos = dict(p.positions)
        self.robots, self.pos = robots, pos
        masters = set(p.masters) & set(robots)
        self.masters = masters
        master_locs = {pos[r] for r in masters}
        rewarded = set(p.explorers if p.reward_robots is None else p.reward_robots)
        sinks = {s for q in p.requirements for s in q.sinks}
        self.m_dist = information_distance(net, master_locs)
        gated = sorted({pos[r] for r in robots if r not in masters} - master_locs)
        self.gated = gated
        gated_set = set(gated)
        master_sinks = (set(p.master_sinks) | sinks) - masters
        self.master_sinks = master_sinks

        # canonical orders (by name): the model, and so the solver's path, do not depend
        # on the order in which the network's graphs were built
        succ = {u: sorted(net.mobility.successors(u)) for u in net.mobility}
        comm_edges = sorted(net.communication.edges)
        self.succ = succ
        # ---- classes ---------------------------------------------------------------
        groups: dict[tuple, list[str]] = defaultdict(list)
        for r in robots:
            single = r if (r in sinks or r in master_sinks or r in p.final_positions) else None
            key = (pos[r], r in p.static, r in p.explorers, r in rewarded, r in p.collision_robots, single)
            groups[key].append(r)
        hop_cache: dict[str, dict[str, int]] = {}
        classes: list[_Class] = []
        for key in sorted(groups, key=lambda k: (k[0], k[1], k[2], k[3], k[4], k[5] or "")):
            start, static, expl, rew, col, _ = key
            if static:
                earliest = {start: 0}
            else:
                delay = 0 if start in master_locs else self.m_dist.get(start, math.inf)
                if delay > T:
                    earliest = {start: 0}
                else:
                    if start not in hop_cache:
                        hop_cache[start] = net.hop_distances(start)
                    earliest = {v: h + int(delay) for v, h in hop_cache[start].items() if h + delay <= T}
                    earliest[start] = 0
                    earliest = dict(sorted(earliest.items()))
            classes.append(_Class(len(classes), start, static, expl, rew, col, sorted(groups[key]), earliest))
        self.classes = classes
        self.class_of = {r: c for c in classes for r in c.robots}

        # ---- robot motion ------------------------------------------------------------
        x: dict[tuple[int, int, str, str], pulp.LpVariable] = {}
        occ_in: dict[tuple[int, int, str], list] = defaultdict(list)   # (c, t, v) -> vars into v at t
        movers: dict[tuple[int, str, str], list] = defaultdict(list)    # (t, u, v) -> vars
        static_count: dict[str, int] = defaultdict(int)
        for c in classes:
            if c.static:
                static_count[c.start] += c.n
                continue
            for t in range(T):
                for u, e in c.earliest.items():
                    if e > t:
                        continue
                    outs = [u] + [v for v in succ[u] if c.earliest.get(v, math.inf) <= t + 1]
                    for v in outs:
                        var = self.var(0, c.n, pulp.LpInteger)
                        x[c.idx, t, u, v] = var
                        occ_in[c.idx, t + 1, v].append(var)
                        movers[t, u, v].append(var)
                        if u != v:
                            cost = net.mobility_cost(u, v)
                            if cost:
                                self.cost_terms.append(cost * var)
                            self.timed(t, var)
                    out_terms = [x[c.idx, t, u, v] for v in outs]
                    if t == 0:
                        self.eq(out_terms, c.n if u == c.start else 0)
                    else:
                        self.eq(out_terms, pulp.lpSum(occ_in[c.idx, t, u]))
        self.x, self.movers, self.static_count = x, movers, static_count
        # robots that can carry information along each mobility arc (u = v: staying)
        carry: dict[tuple[int, str, str], list] = {key: list(mv) for key, mv in movers.items()}
        for u, n in static_count.items():
            for t in range(T):
                carry.setdefault((t, u, u), []).append(n)
        self.carry = carry

        occupiable: list[set[str]] = []
        for t in range(T + 1):
            occupiable.append({v for c in classes for v, e in c.earliest.items() if e <= t})
        self.occupiable = occupiable

        def occ(c: _Class, t: int, v: str):
            if c.static or t == 0:
                return c.n if v == c.start else 0
            return pulp.lpSum(occ_in[c.idx, t, v])

        self.occ = occ
        home_classes: dict[str, list[_Class]] = defaultdict(list)
        for c in classes:
            home_classes[c.start].append(c)

        total_occ_cache: dict[tuple[int, str], object] = {}

        def total_occ(t: int, v: str):
            key = (t, v)
            if key not in total_occ_cache:
                total_occ_cache[key] = pulp.lpSum([occ(c, t, v) for c in classes if c.earliest.get(v, math.inf) <= t])
            return total_occ_cache[key]

        def home_occ(t: int, v: str):
            return pulp.lpSum([occ(c, t, v) for c in home_classes.get(v, [])])

        # ---- master information m ---------------------------------------------------------
        w: dict[tuple[str, int], pulp.LpVariable] = {}
        self.w = w
        h_cache: dict[tuple[str, int], object] = {}

        def g_at(u: str, t: int):
            if u not in gated_set:
                return 1
            return pulp.lpSum([w[u, tau] for tau in range(t + 1) if (u, tau) in w])

        def mholder(t: int, u: str):
            """Robots at u at t that hold m (an upper bound usable in constraints)."""
            if u not in gated_set:
                return total_occ(t, u)
            key = (u, t)
            if key not in h_cache:
                n_home = sum(c.n for c in home_classes[u])
                hv = self.var(0, n_home)
                self.le([hv], n_home * g_at(u, t))
                self.le([hv], home_occ(t, u))
                h_cache[key] = total_occ(t, u) - home_occ(t, u) + hv
            return h_cache[key]

        self.m_arcs: dict[tuple[int, str, str], tuple] = {}
        if gated:
            U = len(gated)
            to_gated = information_distance(net, gated, reverse=True)

            def m_possible(v: str, t: int) -> bool:
                return self.m_dist.get(v, math.inf) <= t and v in occupiable[t]

            def m_useful(v: str, t: int) -> bool:
                return to_gated.get(v, math.inf) <= T - t

            inflow: dict[tuple[str, int], list] = defaultdict(list)
            outflow: dict[tuple[str, int], list] = defaultdict(list)
            carry = self.carry
            for u in gated:
                lo = self.m_dist.get(u, math.inf)
                for t in range(T + 1):
                    if t >= lo and u in occupiable[t]:
                        w[u, t] = self.var(0, 1, pulp.LpBinary)
                        outflow[u, t].append(w[u, t])
                if any((u, t) in w for t in range(T + 1)):
                    self.le([w[u, t] for t in range(T + 1) if (u, t) in w], 1)
            self.carry_arcs(carry, lambda t, u, v: m_possible(u, t) and m_useful(v, t + 1), U, inflow, outflow)
            for t in range(T + 1):
                for u, v in comm_edges:
                    if not (m_possible(u, t) and v in occupiable[t] and m_useful(v, t)):
                        continue
                    f = self.var(0, U)
                    e = self.var(0, 1, pulp.LpBinary)
                    self.le([f], U * e)
                    self.le([e], total_occ(t, v))
                    self.le([e], mholder(t, u))
                    cost = net.communication_cost(u, v)
                    if cost:
                        self.cost_terms.append(cost * e)
                    self.timed(t, e)
                    outflow[u, t].append(f)
                    inflow[v, t].append(f)
                    self.m_arcs[t, u, v] = (f, e)
            for key in sorted(set(inflow) | set(outflow), key=lambda k: (k[1], k[0])):
                v, t = key
                supply = U if (t == 0 and v in master_locs) else 0
                # in + supply >= out + absorbed (m may be dropped, never created)
                self.le(outflow.get(key, []), pulp.lpSum(inflow.get(key, [])) + supply)
            # a class waits at its start until m arrives there
            for c in classes:
                if c.static or c.start not in gated_set:
                    continue
                for t in range(T):
                    leave = [x[c.idx, t, c.start, v] for v in succ[c.start]
                             if (c.idx, t, c.start, v) in x]
                    if leave:
                        self.le(leave, c.n * g_at(c.start, t))
            for r in sorted(master_sinks):
                u = pos[r]
                if u in gated_set:
                    self.eq([w[u, t] for t in range(T + 1) if (u, t) in w], 1)
        self.g_at, self.mholder, self.total_occ = g_at, mholder, total_occ

        # ---- information commodities ------------------------------------------------------
        commodities: list[_Commodity] = []
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
                    commodities.append(self._commodity(labels, supply, {snk: sum(supply.values())}, True,
                                                       master_locs, unit_labels=1))
                continue
            for u in sorted(by_loc):
                need = [s for s in qsinks if any(b != s for b in by_loc[u])]
                if not need:
                    continue
                labels = frozenset().union(*(p.holding(b) for b in by_loc[u]))
                commodities.append(self._commodity(labels, {u: len(need)}, {s: 1 for s in need},
                                                   len(need) == 1, master_locs))
        self.commodities = commodities
        self.info_arcs: list[dict[tuple[int, str, str], pulp.LpVariable]] = []
        carry = self.carry
        for k in commodities:
            U = k.bound

            def possible(v: str, t: int) -> bool:
                if t < k.earliest.get(v, math.inf) or v not in occupiable[t]:
                    return False
                return k.latest_slack is None or k.latest_slack.get(v, math.inf) <= T - t

            inflow = defaultdict(list)
            outflow = defaultdict(list)
            self.carry_arcs(carry, lambda t, u, v: possible(u, t) and possible(v, t + 1), U, inflow, outflow)
            arcs = {}
            for t in range(T + 1):
                for u, v in comm_edges:
                    if not (possible(u, t) and possible(v, t)):
                        continue
                    f = self.var(0, U)
                    self.le([f], U * total_occ(t, v))
                    self.le([f], U * mholder(t, u))
                    cost = net.communication_cost(u, v) * k.unit_labels
                    if k.single_sink:
                        if cost:
                            self.cost_terms.append(cost * f)
                        self.timed(t, f)
                    else:
                        e = self.var(0, 1, pulp.LpBinary)
                        self.le([f], U * e)
                        if cost:
                            self.cost_terms.append(cost * e)
                        self.timed(t, e)
                    outflow[u, t].append(f)
                    inflow[v, t].append(f)
                    arcs[t, u, v] = f
            self.info_arcs.append(arcs)
            nodes = set(inflow) | set(outflow) | {(u, 0) for u in k.supply}
            demand_terms: dict[tuple[str, int], list] = defaultdict(list)
            for s, amount in k.demand.items():
                c = self.class_of[s]
                for v, e in c.earliest.items():
                    if e <= T:
                        demand_terms[v, T].append(amount * occ(c, T, v))
                        nodes.add((v, T))
            for key in sorted(nodes, key=lambda k: (k[1], k[0])):
                v, t = key
                supply = k.supply.get(v, 0) if t == 0 else 0
                self.eq(inflow.get(key, []) + [supply],
                        pulp.lpSum(outflow.get(key, [])) + pulp.lpSum(demand_terms.get(key, [])))

        # ---- required final locations ---
        for r, v in sorted(p.final_positions.items()):
            c = self.class_of[r]
            if c.earliest.get(v, math.inf) > T:
                self.infeasible_reason = f"robot {r} cannot reach {v} within horizon T={T}"
                continue
            self.eq([occ(c, T, v)], 1)

        # ---- frontier rewards ---------------------------------------------------------------
        self.y: dict[tuple[str, int], pulp.LpVariable] = {}
        for s, marg in sorted(p.location_rewards.items()):
            if s not in net:
                continue
            cls = [c for c in classes if c.rewarded and not c.static and c.earliest.get(s, math.inf) <= T]
            cls += [c for c in classes if c.rewarded and c.static and c.start == s]
            K = min(len(marg), sum(c.n for c in cls))
            if K == 0:
                continue
            count = []
            for c in cls:
                if c.start == s and s in gated_set:
                    hx = self.var(0, c.n)
                    self.le([hx], c.n * g_at(s, T))
                    self.le([hx], occ(c, T, s))
                    count.append(hx)
                else:
                    count.append(occ(c, T, s))
            ys = [self.var(0, 1, pulp.LpBinary) for _ in range(K)]
            for k_, yv in enumerate(ys):
                self.y[s, k_ + 1] = yv
                self.reward_terms.append(float(marg[k_]) * yv)
                if k_:
                    self.le([yv], ys[k_ - 1])
            self.le(ys, pulp.lpSum(count))

        # ---- collision constraints --------------------------------------------------------------
        col = [c for c in classes if c.collision]
        if col and p.collision_locations:
            for v in sorted(p.collision_locations):
                n0 = sum(c.n for c in col if c.start == v)
                for t in range(1, T + 1):
                    terms = [occ(c, t, v) for c in col if c.earliest.get(v, math.inf) <= t]
                    if not terms:
                        continue
                    if n0 >= 2:  # robots that start together may stay; nobody else may come
                        arrivals = [x[c.idx, t - 1, u, v] for c in col
                                    for u in sorted(net.mobility.predecessors(v)) if (c.idx, t - 1, u, v) in x]
                        if arrivals:
                            self.le(arrivals, 0)
                    else:
                        self.le(terms, 1)
            done = set()
            for u, v in sorted(net.mobility.edges):
                if (v, u) in done or not (u in p.collision_locations or v in p.collision_locations):
                    continue
                done.add((u, v))
                for t in range(T):
                    terms = [x[c.idx, t, a, b] for c in col for a, b in ((u, v), (v, u)) if (c.idx, t, a, b) in x]
                    if len(terms) > 1:
                        self.le(terms, 1)

        if not p.feasibility_only:
            self.objective = (pulp.lpSum(self.reward_terms) - pulp.lpSum(self.cost_terms)
                              - pulp.lpSum(self.time_terms))

    def _commodity(self, labels, supply, demand, single_sink, master_locs,
                   unit_labels: int | None = None) -> _Commodity:
        start = {u: (0 if u in master_locs else int(min(self.m_dist.get(u, math.inf), self.T + 1)))
                 for u in supply}
        earliest = information_distance(self.net, list(supply), start=start)
        for u in supply:
            earliest[u] = 0
        sink_locs = []
        all_static = True
        for s in demand:
            c = self.class_of[s]
            if c.static:
                sink_locs.append(c.start)
            elif s in self.p.final_positions:  # the sink ends there, so must its information
                sink_locs.append(self.p.final_positions[s])
            else:
                all_static = False
        slack = information_distance(self.net, sink_locs, reverse=True) if all_static else None
        bound = max(1, sum(demand.values()))
        per_unit = len(labels - {MASTER}) if unit_labels is None else unit_labels
        return _Commodity(labels, supply, demand, bound, single_sink, earliest, slack, per_unit)


# ---------------------------------------------------------------------------------------
# solving
# ---------------------------------------------------------------------------------------

def _val(v) -> float:
    x = v.varValue
    return 0.0 if x is None else float(x)


@dataclass
class _Outcome:
    """What one solve of a built model gave: ``status`` is "optimal", "feasible" (an
    incumbent when the time limit passed), "infeasible" or "unknown" (no plan and no
    proof either way, usually the time limit)."""

    status: str
    gap: float | None = None
    timed_out: bool = False


def _warm_values(model: _Model) -> dict[int, float] | None:
    """Column values of the motion variables for ``p.warm_start`` (None when the
    trajectories do not fit the model: a robot missing, a move the model pruned)."""
    ws = model.p.warm_start
    if not ws:
        return None
    T = model.T
    out: dict[int, float] = {}
    counts: dict[tuple[int, int, str, str], int] = defaultdict(int)
    for r in model.robots:
        traj = ws.get(r)
        if not traj or traj[0] != model.pos[r] or len(traj) > T + 1:
            return None
        traj = list(traj) + [traj[-1]] * (T + 1 - len(traj))
        c = model.class_of[r]
        if c.static:
            if any(s != c.start for s in traj):
                return None
            continue
        for t in range(T):
            counts[c.idx, t, traj[t], traj[t + 1]] += 1
    for key, n in counts.items():
        var = model.x.get(key)
        if var is None:
            return None
        out[var._cops_col] = float(n)
    for key, var in model.x.items():
        out.setdefault(var._cops_col, 0.0)
    return out


def _solve_highs(model: _Model, opts: SolverOptions, time_limit: float | None) -> _Outcome:
    """Hand the model to HiGHS as arrays (much faster than pulp's column-by-column
    transfer) and copy the solution back into the pulp variables."""
    import highspy
    import numpy as np

    inf = highspy.kHighsInf
    cols = model.vars
    for i, v in enumerate(cols):
        v._cops_col = i
    n = len(cols)
    lp = highspy.HighsLp()
    lp.num_col_ = n
    lp.num_row_ = len(model.rows)
    cost = np.zeros(n)
    for v, a in model.objective.items():
        cost[v._cops_col] += a
    lp.col_cost_ = cost
    lp.offset_ = float(model.objective.constant or 0.0)
    col_lower = np.array([-inf if v.lowBound is None else float(v.lowBound) for v in cols], dtype=float)
    col_upper = np.array([inf if v.upBound is None else float(v.upBound) for v in cols], dtype=float)
    lp.col_lower_, lp.col_upper_ = col_lower, col_upper
    starts, index, value, lower, upper = [0], [], [], [], []
    for row in model.rows:
        for v, a in row.items():
            if a:
                index.append(v._cops_col)
                value.append(a)
        starts.append(len(index))
        rhs = -float(row.constant or 0.0)
        if row.sense == pulp.LpConstraintEQ:
            lower.append(rhs)
            upper.append(rhs)
        elif row.sense == pulp.LpConstraintLE:
            lower.append(-inf)
            upper.append(rhs)
        else:
            lower.append(rhs)
            upper.append(inf)
    lp.row_lower_ = np.array(lower, dtype=float)
    lp.row_upper_ = np.array(upper, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
    lp.a_matrix_.num_col_ = n
    lp.a_matrix_.num_row_ = len(model.rows)
    lp.a_matrix_.start_ = np.array(starts, dtype=np.int32)
    lp.a_matrix_.index_ = np.array(index, dtype=np.int32)
    lp.a_matrix_.value_ = np.array(value, dtype=float)
    kint, kcont = highspy.HighsVarType.kInteger, highspy.HighsVarType.kContinuous
    lp.integrality_ = [kint if v.cat == pulp.LpInteger else kcont for v in cols]
    lp.sense_ = highspy.ObjSense.kMaximize
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", int(opts.threads or 1))
    h.setOptionValue("random_seed", 0)
    if opts.mip_gap is not None:
        h.setOptionValue("mip_rel_gap", float(opts.mip_gap))
    # presolve's probing can take the whole time limit on these models (HiGHS's own advice)
    h.setOptionValue("presolve_rule_off", _PRESOLVE_NO_PROBING)
    h.passModel(lp)
    M = highspy.HighsModelStatus
    t_start = time.perf_counter()

    def remaining() -> float | None:
        return None if time_limit is None else max(time_limit - (time.perf_counter() - t_start), 0.01)

    warm = _warm_values(model)
    start = None
    if warm:
        # complete the given trajectories first (motion fixed: an easy problem), then hand
        # the whole solution to the real solve as its first incumbent
        idx = np.fromiter(warm.keys(), dtype=np.int32, count=len(warm))
        val = np.fromiter(warm.values(), dtype=float, count=len(warm))
        h.changeColsBounds(len(warm), idx, val, val)
        lim = remaining()
        h.setOptionValue("time_limit", 1e30 if lim is None else float(max(0.5 * lim, 0.01)))
        h.run()
        if h.getInfo().primal_solution_status == 2:
            start = list(h.getSolution().col_value)
        h.changeColsBounds(len(warm), idx, col_lower[idx], col_upper[idx])
    lim = remaining()
    h.setOptionValue("time_limit", 1e30 if lim is None else float(lim))
    if start is not None:
        sol = highspy.HighsSolution()
        sol.col_value = start
        sol.value_valid = True
        h.setSolution(sol)
    stall = opts.stall_time_s if not model.p.feasibility_only else None
    if stall:
        last = [time.perf_counter() if start is not None else None]

        def improved(_event) -> None:
            last[0] = time.perf_counter()

        def check(event) -> None:
            t = last[0]
            if t is not None and time.perf_counter() - t > max(stall, 0.5 * (t - t_start)):
                event.interrupt()

        h.cbMipImprovingSolution.subscribe(improved)
        h.cbMipInterrupt.subscribe(check)
        h.cbSimplexInterrupt.subscribe(check)
    h.run()
    status = h.getModelStatus()
    info = h.getInfo()
    if status in (M.kInfeasible, M.kUnboundedOrInfeasible):
        return _Outcome("infeasible")
    values = None
    gap = float(info.mip_gap) if math.isfinite(info.mip_gap) else None
    if info.primal_solution_status == 2:
        values = h.getSolution().col_value
    elif start is not None:  # nothing better than the completed warm start in time
        values, gap, status = start, None, M.kTimeLimit
    if values is None:
        return _Outcome("unknown", timed_out=status == M.kTimeLimit)
    for v, x in zip(cols, values):
        v.varValue = x
    if status == M.kOptimal:
        return _Outcome("optimal", 0.0 if gap is None else gap)
    return _Outcome("feasible", gap, timed_out=status == M.kTimeLimit)


def _solve_pulp(model: _Model, opts: SolverOptions, time_limit: float | None) -> _Outcome:
    o = SolverOptions(time_limit_s=time_limit, mip_gap=opts.mip_gap, solver=opts.solver, threads=opts.threads)
    _name, solver = _make_solver(o)
    for row in model.rows:
        model.lp += row
    model.lp += model.objective
    t0 = time.perf_counter()
    model.lp.solve(solver)
    status, sol_status = model.lp.status, model.lp.sol_status
    if sol_status == pulp.LpSolutionInfeasible or status == pulp.LpStatusInfeasible:
        return _Outcome("infeasible")
    if sol_status == pulp.LpSolutionOptimal:
        return _Outcome("optimal", 0.0)
    timed_out = time_limit is not None and time.perf_counter() - t0 >= 0.9 * time_limit
    if sol_status == pulp.LpSolutionIntegerFeasible:
        return _Outcome("feasible", None, timed_out)
    return _Outcome("unknown", timed_out=timed_out)


def solve_connectivity(p: ConnectivityProblem, *, time_limit_s: float | None = None) -> Plan | None:
    """Solve ``p`` at its horizon: the plan, or None when infeasible at this horizon.

    ``time_limit_s`` overrides ``p.options.time_limit_s`` for this call (building the
    model included; the solver gets at least a fraction of a second). When the
    limit passes with a plan in hand, that plan is returned (``meta["status"]`` is
    "feasible" and ``meta["gap"]`` its optimality gap, None when unknown). Raises
    :class:`SolverTimeout` when the limit passes before any plan is found.
    """
    t0 = time.perf_counter()
    for r, s in p.positions.items():
        if s not in p.network:
            raise ValueError(f"robot '{r}' at unknown location '{s}'")
    model = _Model(p)
    model.build()
    if model.infeasible_reason:
        return None
    limit = p.options.time_limit_s if time_limit_s is None else time_limit_s
    if limit is not None:  # the limit bounds the whole call, model building included
        limit = max(limit - (time.perf_counter() - t0), min(limit, _MIN_SOLVER_TIME_S))
    solver_name = available_solver(p.options.solver)
    if not model.vars:
        out = _Outcome("optimal", 0.0)
    elif solver_name == "highs":
        out = _solve_highs(model, p.options, limit)
    else:
        out = _solve_pulp(model, p.options, limit)
    if out.status == "infeasible":
        return None
    if out.status == "unknown":
        if out.timed_out:
            raise SolverTimeout(f"no plan found within the time limit of {limit:g} s (horizon T={p.horizon})")
        return None
    plan = _extract(model)
    reward = sum(_val(v) * c for v, c in _terms(model.reward_terms))
    cost = sum(_val(v) * c for v, c in _terms(model.cost_terms))
    plan.meta.update({
        "status": out.status,
        "gap": None if out.gap is None else round(out.gap, 6),
        "objective": round(reward - cost, 6),
        "reward": round(reward, 6),
        "cost": round(plan_cost(p.network, plan), 6),
        "ilp_cost": round(cost, 6),
        "solver": solver_name,
        "solve_time_s": round(time.perf_counter() - t0, 4),
        "variables": len(model.vars),
        "constraints": len(model.rows),
    })
    return plan


def _terms(terms: list) -> list[tuple[pulp.LpVariable, float]]:
    out = []
    for t in terms:
        for v, c in t.items():
            out.append((v, c))
    return out


def plan_cost(net: MCNetwork, plan: Plan) -> float:
    """C(Π) of equation (1): mobility costs plus communication costs of every tuple."""
    cost = 0.0
    for traj in plan.trajectories.values():
        for a, b in zip(traj, traj[1:]):
            if a != b:
                cost += net.mobility_cost(a, b)
    for c in plan.communications:
        cost += net.communication_cost(plan.location(c.sender, c.t), plan.location(c.receiver, c.t))
    return cost


def _extract(model: _Model) -> Plan:
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
                    k = int(round(_val(var))) if var is not None else 0
                    for r in rs[i:i + k]:
                        where[r] = v
                    i += k
                # numerical slack: anyone left over stays
            for r in c.robots:
                traj[r].append(where[r])
    m_arcs: dict[int, list[tuple[str, str]]] = defaultdict(list)
    for (t, u, v), (f, _e) in model.m_arcs.items():
        if _val(f) > _EPS:
            m_arcs[t].append((u, v))
    info_arcs: dict[int, list[tuple[str, str, frozenset[str]]]] = defaultdict(list)
    for k, arcs in zip(model.commodities, model.info_arcs):
        for (t, u, v), f in arcs.items():
            if _val(f) > _EPS:
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
    explorers = _explorers(model, traj)
    for r in explorers:
        needs[r].add(MASTER)
    comms = reconstruct_communications(net, traj, T, model.masters, holdings, m_arcs, info_arcs, needs)
    return Plan(horizon=T, trajectories={r: traj[r] for r in sorted(traj)}, communications=comms,
                masters=sorted(model.masters),
                holdings={r: sorted(holdings[r]) for r in sorted(holdings) if holdings[r] != {r}},
                requirements=list(p.requirements), explore=explorers, phase=p.phase)


def _explorers(model: _Model, traj: Mapping[str, list[str]]) -> dict[str, str]:
    """Rewarded robots that end at a frontier and hold m there: they explore it."""
    p, T = model.p, model.T
    out = {}
    for s in sorted(p.frontiers):
        k_max = sum(1 for (ss, _k), yv in model.y.items() if ss == s and _val(yv) > 0.5)
        if k_max == 0:
            continue
        cands = []
        for r in model.robots:
            c = model.class_of[r]
            if not c.rewarded or traj[r][T] != s:
                continue
            moved = any(a != b for a, b in zip(traj[r], traj[r][1:]))
            has_m = (r in model.masters or moved or c.start not in model.gated
                     or _val_expr(model.g_at(c.start, T)) > 0.5)
            if has_m:
                cands.append(r)
        for r in sorted(cands)[:k_max]:
            out[r] = s
    return out


def _val_expr(e) -> float:
    if isinstance(e, (int, float)):
        return float(e)
    return float(pulp.value(e) or 0.0)


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
