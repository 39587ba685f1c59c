"""Planning and waiting for plans: the leader plans each cycle (``Leader?``,
``COPS``); the others wait for its plan m (``WaitToReceivePlan``), go back to the
base when none comes (``ReturnWithoutPlan``), and tell the leader when the mission
is complete (``MissionComplete?``)."""
from __future__ import annotations

import math
from typing import Any

from py_trees.common import Status

from ...planners.cops import (MASTER, CyclePlan, PlanningError, SolverOptions, plan_cycle,
                              solve_post_exploration, validate_plan)
from ...planners.cops.meter import Meter
from ...planners.cops.plan import idle_plan
from ...planners.cops.recall import solve_recall
from ...planners.cops.topology import Topology, team_network
from ..base import Param, Skill
from .base import CopsSkill, network_view
from .state import CopsState, final_plan_id


class IsLeader(Skill):
    """Leader?: SUCCESS when this agent plans for the team (``leader``), else FAILURE."""

    TYPE_NAME = "Leader?"
    AGENT = None
    PARAMS = {"leader": Param(str, "base", "name of the agent responsible for planning")}

    def update(self) -> Status:
        return Status.SUCCESS if self.ctx.name == self.p["leader"] else Status.FAILURE


class SolveCOPS(CopsSkill):
    """COPS: plan the next cycle at the leader (the base station).

    From everything the leader knows it builds the network N (explored locations),
    places the team (robots not declared lost nor gone home, where the
    last plan left them) and plans pre-exploration, exploration and
    post-exploration (``plan_cycle``). Robots whose earlier information never
    reached the base are added to the post-exploration sources. With no frontier
    left, the plan is the recall: m reaches every robot and brings it to the base,
    where those sources hand over what the base lacks; with no robot left, the
    (empty) recall is the last plan. Robots coming back by the standing order of m
    are planned static at the base; so are, in a recall, robots that order will
    have sent home before the recall's m reaches them (logged
    ``cops_replan_returning``). Every plan is checked with the plan validator
    before it is used.

    Solves are bounded by work limits (``SolverOptions``), so the plans do not
    depend on the machine's load; ``time_limit_s`` is only a safety stop, and each
    one that fires while planning is logged (``cops_safety_stop``).

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
        "time_limit_s": Param(float, 100.0, "safety stop of each integer program (wall clock; plans are "
                              "bounded by work limits, and a safety stop that fires is logged, "
                              "cops_safety_stop)", exclusive_minimum=0),
        "spacing_m": Param(float, 50.0, "location spacing: a move's cost is its length over this",
                           exclusive_minimum=0),
        "recall_after_s": Param(float, 1800.0, "standing order of m: a robot that receives no new plan "
                                "this long after its part goes back to the base", exclusive_minimum=0),
    }
    _meter: Meter | None = None  # work and safety stops of the planning in progress

    def update(self) -> Status:
        st = self.state
        base_loc = st.base_location = self.ctx.services["base_location"]
        team = self.ctx.services["team"]
        kn = st.knowledge
        positions, returning = self._positions(st, team)
        meter = self._meter = Meter()
        try:
            net, cyc = self._plan(st, positions, returning)
            gone = set() if net.frontiers or cyc.meta["owed"] else self._gone_before_m(st, cyc)
            if gone:  # plan them at the base, where the standing order of m brings them
                self.event("cops_replan_returning", cycle=st.cycle + 1, robots=sorted(gone))
                returning = sorted(set(returning) | gone)
                net, cyc = self._plan(st, {r: base_loc if r in gone else s for r, s in positions.items()}, returning)
            positions, frontiers, owed = net.positions(), net.frontiers, cyc.meta["owed"]
            if frontiers and not cyc.exploration and not owed and set(positions) - {self.ctx.name}:
                raise PlanningError(f"{len(frontiers)} frontiers left but no robot that m can reach is "
                                    f"sent to one (robots out of radio reach of the base and of each other)")
            cyc.meta["explored"] = sorted(kn.topology.explored)
            cyc.meta["returning"] = returning
        except (PlanningError, ValueError) as err:
            self._safety_stops(st, meter)
            self.event("cops_no_plan", cycle=st.cycle + 1, reason=str(err))
            self.feedback_message = str(err)
            return Status.FAILURE
        self._safety_stops(st, meter)
        problems = validate_plan(net, cyc.pre) + validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post)
        if problems:
            self.event("cops_invalid_plan", cycle=st.cycle + 1, reason=str(problems[0]))
            return Status.FAILURE
        nobody = not set(positions) - {self.ctx.name}  # every robot lost or home by endurance
        final = (not frontiers or nobody) and not owed and not cyc.meta.get("stranded")
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
                   solve_time_s=cyc.meta.get("solve_time_s"), work=meter.work, gap=cyc.meta.get("gap"),
                   clustered=bool(cyc.meta.get("clustered")), valid=True)
        return Status.SUCCESS

    def _positions(self, st: CopsState, team: dict[str, str]) -> tuple[dict[str, str], list[str]]:
        """Where the last plan left each robot not declared lost, and the robots that
        go back to the base by the standing order of m (the last plan did not reach
        them, or no new plan can)."""
        topo = st.knowledge.topology
        alive = {r: topo.resolve(s) for r, s in team.items() if r not in st.knowledge.retired}
        if st.plan is None:
            return alive, []
        last = st.plan.post.final_positions()
        reached = st.plan.pre.master_receivers() | st.plan.post.master_receivers()
        pos = {r: topo.resolve(last.get(r, s)) if r in reached else st.base_location for r, s in alive.items()}
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
        opts = SolverOptions(time_limit_s=self.p["time_limit_s"], meter=self._meter)
        owed = {r for r in positions if st.explored_in.get(r, -1) > kn.freshness.get(r, -1)}
        plan = self._cycle if net.frontiers and set(positions) - {self.ctx.name} else self._recall
        static = {self.ctx.name, *returning}
        if net.frontiers and not set(positions) - static:
            static = {self.ctx.name}
        cyc = plan(net, positions, owed, static, opts)
        cyc.meta["owed"] = sorted(owed)
        return net, cyc

    def _safety_stops(self, st: CopsState, meter: Meter) -> None:
        """Log the safety stops that fired while planning the next cycle: its plan may
        differ from run to run."""
        if meter.safety_stops:
            self.event("cops_safety_stop", cycle=st.cycle + 1, count=len(meter.safety_stops),
                       reasons=meter.safety_stops)

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
        except PlanningError as err:  # too hard within the limits: the nearest frontier only
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
        away = [r for r in sorted(team) if final_plan_id(st.cycle, r) not in kn.acked
                and r not in kn.gone_home]
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
