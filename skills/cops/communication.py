"""Communication: the information storage that listens, acknowledges and stores in
the background, and the Communication Action of a plan step (PreIntCom, ExtCom,
PostIntCom)."""
from __future__ import annotations

import math
from typing import Any

from py_trees.common import Status

from ...planners.cops import MASTER, Communication
from ...planners.cops.topology import Topology
from ..base import AgentContext, Param
from .base import CopsSkill, network_view
from .state import KIND, CopsState, Knowledge, collect_own_map, final_plan_id, message_id


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
                    if other in kn.retired:
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
        return other in kn.retired or kn.finished.get(other) == st.cycle or (
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
