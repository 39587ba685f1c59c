"""The COPS mission executive (Figure 4 of the COPS paper) as behaviours.

Every agent (robots and the base station) keeps one :class:`CopsState` on its
blackboard (key ``cops``): what it knows (the topology it gathered or received,
the freshness of each robot's information, robots declared lost), the cycle plan it
executes (the information m), which part of the cycle it is in (``pre``,
``explore``, ``post``, ``done``) and the plan step t.

Behaviours, in the paper's words:

* ``InformationStorage``: background; receives, acknowledges and stores every
  message, merges what the robot's own sensing reveals.
* ``Leader?`` (``IsLeader``), ``COPS`` (``SolveCOPS``), ``WaitToReceivePlan``.
* ``Explore?`` (``IsExploring``), ``ExplorationAction`` (Algorithm 1),
  ``ExplorationTimer``, ``TransitToReturnNode``.
* ``CommunicationAction`` (PreIntCom, ExtCom, PostIntCom; re-sent until
  acknowledged), ``TransitionAction`` and ``ActionTimer``.
* ``FinishedPlan?`` (``FinishedPlan``) and ``MissionComplete``.

Messages (radio kind ``cops``) are ``{"type": "info" | "ack" | "hello", ...}``. An
info message carries one plan communication (t, r, r', b) of one part of one
cycle; its payload is the sender's whole knowledge (topology, information
freshness, lost robots) and, for b = m, the cycle plan.
"""
from __future__ import annotations

import math
from abc import abstractmethod
from dataclasses import dataclass, field
from typing import Any

from py_trees.common import Status

from ..planners.cops import (MASTER, Communication, CyclePlan, PlanningError, SolverOptions, plan_cycle,
                             solve_post_exploration, validate_plan)
from ..planners.cops.plan import Plan, idle_plan
from ..planners.cops.recall import solve_recall
from ..planners.cops.topology import Topology, team_network
from .base import AgentContext, Param, Skill
from .robot import NetworkView, PathStatus

KIND = "cops"
PARTS = ("pre", "explore", "post", "done")
STATE_KEY = Param(str, "cops", "blackboard key of the agent's COPS state", key=True)


@dataclass
class Knowledge:
    """What an agent holds (the paper's information storage).

    ``freshness[r]``: newest cycle whose information of robot r this agent holds.
    ``received`` / ``acked``: ids of info messages received / acknowledged to us.
    ``heard[r]``: newest sim time r was heard from (by anyone whose knowledge we have);
    ``declared[r]``: newest time r was declared lost. r counts as lost while it was
    declared lost after it was last heard from.
    ``map_chunks``: on voxel worlds, the pieces of robots' onboard maps this agent
    holds ("r1/4" -> (flat indices, values)), carried like the rest of the
    information until they reach the base station's map.
    ``finished[r]``: the final plan's cycle, for a robot that got it at the base with
    its part done (its communications in that plan count as done)."""

    topology: Topology = field(default_factory=Topology)
    freshness: dict[str, int] = field(default_factory=dict)
    declared: dict[str, float] = field(default_factory=dict)
    received: set[str] = field(default_factory=set)
    acked: set[str] = field(default_factory=set)
    heard: dict[str, float] = field(default_factory=dict)
    pending_plan: dict[str, Any] | None = None
    map_chunks: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    finished: dict[str, int] = field(default_factory=dict)

    @property
    def lost(self) -> set[str]:
        return {r for r, t in self.declared.items() if t > self.heard.get(r, -math.inf)}

    def payload(self) -> dict[str, Any]:
        return {"topology": self.topology.to_dict(), "freshness": dict(self.freshness),
                "declared": dict(self.declared), "heard": dict(self.heard), "map": dict(self.map_chunks),
                "finished": dict(self.finished)}

    def collect_map(self, robot: str, onboard_map: Any) -> None:
        """Add what ``robot``'s onboard map gained since the last call as a chunk."""
        flat, values = onboard_map.take_changes()
        if len(flat):
            self.map_chunks[f"{robot}/{len(self.map_chunks)}"] = (flat, values)  # unique: the dict only grows

    def absorb(self, payload: dict[str, Any]) -> None:
        for key, chunk in payload.get("map", {}).items():
            self.map_chunks.setdefault(key, chunk)
        self.topology.merge(Topology.from_dict(payload["topology"]))
        for mine, theirs in ((self.freshness, payload["freshness"]), (self.declared, payload["declared"]),
                             (self.heard, payload["heard"]), (self.finished, payload.get("finished", {}))):
            for r, v in theirs.items():
                mine[r] = max(mine.get(r, -math.inf), v)


