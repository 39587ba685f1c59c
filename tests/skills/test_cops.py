"""delve.skills.cops: the COPS behaviours, one agent at a time with a scripted radio."""
from __future__ import annotations

from types import SimpleNamespace

import py_trees
import pytest
from delve.planners.cops.plan import Communication, CyclePlan, Plan
from delve.planners.cops.topology import Topology
from delve.skills.base import AgentContext
from delve.skills.cops import (CommunicationAction, InformationStorage, MissionComplete, TransitionAction,
                               message_id)
from py_trees.common import Status


class Radio:
    """Records what is sent; tests hand in what is received."""

    def __init__(self) -> None:
        self.sent: list[tuple[str, str, dict]] = []
        self.inbox: list[SimpleNamespace] = []

    def send(self, recipient: str, kind: str, data: dict) -> None:
        self.sent.append((recipient, kind, data))

    def receive(self) -> list[SimpleNamespace]:
        out, self.inbox = self.inbox, []
        return out

    def infos(self) -> list[dict]:
        return [d for _to, _k, d in self.sent if d["type"] == "info"]


@pytest.fixture()
def relay():
    """r3 relays r2's information from r4 to the base within one step (all ExtCom)."""
    py_trees.blackboard.Blackboard.clear()
    radio = Radio()
    ctx = AgentContext(name="r3", namespace="/r3", clock=SimpleNamespace(now_s=0.0),
                       log=lambda event, **fields: None, services={"radio": radio})
    post = Plan(horizon=0, trajectories={"base": ["s0"], "r3": ["s1"], "r4": ["s2"]},
                communications=[Communication(0, "r4", "r3", "r2"), Communication(0, "r3", "base", "r2")],
                masters=["base", "r3", "r4"], phase="post")
    pre = Plan(horizon=0, trajectories=dict(post.trajectories), masters=list(post.masters), phase="pre")
    storage = InformationStorage("Information storage", ctx)
    action = CommunicationAction("Communication action", ctx)
    st = storage.state
    st.plan, st.cycle, st.part, st.step = CyclePlan(pre, post, {}), 3, "post", 0
    yield SimpleNamespace(ctx=ctx, radio=radio, storage=storage, action=action, st=st, post=post)
    py_trees.blackboard.Blackboard.clear()


def deliver(relay, sender: str, c: Communication, topology: Topology) -> None:
    payload = {"topology": topology.to_dict(), "freshness": {"r2": 3}, "declared": {}, "heard": {}}
    relay.radio.inbox.append(SimpleNamespace(sender=sender, kind="cops", data={
        "type": "info", "id": message_id(3, "post", c), "cycle": 3, "part": "post", "t": c.t, "info": c.info,
        "payload": payload}))


def test_a_relay_sends_only_information_it_holds(relay):
    incoming, outgoing = relay.post.communications
    relay.storage.tick_once()
    relay.action.tick_once()
    assert relay.action.status == Status.RUNNING
    assert relay.radio.infos() == []  # r2's information has not reached r3 yet

    news = Topology()
    news.add_location("s9", (0.0, 0.0, 0.0), explored=True)
    deliver(relay, "r4", incoming, news)
    relay.ctx.clock.now_s = 1.0
    relay.storage.tick_once()
    relay.action.tick_once()
    (sent,) = relay.radio.infos()
    assert sent["id"] == message_id(3, "post", outgoing)
    assert "s9" in sent["payload"]["topology"]["explored"]
    assert sent["payload"]["freshness"]["r2"] == 3


def test_a_relay_acknowledges_what_it_receives(relay):
    incoming, _ = relay.post.communications
    deliver(relay, "r4", incoming, Topology())
    relay.storage.tick_once()
    assert ("r4", "cops", {"type": "ack", "id": message_id(3, "post", incoming)}) in relay.radio.sent


def test_the_step_ends_when_the_relayed_message_is_acknowledged(relay):
    incoming, outgoing = relay.post.communications
    deliver(relay, "r4", incoming, Topology())
    relay.storage.tick_once()
    relay.action.tick_once()
    assert relay.action.status == Status.RUNNING
    relay.radio.inbox.append(SimpleNamespace(sender="base", kind="cops", data={
        "type": "ack", "id": message_id(3, "post", outgoing)}))
    relay.storage.tick_once()
    relay.action.tick_once()
    assert relay.action.status == Status.SUCCESS


def test_a_silent_partner_is_declared_lost(relay):
    relay.storage.tick_once()
    relay.action.tick_once()
    relay.ctx.clock.now_s = relay.st.lost_timeout_s + 1.0
    relay.radio.inbox.append(SimpleNamespace(sender="base", kind="cops", data={"type": "hello"}))
    relay.storage.tick_once()
    relay.action.tick_once()
    assert "r4" in relay.st.knowledge.lost
    relay.action.tick_once()  # it goes on with what it holds
    assert [d["id"] for d in relay.radio.infos()] == [message_id(3, "post", relay.post.communications[1])]
    assert relay.action.status == Status.RUNNING


