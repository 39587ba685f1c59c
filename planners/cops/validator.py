"""Plan validator: validity of Πc with respect to Πt, and information consistency.

A plan Π = (Πt, Πc) is valid (the paper, "Approach") when

* every trajectory follows mobility edges (or stays);
* a tuple (t, r, r', b) joins robots at the same location or across a
  communication edge;
* robot r holds b at time t: b was r's at t = 0, or r received b at some t' <= t;
* for a fixed b and t the tuples form no cycle (information does not appear out of
  nowhere);

and it is information-consistent (Definition 1) when a robot that does not hold the
master information m neither moves nor sends. The validator also checks the
extensions a plan was made under (static robots, collision constraints) and the
plan's own intermittent-connectivity requirements.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from typing import Iterable

import networkx as nx

from .network import MCNetwork
from .plan import MASTER, Plan

#: Violation kinds.
UNKNOWN_ROBOT = "unknown_robot"
UNKNOWN_LOCATION = "unknown_location"
BAD_TRAJECTORY = "bad_trajectory"
NON_EDGE_MOVE = "non_edge_move"
MOVE_WITHOUT_MASTER = "move_without_master"
SEND_WITHOUT_MASTER = "send_without_master"
SEND_WITHOUT_INFORMATION = "send_without_information"
NO_LINK = "no_link"
COMMUNICATION_CYCLE = "communication_cycle"
BAD_TIME = "bad_time"
SELF_COMMUNICATION = "self_communication"
STATIC_MOVED = "static_moved"
COLLISION = "collision"
UNMET_REQUIREMENT = "unmet_requirement"
DUPLICATE_COMMUNICATION = "duplicate_communication"


@dataclass(frozen=True)
class Violation:
    kind: str
    message: str
    t: int | None = None
    robot: str | None = None

    def __str__(self) -> str:
        return f"{self.kind}: {self.message}"


def validate_plan(network: MCNetwork, plan: Plan, *, static: Iterable[str] | None = None,
                  collision_robots: Iterable[str] | None = None,
                  collision_locations: Iterable[str] | None = None,
                  check_requirements: bool = True) -> list[Violation]:
    """Every way ``plan`` breaks validity or information consistency on ``network``.

    ``static`` defaults to the network's static robots that appear in the plan; the
    collision sets default to the network's. An empty list means the plan is valid.
    """
    out: list[Violation] = []
    T = plan.horizon
    robots = set(plan.trajectories)
    static_set = set(static) if static is not None else {r for r in robots if r in network.robots
                                                          and network.robots[r].static}
    col_r = set(collision_robots) if collision_robots is not None else (network.collision_robots() & robots)
    col_s = set(collision_locations) if collision_locations is not None else set(network.collision_locations)

    # -- trajectories -------------------------------------------------------------------
    traj_ok = True
    for r in sorted(robots):
        traj = plan.trajectories[r]
        if len(traj) != T + 1:
            out.append(Violation(BAD_TRAJECTORY, f"robot {r} has {len(traj)} locations for horizon T={T}", None, r))
            traj_ok = False
            continue
        for t, s in enumerate(traj):
            if s not in network:
                out.append(Violation(UNKNOWN_LOCATION, f"robot {r} at unknown location '{s}' at t={t}", t, r))
                traj_ok = False
        for t, (a, b) in enumerate(zip(traj, traj[1:])):
            if a != b and a in network and b in network and not network.mobility.has_edge(a, b):
                out.append(Violation(NON_EDGE_MOVE, f"robot {r} moves {a}->{b} at t={t} without a mobility edge", t, r))
            if a != b and r in static_set:
                out.append(Violation(STATIC_MOVED, f"static robot {r} moves {a}->{b} at t={t}", t, r))
    for r in sorted(set(plan.masters) - robots):
        out.append(Violation(UNKNOWN_ROBOT, f"master {r} has no trajectory", None, r))
    if not traj_ok:
        return out

    def at(r: str, t: int) -> str:
        return plan.trajectories[r][t]

    # -- communications: well-formedness ---------------------------------------------------
    seen = set()
    by_step: dict[int, list] = {}
    for c in plan.communications:
        if c.sender not in robots or c.receiver not in robots:
            who = c.sender if c.sender not in robots else c.receiver
            out.append(Violation(UNKNOWN_ROBOT, f"communication {c.as_list()} names unknown robot {who}", c.t, who))
            continue
        if not 0 <= c.t <= T:
            out.append(Violation(BAD_TIME, f"communication {c.as_list()} outside 0..{T}", c.t, c.sender))
            continue
        if c.sender == c.receiver:
            out.append(Violation(SELF_COMMUNICATION, f"robot {c.sender} sends {c.info} to itself at t={c.t}", c.t, c.sender))
            continue
        key = (c.t, c.sender, c.receiver, c.info)
        if key in seen:
            out.append(Violation(DUPLICATE_COMMUNICATION, f"communication {c.as_list()} listed twice", c.t, c.sender))
            continue
        seen.add(key)
        a, b = at(c.sender, c.t), at(c.receiver, c.t)
        if not network.can_communicate(a, b):
            out.append(Violation(NO_LINK, f"{c.sender} at {a} sends {c.info} to {c.receiver} at {b} at t={c.t} "
                                          f"without a communication link", c.t, c.sender))
        by_step.setdefault(c.t, []).append(c)

    # -- information flow and consistency ---------------------------------------------------
    holds: dict[str, set[str]] = {r: set(plan.holdings.get(r, [r])) for r in robots}
    for r in plan.masters:
        if r in holds:
            holds[r].add(MASTER)
    for t in range(T + 1):
        step = by_step.get(t, [])
        labels = sorted({c.info for c in step}, key=lambda b: (b != MASTER, b))
        for b in labels:  # m first: sending anything needs m at t
            g = nx.DiGraph()
            for c in step:
                if c.info == b:
                    g.add_edge(c.sender, c.receiver)
            if not nx.is_directed_acyclic_graph(g):
                cyc = nx.find_cycle(g)
                names = " -> ".join([e[0] for e in cyc] + [cyc[0][0]])
                out.append(Violation(COMMUNICATION_CYCLE, f"information {b} goes round a cycle {names} at t={t}", t, cyc[0][0]))
                order = list(g.nodes)
            else:
                order = list(nx.topological_sort(g))
            for r in order:
                for r2 in sorted(g.successors(r)):
                    if b not in holds[r]:
                        out.append(Violation(SEND_WITHOUT_INFORMATION, f"{r} sends {b} to {r2} at t={t} "
                                                                       f"without holding it", t, r))
                    if MASTER not in holds[r] and b != MASTER:
                        out.append(Violation(SEND_WITHOUT_MASTER, f"{r} sends {b} to {r2} at t={t} "
                                                                  f"before receiving the plan m", t, r))
                    holds[r2].add(b)
        if t < T:
            for r in sorted(robots):
                a, b2 = at(r, t), at(r, t + 1)
                if a != b2 and MASTER not in holds[r]:
                    out.append(Violation(MOVE_WITHOUT_MASTER, f"{r} moves {a}->{b2} at t={t} before receiving "
                                                              f"the plan m", t, r))

    # -- collisions ------------------------------------------------------------------------
    col = sorted(col_r & robots)
    for r1, r2 in combinations(col, 2):
        for t in range(T + 1):
            s1, s2 = at(r1, t), at(r2, t)
            if s1 == s2 and s1 in col_s and not (at(r1, 0) == at(r2, 0) == s1 and
                                                  all(at(r1, k) == s1 == at(r2, k) for k in range(t))):
                out.append(Violation(COLLISION, f"{r1} and {r2} both at collision location {s1} at t={t}", t, r1))
            if t < T:
                n1, n2 = at(r1, t + 1), at(r2, t + 1)
                if s1 != n1 and {s1, n1} == {s2, n2} and (s1 in col_s or n1 in col_s):
                    out.append(Violation(COLLISION, f"{r1} and {r2} both traverse {s1}-{n1} at t={t}", t, r1))

    # -- requirements -----------------------------------------------------------------------
    if check_requirements:
        for q in plan.requirements:
            for snk in q.sinks:
                if snk not in holds:
                    out.append(Violation(UNKNOWN_ROBOT, f"sink {snk} has no trajectory", None, snk))
                    continue
                for src in q.sources:
                    if src == snk:
                        continue
                    for b in plan.holdings.get(src, [src]):
                        if b not in holds[snk]:
                            out.append(Violation(UNMET_REQUIREMENT, f"{snk} never receives information {b} "
                                                                    f"of {src}", T, snk))
    return out