@dataclass
class CopsState:
    """An agent's COPS state (blackboard key ``cops``)."""

    knowledge: Knowledge = field(default_factory=Knowledge)
    cycle: int = -1
    plan: CyclePlan | None = None
    part: str = "done"
    step: int = 0
    final: bool = False
    delta_t_s: float = 60.0
    lost_timeout_s: float = 1200.0
    recall_after_s: float = 1800.0
    base_location: str | None = None
    explored_in: dict[str, int] = field(default_factory=dict)
    planned_s: float = 0.0

    def part_plan(self) -> Plan | None:
        if self.plan is None:
            return None
        return {"pre": self.plan.pre, "post": self.plan.post}.get(self.part)

    def plan_message(self) -> dict[str, Any]:
        """The cycle plan m as a message carries it."""
        return {"cycle": self.plan.to_dict(), "final": self.final, "delta_t_s": self.delta_t_s,
                "lost_timeout_s": self.lost_timeout_s, "recall_after_s": self.recall_after_s,
                "base_location": self.base_location}

    def adopt(self, msg: dict[str, Any]) -> None:
        """Take the cycle plan m of ``msg`` and continue from the step it arrived at."""
        m = msg["plan"]
        self.plan = CyclePlan.from_dict(m["cycle"])
        self.cycle, self.final = int(msg["cycle"]), bool(m["final"])
        self.delta_t_s, self.lost_timeout_s = float(m["delta_t_s"]), float(m["lost_timeout_s"])
        self.recall_after_s = float(m["recall_after_s"])
        self.base_location = m["base_location"]
        self.part, self.step = msg["part"], int(msg["t"])


def message_id(cycle: int, part: str, c: Communication) -> str:
    return f"{cycle}:{part}:{c.t}:{c.sender}>{c.receiver}:{c.info}"


def final_plan_id(cycle: int, robot: str) -> str:
    """Id of the final plan the leader hands to ``robot`` at the base."""
    return f"{cycle}:final:{robot}"


def network_view(ctx: AgentContext) -> NetworkView | None:
    """The robot's NetworkView (service ``network_view``, which the world backend
    makes for each robot of a COPS team); None at the base station."""
    return ctx.services.get("network_view")


class CopsSkill(Skill):
    """Base of the COPS behaviours: the agent's state and radio."""

    ABSTRACT = True
    PARAMS = {"state": STATE_KEY}
    #: The location :meth:`drive_to` last sent the robot to, and the last one where
    #: it found the robot as near the position as it can get.
    _driving: str | None = None
    _settled: str | None = None

    def reset_drive(self) -> None:
        """Forget earlier drives (when the behaviour starts afresh)."""
        self._driving = self._settled = None

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self._state_key = self.key(self.p["state"])

    def stored_state(self) -> CopsState | None:
        """The agent's COPS state; None until a behaviour has made it."""
        return self.get(self._state_key)

    @property
    def state(self) -> CopsState:
        st = self.get(self._state_key)
        if st is None:
            st = CopsState()
            self.bb.set(self._state_key, st)
        return st

    @property
    def radio(self) -> Any:
        return self.ctx.robot.radio if self.ctx.robot is not None else self.ctx.services["radio"]

    def greet_home(self, st: "CopsState") -> None:
        """Greet the leader from the base, with everything the agent holds (what it
        mapped on its way home included)."""
        collect_own_map(self.ctx, st.knowledge)
        self.radio.send(self.p["leader"], KIND, {"type": "hello", "home": True, "payload": st.knowledge.payload()})

    def drive_to(self, there: str, arrive: bool = False) -> Status | None:
        """Drive towards location ``there`` through the NetworkView: None once there
        (in its region; with ``arrive``, at the end of its route to the position, or as
        near the position as the robot can get inside the region), RUNNING on the way,
        FAILURE when it cannot get there (no route, or blocked). A route that ends short of ``there`` (a voxel map's
        graph reaches further as the robot walks) is asked for again where it ends."""
        view, robot = network_view(self.ctx), self.robot
        inside = view.location() == there
        on_own_route = self._driving == there and getattr(self, "_command_id", None) == robot.command_id
        if inside and (not arrive or not (on_own_route and robot.path_status == PathStatus.FOLLOWING)
                       and (self._settled == there or view.arrived(there))):
            self._driving = None
            return None
        if not on_own_route or robot.path_status in (PathStatus.ARRIVED, PathStatus.IDLE):
            route = view.route(there)
            if route is None and inside:  # as near as it gets
                self._driving, self._settled = None, there
                return None
            if route is None:
                self.feedback_message = f"no route to {there}"
                return Status.FAILURE
            self.follow(route)
            self._driving = there
        if robot.path_status == PathStatus.BLOCKED:
            self.feedback_message = f"blocked on the way to {there}"
            return Status.FAILURE
        return Status.RUNNING