class Walker:
    """A robot on a line of locations s0..s9 (the NetworkView too): one location per tick."""

    def __init__(self, at: int) -> None:
        self.at, self.goal, self.command_id, self.path_status = at, at, 0, "arrived"

    def follow_path(self, path) -> None:
        self.command_id += 1
        self.goal, self.path_status = int(path[-1]), "following"

    def stop(self) -> None:
        self.command_id += 1
        self.goal, self.path_status = self.at, "idle"

    def step(self) -> None:
        self.at += (self.goal > self.at) - (self.goal < self.at)
        if self.at == self.goal and self.path_status == "following":
            self.path_status = "arrived"

    def location(self) -> str | None:
        return f"s{self.at}"

    def route(self, location: str) -> list[float]:
        return [float(location[1:])]


def test_a_robot_away_from_the_plan_goes_to_its_place_before_the_part_ends():
    """It adopted the recall on its way home: the plan has it at the base already."""
    py_trees.blackboard.Blackboard.clear()
    robot = Walker(at=4)
    ctx = AgentContext(name="r1", namespace="/r1", clock=SimpleNamespace(now_s=0.0), log=lambda *a, **k: None,
                       robot=robot, services={"network_view": robot})
    action = TransitionAction("Transition action", ctx)
    home = Plan(horizon=0, trajectories={"base": ["s0"], "r1": ["s0"]}, masters=["base", "r1"], phase="pre")
    st = action.state
    st.plan, st.cycle, st.part, st.step = CyclePlan(home, home, {}), 5, "pre", 0
    for _ in range(4):
        action.tick_once()
        assert action.status == Status.RUNNING and st.part == "pre"
        robot.step()
    action.tick_once()
    assert action.status == Status.SUCCESS and robot.location() == "s0" and st.part == "post"
    py_trees.blackboard.Blackboard.clear()


def final_state(agent: str, services: dict) -> tuple:
    py_trees.blackboard.Blackboard.clear()
    ctx = AgentContext(name=agent, namespace=f"/{agent}", clock=SimpleNamespace(now_s=100.0),
                       log=lambda *a, **k: None, services=services)
    storage, done = InformationStorage("Information storage", ctx), MissionComplete("Mission complete?", ctx)
    home = Plan(horizon=0, trajectories={"base": ["s0"], "r1": ["s0"]}, masters=["base"], phase="recall")
    st = storage.state
    st.plan, st.cycle, st.part, st.final, st.planned_s = CyclePlan(home, home, {}), 6, "done", True, 50.0
    return ctx, storage, done, st


def test_the_leader_waits_for_every_robot_home_and_hands_it_the_final_plan():
    radio = Radio()
    ctx, storage, done, st = final_state("base", {"radio": radio, "team": {"r1": "s0"}})
    done.tick_once()
    assert done.status == Status.RUNNING  # r1 not heard since the final plan
    radio.inbox.append(SimpleNamespace(sender="r1", kind="cops", data={"type": "hello", "home": True}))
    storage.tick_once()
    (reply,) = radio.infos()
    assert reply["id"] == "6:final:r1" and reply["part"] == "done" and reply["payload"]["plan"]["final"]
    done.tick_once()
    assert done.status == Status.RUNNING  # until r1 acknowledges it
    radio.inbox.append(SimpleNamespace(sender="r1", kind="cops", data={"type": "ack", "id": "6:final:r1"}))
    storage.tick_once()
    done.tick_once()
    assert done.status == Status.SUCCESS


def test_the_leader_declares_a_robot_never_heard_again_lost():
    ctx, storage, done, st = final_state("base", {"radio": Radio(), "team": {"r1": "s0"}})
    ctx.clock.now_s = 50.0 + st.recall_after_s + st.lost_timeout_s + 1.0
    done.tick_once()
    assert done.status == Status.SUCCESS and "r1" in st.knowledge.lost


def test_a_robot_home_greets_the_leader_until_it_answers():
    radio = Radio()
    ctx, storage, done, st = final_state("r1", {"radio": radio})
    done.tick_once()
    assert done.status == Status.RUNNING and radio.sent == [("base", "cops", {"type": "hello", "home": True})]
    radio.inbox.append(SimpleNamespace(sender="base", kind="cops", data={
        "type": "info", "id": "6:final:r1", "cycle": 6, "part": "done", "t": 0, "info": "m",
        "payload": {"topology": Topology().to_dict(), "freshness": {}, "declared": {}, "heard": {}}}))
    storage.tick_once()
    done.tick_once()
    assert done.status == Status.RUNNING  # greets a little longer, for the leader to hear the ack
    ctx.clock.now_s += 10.0
    done.tick_once()
    assert done.status == Status.SUCCESS