class InformationStorage(CopsSkill):
    """Background task: listen, acknowledge, store.

    Every tick it receives all ``cops`` messages: it acknowledges each info message
    (duplicates too), merges its payload into the agent's knowledge and, for a newer
    plan m, keeps it for ``WaitToReceivePlan``; it records acknowledgements and when
    each sender was last heard. Once it has made the final plan, it answers a robot
    greeting it from the base with that plan. When the robot reaches a new location,
    or its NetworkView's ``revision`` changes (a voxel map extracted again), it
    merges what its own sensing revealed and marks its own information fresh, and
    takes what its onboard map gained into its knowledge. The base station merges the
    map chunks that reach it into its map (service ``map``).

    Reads/writes: ``cops`` (knowledge). Returns RUNNING.
    """

    PARAMS = dict(CopsSkill.PARAMS)

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self._at: Any = ()
        self._merged: set[str] = set()

    def initialise(self) -> None:
        initial = self.ctx.services.get("initial_topology")
        if initial is not None:
            self.state.knowledge.topology.merge(Topology.from_dict(initial))

    def update(self) -> Status:
        st, now = self.state, self.ctx.clock.now_s
        kn = st.knowledge
        kn.heard[self.ctx.name] = now
        for msg in self.radio.receive():
            if msg.kind != KIND:
                continue
            d = msg.data
            kn.heard[msg.sender] = now
            if d["type"] == "hello" and "payload" in d:
                kn.absorb(d["payload"])
            if d["type"] == "hello" and d.get("home") and st.final:
                self._hand_final_plan(msg.sender, st)
            elif d["type"] == "ack":
                kn.acked.add(d["id"])
            elif d["type"] == "info":
                self.radio.send(msg.sender, KIND, {"type": "ack", "id": d["id"]})
                if d["id"] in kn.received:
                    continue
                kn.received.add(d["id"])
                kn.absorb(d["payload"])
                if d["info"] == MASTER and d["cycle"] > st.cycle and (
                        kn.pending_plan is None or d["cycle"] > kn.pending_plan["cycle"]):
                    kn.pending_plan = d
        self._sense(st)
        self._merge_maps(kn)
        return Status.RUNNING

    def _hand_final_plan(self, robot: str, st: CopsState) -> None:
        """A robot greeting the leader from the base gets the final plan m there. When
        the plan has it at the base at the leader's step, it joins in there (it may
        still have to carry m out, or hand over what it holds); else (the plan
        believed it elsewhere) its part is done, the mission is over for it, and the
        team counts their communications with it as done (``finished``)."""
        plan = st.part_plan()
        joins = plan is not None and robot in plan.robots and plan.location(robot, st.step) == st.base_location
        part, step = (st.part, st.step) if joins else ("done", 0)
        if not joins:
            st.knowledge.finished[robot] = st.cycle
        payload = {**st.knowledge.payload(), "plan": st.plan_message()}
        self.radio.send(robot, KIND, {"type": "info", "id": final_plan_id(st.cycle, robot), "cycle": st.cycle,
                                      "part": part, "t": step, "info": MASTER, "payload": payload})

    def _sense(self, st: CopsState) -> None:
        view = network_view(self.ctx)
        if view is None:
            return
        at = (view.location(), getattr(view, "revision", None))
        if at == self._at:
            return
        self._at = at
        if st.knowledge.topology.merge(Topology.from_dict(view.topology())):
            st.knowledge.freshness[self.ctx.name] = max(st.cycle, 0)
        collect_own_map(self.ctx, st.knowledge)

    def _merge_maps(self, kn: Knowledge) -> None:
        """Base station: merge the map chunks that arrived into its map (service ``map``)."""
        base_map = self.ctx.services.get("map")
        if base_map is None:
            return
        for key in sorted(kn.map_chunks.keys() - self._merged):
            base_map.merge(*kn.map_chunks[key])
            self._merged.add(key)


def collect_own_map(ctx: AgentContext, kn: Knowledge) -> None:
    """Put what the agent's robot mapped since the last call into its knowledge (robots
    with an onboard voxel map only)."""
    onboard = getattr(ctx.robot, "onboard_map", None)
    if onboard is not None:
        kn.collect_map(ctx.name, onboard)


class IsLeader(Skill):
    """Leader?: SUCCESS when this agent plans for the team (``leader``), else FAILURE."""

    TYPE_NAME = "Leader?"
    PARAMS = {"leader": Param(str, "base", "name of the agent responsible for planning")}

    def update(self) -> Status:
        return Status.SUCCESS if self.ctx.name == self.p["leader"] else Status.FAILURE


class SolveCOPS(CopsSkill):
    """COPS: plan the next cycle at the leader (the base station).

    From everything the leader knows it builds the network N (explored locations),
    places the team (robots not declared lost, where the last plan left them) and
    plans pre-exploration, exploration and post-exploration (``plan_cycle``). Robots
    whose earlier information never reached the base are added to the
    post-exploration sources. With no frontier left, the plan is the recall: m
    reaches every robot and brings it to the base, where those sources hand over
    what the base lacks. Robots coming back by the standing order of m are planned
    static at the base; so are, in a recall, robots that order will have sent home
    before the recall's m reaches them (logged ``cops_replan_returning``). Every
    plan is checked with the plan validator before it is used.

    Reads services ``team`` (robot -> start location) and ``base_location``.
    Writes ``cops`` (plan, cycle, part = pre, step = 0). Logs ``cops_plan``.
    Returns SUCCESS with a plan, FAILURE when no plan exists (logged with the reason).
    """

    TYPE_NAME = "COPS"
    PARAMS = {
        **CopsSkill.PARAMS,
        "delta_t_s": Param(float, 60.0, "ΔT: duration of one plan step (one transition)", exclusive_minimum=0),
        "min_exploration_steps": Param(int, 4, "exploration time of a cycle, in steps of ΔT", minimum=1),
        "lost_timeout_s": Param(float, 1200.0, "silence after which a partner is declared lost",
                                exclusive_minimum=0),
        "time_limit_s": Param(float, 10.0, "time limit of each integer program (wall clock)",
                              exclusive_minimum=0),
        "spacing_m": Param(float, 50.0, "location spacing: a move's cost is its length over this",
                           exclusive_minimum=0),
        "recall_after_s": Param(float, 1800.0, "standing order of m: a robot that receives no new plan "
                                "this long after its part goes back to the base", exclusive_minimum=0),
    }

    def update(self) -> Status:
        st = self.state
        base_loc = st.base_location = self.ctx.services["base_location"]
        team = self.ctx.services["team"]
        kn = st.knowledge
        positions, returning = self._positions(st, team)
        try:
            net, cyc = self._plan(st, positions, returning)
            gone = set() if net.frontiers or cyc.meta["owed"] else self._gone_before_m(st, cyc)
            if gone:  # plan them at the base, where the standing order of m brings them
                self.event("cops_replan_returning", cycle=st.cycle + 1, robots=sorted(gone))
                returning = sorted(set(returning) | gone)
                net, cyc = self._plan(st, {r: base_loc if r in gone else s for r, s in positions.items()}, returning)
            positions, frontiers, owed = net.positions(), net.frontiers, cyc.meta["owed"]
            if frontiers and not cyc.exploration and not owed:
                raise PlanningError(f"{len(frontiers)} frontiers left but no robot that m can reach is "
                                    f"sent to one (robots out of radio reach of the base and of each other)")
            cyc.meta["explored"] = sorted(kn.topology.explored)
            cyc.meta["returning"] = returning
        except (PlanningError, ValueError) as err:
            self.event("cops_no_plan", cycle=st.cycle + 1, reason=str(err))
            self.feedback_message = str(err)
            return Status.FAILURE
        problems = validate_plan(net, cyc.pre) + validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post)
        if problems:
            self.event("cops_invalid_plan", cycle=st.cycle + 1, reason=str(problems[0]))
            return Status.FAILURE
        final = not frontiers and not owed and not cyc.meta.get("stranded")
        st.cycle += 1
        for r in cyc.exploration:
            st.explored_in[r] = st.cycle
        st.plan, st.final, st.part, st.step = cyc, final, "pre", 0
        st.delta_t_s, st.lost_timeout_s = self.p["delta_t_s"], self.p["lost_timeout_s"]
        st.recall_after_s, st.planned_s = self.p["recall_after_s"], self.ctx.clock.now_s
        st.knowledge.freshness[MASTER] = st.cycle
        self.event("cops_plan", cycle=st.cycle, final=final, robots=len(positions) - 1,
                   team=sorted(r for r in positions if r != self.ctx.name), locations=len(net),
                   frontiers=len(frontiers), explorers=sorted(cyc.exploration), T_pre=cyc.pre.horizon,
                   T_post=cyc.post.horizon, ext_com=_count(cyc, external=True), int_com=_count(cyc, external=False),
                   transitions=sum(p.moves(r) for p in (cyc.pre, cyc.post) for r in p.robots),
                   relayed=sum(1 for p in (cyc.pre, cyc.post) for c in p.communications
                               if c.info not in (c.sender, MASTER)),
                   solve_time_s=cyc.meta.get("solve_time_s"), gap=cyc.meta.get("gap"),
                   clustered=bool(cyc.meta.get("clustered")), valid=True)
        return Status.SUCCESS

    def _positions(self, st: CopsState, team: dict[str, str]) -> tuple[dict[str, str], list[str]]:
        """Where the last plan left each robot not declared lost, and the robots that
        go back to the base by the standing order of m (the last plan did not reach
        them, or no new plan can)."""
        alive = {r: s for r, s in team.items() if r not in st.knowledge.lost}
        if st.plan is None:
            return alive, []
        last = st.plan.post.final_positions()
        reached = st.plan.pre.master_receivers() | st.plan.post.master_receivers()
        pos = {r: last.get(r, s) if r in reached else st.base_location for r, s in alive.items()}
        unreachable = _unreachable(st.knowledge.topology, st.base_location, pos)
        return {r: st.base_location if r in unreachable else s for r, s in pos.items()}, sorted(unreachable)

    def _plan(self, st: CopsState, positions: dict[str, str], returning: list[str]) -> tuple[Any, CyclePlan]:
        """The network N of what the base knows with the team at ``positions``, and the
        next cycle on it: a cycle with frontiers left, else the recall. Robots
        ``returning`` by the standing order reach the base at a time nobody knows:
        they are planned static there (they get m when they arrive), unless no other
        robot is left to explore."""
        kn = st.knowledge
        net = team_network(kn.topology, st.base_location, self.ctx.name, positions, spacing_m=self.p["spacing_m"])
        positions = net.positions()
        opts = SolverOptions(time_limit_s=self.p["time_limit_s"])
        owed = {r for r in positions if st.explored_in.get(r, -1) > kn.freshness.get(r, -1)}
        plan = self._cycle if net.frontiers else self._recall
        static = {self.ctx.name, *returning}
        if net.frontiers and not set(positions) - static:
            static = {self.ctx.name}
        cyc = plan(net, positions, owed, static, opts)
        cyc.meta["owed"] = sorted(owed)
        return net, cyc

    def _gone_before_m(self, st: CopsState, cyc: CyclePlan) -> set[str]:
        """Robots away from the base whose standing order of m will have sent them home
        before the recall's m reaches them (asked only of a recall that may be the
        last plan: a robot taken for gone too early comes home by that order anyway,
        and the last plan hands it m there): the last plan's part ended
        ``recall_after_s`` earlier (at the earliest: every step ΔT long), m reaches
        them at step t of the new plan (at the earliest: t ΔT from now)."""
        last = st.plan
        if last is None:
            return set()
        now, base = self.ctx.clock.now_s, st.base_location
        reaches: dict[str, int] = {r: 0 for r in cyc.pre.masters}
        for c in sorted(cyc.pre.communications):
            if c.info == MASTER:
                reaches.setdefault(c.receiver, c.t)
        gone = set()
        for r, t in reaches.items():
            if r == self.ctx.name or cyc.pre.location(r, 0) == base or r not in last.pre.robots:
                continue
            task = last.exploration.get(r)
            steps = last.pre.horizon + last.post.horizon + (task.steps if task else 0)
            standing_order_s = st.planned_s + steps * st.delta_t_s + st.recall_after_s
            if now + t * self.p["delta_t_s"] >= standing_order_s:
                gone.add(r)
        return gone

    def _cycle(self, net, positions: dict[str, str], owed: set[str], static: set[str],
               opts: SolverOptions) -> CyclePlan:
        """Pre-exploration, exploration and post-exploration; robots whose earlier
        information the base lacks (``owed``) are post-exploration sources too."""
        me = self.ctx.name
        kw = dict(masters={me}, explorers=set(positions) - static, static=static,
                  min_exploration_steps=self.p["min_exploration_steps"], options=opts)
        try:
            cyc = plan_cycle(net, **kw)
        except PlanningError as err:  # too hard within the time limit: the nearest frontier only
            hops = net.hop_distances(net.base)
            nearest = min(net.frontiers, key=lambda s: (hops.get(s, math.inf), s))
            self.event("cops_fallback", reason=str(err), frontier=nearest)
            cyc = plan_cycle(net, frontiers={nearest}, **kw)
        if owed - set(cyc.pre.explore):
            post = solve_post_exploration(net, sources=sorted(set(cyc.pre.explore) | owed),
                                          positions=cyc.pre.final_positions(),
                                          masters=sorted(cyc.pre.master_receivers()), static=static, options=opts)
            cyc = CyclePlan(cyc.pre, post, cyc.exploration, dict(cyc.meta))
        return cyc

    def _recall(self, net, positions: dict[str, str], owed: set[str], static: set[str],
                opts: SolverOptions) -> CyclePlan:
        """No frontier left: the recall brings home every robot m reaches, then the
        robots whose information the base lacks (``owed``) hand it over there. The
        information may hold new frontiers, so that recall is not the last plan."""
        me = self.ctx.name
        pre = solve_recall(net, positions=positions, masters={me}, static=static, options=opts)
        home, holders = pre.final_positions(), pre.master_receivers()
        sources = sorted(owed & holders)
        post = solve_post_exploration(net, sources=sources, positions=home, masters=sorted(holders),
                                      static=static, options=opts) if sources else idle_plan(home, holders, "post")
        solve_s = sum(p.meta.get("solve_time_s") or 0.0 for p in (pre, post))
        return CyclePlan(pre, post, {}, {"solve_time_s": round(solve_s, 4), "recall": True,
                                         "stranded": pre.meta["stranded"]})


def _unreachable(topology: Topology, base: str, positions: dict[str, str]) -> set[str]:
    """Robots a new plan m cannot reach: m spreads over communication edges between
    occupied locations from the base; once one robot holds it, robots carry it to
    every other. With nobody in the base's reach, everyone away is unreachable."""
    occupied = set(positions.values()) | {base}
    reach, todo = {base}, [base]
    while todo:
        s = todo.pop()
        for u, v in topology.communication:
            other = v if u == s else u if v == s else None
            if other in occupied and other not in reach:
                reach.add(other)
                todo.append(other)
    if any(s in reach for s in positions.values()):
        return set()
    return {r for r, s in positions.items() if s != base}


def _count(cyc: CyclePlan, external: bool) -> int:
    n = 0
    for p in (cyc.pre, cyc.post):
        for c in p.communications:
            ext = p.location(c.sender, c.t) != p.location(c.receiver, c.t)
            n += ext == external
    return n


class WaitToReceivePlan(CopsSkill):
    """Wait to receive plan: RUNNING until a plan m newer than the last one has
    arrived, then adopt it (continue from the step at which it arrived): SUCCESS.

    Reads/writes ``cops``."""

    def update(self) -> Status:
        st = self.state
        pending = st.knowledge.pending_plan
        if pending is None or pending["cycle"] <= st.cycle:
            return Status.RUNNING
        st.adopt({"plan": pending["payload"]["plan"], "cycle": pending["cycle"], "part": pending["part"],
                  "t": pending["t"]})
        st.knowledge.pending_plan = None
        self.event("cops_plan_received", cycle=st.cycle, part=st.part, step=st.step)
        return Status.SUCCESS


class ReturnWithoutPlan(CopsSkill):
    """The standing order of m: a robot that has received no new plan
    ``recall_after_s`` (from its last plan) after it started waiting goes back to the
    base location, where the next plan reaches it (the base station plans it there).
    Back at the base it greets the base station every ``greet_period_s``, so that a
    robot wrongly declared lost is counted again.

    Reads ``cops``; drives the robot. Returns RUNNING (a background task of the wait).
    """

    PARAMS = {**CopsSkill.PARAMS,
              "greet_period_s": Param(float, 5.0, "greeting period once back at the base", exclusive_minimum=0),
              "leader": Param(str, "base", "the agent to greet (the planner at the base)")}

    def initialise(self) -> None:
        self._since = self.ctx.clock.now_s
        self._sent = self._stranded = False
        self.reset_drive()
        self._greeted = -math.inf

    def update(self) -> Status:
        st, now = self.state, self.ctx.clock.now_s
        if self.ctx.robot is None or st.plan is None:
            return Status.RUNNING
        if now - self._since < st.recall_after_s:
            return Status.RUNNING
        home = network_view(self.ctx).location() == st.base_location
        if not self._sent:
            self._sent = True
            if not home:
                self.event("return_without_plan", cycle=st.cycle)
        if not self._stranded and self.drive_to(st.base_location, arrive=True) == Status.FAILURE:
            self._stranded = True  # no way home: wait where it is
        if home and now - self._greeted >= self.p["greet_period_s"]:
            self._greeted = now
            self.greet_home(st)
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        self.stop_own_motion()


class _PartCheck(CopsSkill):
    ABSTRACT = True
    PART = ""

    def update(self) -> Status:
        return Status.SUCCESS if self.state.part == self.PART else Status.FAILURE


class IsExploring(_PartCheck):
    """Explore?: SUCCESS when the agent is in the exploration phase, else FAILURE."""

    TYPE_NAME = "Explore?"
    PART = "explore"


class FinishedPlan(_PartCheck):
    """Finished plan?: SUCCESS when the agent has done its part of the cycle plan."""

    TYPE_NAME = "FinishedPlan?"
    PART = "done"


class MissionComplete(CopsSkill):
    """SUCCESS when the agent has executed the final plan (the recall), else FAILURE.

    A robot that has, back at the base, greets the leader (``home``) every
    ``greet_period_s`` and is RUNNING until the leader answers with the final plan
    (or ``lost_timeout_s`` passes) and a little longer, so that the leader learns
    it is home. The leader (``leader``, it has the ``team`` service) is RUNNING
    after its final plan until every robot of the team has acknowledged the final
    plan it hands to robots greeting it from the base: a robot the plan believed
    elsewhere, or wrongly declared lost, comes home by the standing order and gets
    the plan there. A robot silent for ``recall_after_s + lost_timeout_s`` after
    the final plan is declared lost (``robot_declared_lost``).
    """

    TYPE_NAME = "MissionComplete?"
    PARAMS = {**CopsSkill.PARAMS,
              "greet_period_s": Param(float, 5.0, "a robot's greeting period once home", exclusive_minimum=0),
              "leader": Param(str, "base", "the planner at the base (robots greet it)")}

    def initialise(self) -> None:
        self._done_s: float | None = None
        self._answered_s: float | None = None
        self._greeted = -math.inf

    def update(self) -> Status:
        st = self.state
        if not (st.final and st.part == "done"):
            return Status.FAILURE
        now = self.ctx.clock.now_s
        if self.ctx.name != self.p["leader"]:
            return self._home(st, now)
        team = self.ctx.services["team"]
        kn = st.knowledge
        away = [r for r in sorted(team) if final_plan_id(st.cycle, r) not in kn.acked]
        if away and now - st.planned_s > st.recall_after_s + st.lost_timeout_s:
            for r in away:
                kn.declared[r] = now
                self.event("robot_declared_lost", robot=r, cycle=st.cycle, part=st.part, step=st.step)
            away = []
        self.feedback_message = f"waiting for {', '.join(away)} at the base" if away else ""
        return Status.RUNNING if away else Status.SUCCESS

    def _home(self, st: CopsState, now: float) -> Status:
        if self._done_s is None:
            self._done_s = now
        if final_plan_id(st.cycle, self.ctx.name) in st.knowledge.received and self._answered_s is None:
            self._answered_s = now
        # after the answer, greet twice more: the leader's answer to each is acknowledged again
        answered = self._answered_s is not None and now - self._answered_s >= 2 * self.p["greet_period_s"]
        if answered or now - self._done_s >= st.lost_timeout_s:
            return Status.SUCCESS
        if now - self._greeted >= self.p["greet_period_s"]:
            self._greeted = now
            self.greet_home(st)
        self.feedback_message = f"home: telling {self.p['leader']}"
        return Status.RUNNING


class CommunicationAction(CopsSkill):
    """Communication Action of step t: PreIntCom, then ExtCom, then PostIntCom.

    In each phase the agent re-sends its outgoing messages every ``resend_period_s``
    until each is acknowledged (information it relays only once that has arrived),
    and waits until every incoming one has arrived
    (``InformationStorage`` listens and acknowledges throughout). While it waits it
    greets every partner of the step so that they know it is alive. A partner not
    heard for ``lost_timeout_s`` (from the plan) is declared lost: its messages are
    dropped from the plan and the agent goes on.

    Reads/writes ``cops``. Logs ``cops_phase`` per completed phase and
    ``robot_declared_lost``. Returns RUNNING until all communication of step t is
    done, then SUCCESS.
    """

    PARAMS = {**CopsSkill.PARAMS,
              "resend_period_s": Param(float, 5.0, "re-send an unacknowledged message this often",
                                       exclusive_minimum=0)}

    def initialise(self) -> None:
        st = self.state
        plan = st.part_plan()
        self._phases = list(plan.communication_phases(st.step, self.ctx.name).items()) if plan else []
        self._i = 0
        self._sent: dict[str, float] = {}
        self._since = self.ctx.clock.now_s
        self._partners = sorted(set(plan.robots) - {self.ctx.name}) if plan else []
        self._greeted = -math.inf

    def update(self) -> Status:
        st, now = self.state, self.ctx.clock.now_s
        kn = st.knowledge
        self._greet(now, kn)
        while self._i < len(self._phases):
            name, comms = self._phases[self._i]
            waiting = [c for c in comms if not self._done(c, st)]
            if waiting:
                for c in waiting:
                    other = self._partner(c)
                    if other in kn.lost:
                        continue
                    silent_s = now - max(self._since, kn.heard.get(other, -math.inf))
                    if silent_s > st.lost_timeout_s + self._allow(other):
                        kn.declared[other] = now
                        self.event("robot_declared_lost", robot=other, cycle=st.cycle, part=st.part, step=st.step)
                    elif c.sender == self.ctx.name and not self._relay_pending(c, comms, st):
                        self._send(c, st, now)
                self.feedback_message = f"t={st.step} {name}: {len(waiting)} to go"
                if any(not self._done(c, st) for c in waiting):
                    return Status.RUNNING
            self.event("cops_phase", cycle=st.cycle, part=st.part, step=st.step, phase=name, messages=len(comms))
            self._i += 1
            self._since = now
        return Status.SUCCESS

    def _relay_pending(self, c: Communication, comms: list[Communication], st: CopsState) -> bool:
        """Whether information c.info that this agent relays in c has yet to arrive in
        this phase (a relay chain within one step: send only what you hold)."""
        return any(d.receiver == self.ctx.name and d.info == c.info and not self._done(d, st) for d in comms)

    def _partner(self, c: Communication) -> str:
        return c.receiver if c.sender == self.ctx.name else c.sender

    def _allow(self, other: str) -> float:
        """Extra silence allowed for a partner that explores out of radio reach (its
        exploration time and the way back) or comes back by the standing order."""
        st = self.state
        if other in st.plan.meta.get("returning", ()):
            return st.recall_after_s + st.lost_timeout_s
        task = st.plan.exploration.get(other) if st.part == "post" else None
        return 2.0 * task.steps * st.delta_t_s if task else 0.0

    def _done(self, c: Communication, st: CopsState) -> bool:
        kn = st.knowledge
        mid = message_id(st.cycle, st.part, c)
        other = self._partner(c)
        return other in kn.lost or kn.finished.get(other) == st.cycle or (
            mid in kn.acked if c.sender == self.ctx.name else mid in kn.received)

    def _send(self, c: Communication, st: CopsState, now: float) -> None:
        mid = message_id(st.cycle, st.part, c)
        if now - self._sent.get(mid, -math.inf) < self.p["resend_period_s"]:
            return
        self._sent[mid] = now
        collect_own_map(self.ctx, st.knowledge)
        payload = st.knowledge.payload()
        if c.info == MASTER:
            payload["plan"] = st.plan_message()
        self.radio.send(c.receiver, KIND, {"type": "info", "id": mid, "cycle": st.cycle, "part": st.part,
                                           "t": c.t, "info": c.info, "payload": payload})

    def _greet(self, now: float, kn: Knowledge) -> None:
        if now - self._greeted < self.p["resend_period_s"]:
            return
        self._greeted = now
        for other in self._partners:
            self.radio.send(other, KIND, {"type": "hello"})


class TransitionAction(CopsSkill):
    """Transition Action: move to the plan's next location s_{t+1} and set t = t + 1.

    At the last step of a part it moves on, once at the part's last location:
    pre-exploration to exploration (a robot the plan sends exploring) or to
    post-exploration, post-exploration to done. A robot that adopted the plan away
    from where the plan has it (coming home by the standing order) goes there first.

    Reads/writes ``cops``; drives the robot through its NetworkView's routes.
    Returns RUNNING while moving, SUCCESS on arrival (at once for a stay), FAILURE
    when the location cannot be reached.
    """

    def initialise(self) -> None:
        self.reset_drive()

    def update(self) -> Status:
        st = self.state
        plan = st.part_plan()
        if plan is None:
            return Status.FAILURE
        last = st.step >= plan.horizon
        moving = self.drive_to(plan.location(self.ctx.name, min(st.step + 1, plan.horizon)), arrive=True) \
            if self.ctx.robot is not None else None
        if moving is not None:
            return moving
        if last:
            self._next_part(st)
        else:
            st.step += 1
        return Status.SUCCESS

    def _next_part(self, st: CopsState) -> None:
        if st.part == "pre":
            st.part = "explore" if self.ctx.name in st.plan.exploration else "post"
        else:
            st.part = "done"
        st.step = 0

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()


class _PlanTimer(CopsSkill):
    """A sim-clock timer whose duration the plan sets when it is entered."""

    ABSTRACT = True

    @abstractmethod
    def duration_s(self, st: CopsState) -> float:
        """The timer's duration, read from the plan when the timer is entered."""

    def initialise(self) -> None:
        self._until = self.ctx.clock.now_s + self.duration_s(self.state)

    def update(self) -> Status:
        return Status.SUCCESS if self.ctx.clock.now_s >= self._until - 1e-9 else Status.RUNNING


class ActionTimer(_PlanTimer):
    """Action Timer: RUNNING for ΔT (from the plan) when the step has a transition
    to make, so that robots stay in step; SUCCESS at once at the last step of a part.
    Reads ``cops``."""

    def duration_s(self, st: CopsState) -> float:
        plan = st.part_plan()
        return 0.0 if plan is None or st.step >= plan.horizon else st.delta_t_s


class ExplorationTimer(_PlanTimer):
    """Exploration Timer: RUNNING for the robot's exploration time (its task's steps
    times ΔT), then SUCCESS. Reads ``cops``."""

    def duration_s(self, st: CopsState) -> float:
        task = st.plan.exploration.get(self.ctx.name) if st.plan else None
        return task.steps * st.delta_t_s if task else 0.0


def _bearing(a: Any, b: Any) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def ordered_choices(topology: Topology, at: str, came_from: str | None, candidates: list[str]) -> list[str]:
    """Algorithm 1's choices in an order every robot agrees on without talking:
    clockwise from the direction the robot came from (from +x at a frontier)."""
    p = topology.locations[at]
    ref = _bearing(p, topology.locations[came_from]) if came_from else math.pi

    def turn(s: str) -> float:
        return (ref - _bearing(p, topology.locations[s])) % (2 * math.pi)
    return sorted(candidates, key=lambda s: (round(turn(s), 6), s))


class ExplorationAction(CopsSkill):
    """Exploration Action (Algorithm 1): communication-free split at forks.

    Starting at its frontier with frontier index i, the robot repeats: c = number of
    choices (at the frontier: its unexplored exits; further on: the tunnels other than
    the one it came by), choice = i mod c, i = i div c, move one location towards the
    choice. Robots sent to one frontier thus spread over its branches (Figure 5). A
    choice the robot cannot reach (no route, or blocked) is dropped and the robot
    chooses again among the others, with i as it was. At a dead end it waits. Runs
    until the Exploration Timer stops it.

    Reads ``cops`` (the plan's exploration task and network); drives the robot.
    Logs ``exploration_choice`` and ``exploration_unreachable``. Returns RUNNING.
    """

    def initialise(self) -> None:
        st = self.state
        task = st.plan.exploration[self.ctx.name]
        self._i, self._at, self._prev = task.index, task.frontier, None
        self._moving: str | None = None
        self.reset_drive()
        self._i_before = self._i
        self._visited = {task.frontier}
        st.knowledge.freshness[self.ctx.name] = st.cycle

    def update(self) -> Status:
        st = self.state
        topo = st.knowledge.topology
        if self._moving is not None:
            moving = self.drive_to(self._moving)
            if moving == Status.RUNNING:
                return moving
            if moving == Status.FAILURE:
                self.event("exploration_unreachable", at=self._at, choice=self._moving)
                topo.unreachable.add(self._moving)
                self._i, self._moving = self._i_before, None
                return Status.RUNNING
            self._prev, self._at, self._moving = self._at, self._moving, None
            self._visited.add(self._at)
        if self._prev is None:
            explored = set(st.plan.meta.get("explored", ())) | self._visited | topo.unreachable
            cands = [s for s in topo.neighbours(self._at) if s not in explored]
        else:
            cands = [s for s in topo.neighbours(self._at)
                     if s != self._prev and s not in self._visited and s not in topo.unreachable]
        choices = ordered_choices(topo, self._at, self._prev, cands)
        if not choices:
            self.feedback_message = f"dead end at {self._at}"
            return Status.RUNNING
        c = len(choices)
        choice, i = choices[self._i % c], self._i // c
        self.event("exploration_choice", at=self._at, choices=choices, index=self._i, choice=choice)
        self._i_before, self._i, self._moving = self._i, i, choice
        self.feedback_message = f"to {choice} (i={self._i})"
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        self.stop_own_motion()


class TransitToReturnNode(CopsSkill):
    """Transit to return node: go back to the frontier the exploration started from,
    then continue with post-exploration (step 0).

    Reads/writes ``cops``; drives the robot. Returns RUNNING on the way, SUCCESS
    there, FAILURE without a route.
    """

    def initialise(self) -> None:
        self.reset_drive()

    def update(self) -> Status:
        st = self.state
        moving = self.drive_to(st.plan.exploration[self.ctx.name].frontier, arrive=True)
        if moving is not None:
            return moving
        st.part, st.step = "post", 0
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()
