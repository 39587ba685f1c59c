"""delve.skills.cops: the COPS behaviours, one agent at a time with a scripted radio."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import py_trees
import pytest
from delve.planners.cops.plan import Communication, CyclePlan, ExplorationTask, Plan
from delve.planners.cops.topology import Topology
from delve.skills.base import AgentContext
from delve.skills.cops import (CommunicationAction, ExplorationAction, GreetBase, InformationStorage, Knowledge,
                               LeavePlan, MissionComplete, SolveCOPS, TransitionAction, TransitToBase, message_id)
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

    def arrived(self, location: str) -> bool:
        return location == self.location()

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


class BlockedWalker(Walker):
    """A Walker that cannot get to the locations in ``blocked``."""

    def __init__(self, at: int, blocked: set[str]) -> None:
        super().__init__(at)
        self.blocked = blocked

    def route(self, location: str) -> list[float] | None:
        return None if location in self.blocked else super().route(location)


def test_an_unreachable_choice_is_dropped_and_reported():
    """At a fork s1 | s2 (s1 first clockwise), s1 cannot be reached: Algorithm 1
    chooses again among the rest with the same index, and the knowledge says why."""
    py_trees.blackboard.Blackboard.clear()
    robot = BlockedWalker(at=0, blocked={"s1"})
    events = []
    ctx = AgentContext(name="r1", namespace="/r1", clock=SimpleNamespace(now_s=0.0),
                       log=lambda event, **f: events.append((event, f)), robot=robot,
                       services={"network_view": robot})
    action = ExplorationAction("Exploration action", ctx)
    st = action.state
    topo = st.knowledge.topology
    for name, y in (("s0", 0.0), ("s1", 50.0), ("s2", -50.0)):
        topo.add_location(name, (0.0, y, 0.0), explored=name == "s0")
    topo.add_mobility_edge("s0", "s1")
    topo.add_mobility_edge("s0", "s2")
    idle = Plan(horizon=0, trajectories={"r1": ["s0"]}, masters=["r1"], phase="pre")
    st.plan = CyclePlan(idle, idle, {"r1": ExplorationTask("s0", 0, 0, 4, 0)})
    for _ in range(6):
        action.tick_once()
        robot.step()
    assert [f["choice"] for e, f in events if e == "exploration_choice"] == ["s1", "s2"]
    assert [f["choice"] for e, f in events if e == "exploration_unreachable"] == ["s1"]
    assert topo.unreachable == {"s1"} and robot.location() == "s2"
    assert action.status == Status.RUNNING
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


def greet(radio, storage, robot: str) -> dict:
    radio.inbox.append(SimpleNamespace(sender=robot, kind="cops", data={"type": "hello", "home": True}))
    storage.tick_once()
    return radio.infos()[-1]


def test_a_robot_greeting_from_the_base_joins_the_final_plan_where_the_plan_has_it_there():
    """r1 is at the base at the leader's step 1 and carries m out at step 2: it joins
    in at step 1. r2, which the plan has at s2, has its part done and counts as finished."""
    radio = Radio()
    ctx, storage, done, st = final_state("base", {"radio": radio, "team": {"r1": "s0", "r2": "s2"}})
    pre = Plan(horizon=3, trajectories={"base": ["s0"] * 4, "r1": ["s0", "s0", "s1", "s2"],
                                        "r2": ["s2"] * 4},
               communications=[Communication(0, "base", "r1", "m"), Communication(3, "r1", "r2", "m")],
               masters=["base"], phase="recall")
    st.plan, st.part, st.step, st.base_location = CyclePlan(pre, pre, {}), "pre", 1, "s0"
    reply = greet(radio, storage, "r1")
    assert (reply["part"], reply["t"]) == ("pre", 1) and "r1" not in st.knowledge.finished
    reply = greet(radio, storage, "r2")
    assert reply["part"] == "done" and st.knowledge.finished == {"r2": 6}
    assert Knowledge().payload().keys() == st.knowledge.payload().keys()
    other = Knowledge()
    other.absorb(st.knowledge.payload())
    assert other.finished == {"r2": 6}  # it travels with the information


def test_a_communication_with_a_finished_robot_is_done(relay):
    """r4 got the final plan at the base with its part done: r3 does not wait for it."""
    relay.st.knowledge.finished["r4"] = relay.st.cycle
    relay.action.tick_once()
    assert [d["info"] for d in relay.radio.infos()] == ["r2"]  # sends what it holds of r2's; gets nothing from r4
    assert relay.action.status == Status.RUNNING  # its own message to the base is still unacknowledged


def test_the_leader_declares_a_robot_never_heard_again_lost():
    ctx, storage, done, st = final_state("base", {"radio": Radio(), "team": {"r1": "s0"}})
    ctx.clock.now_s = 50.0 + st.recall_after_s + st.lost_timeout_s + 1.0
    done.tick_once()
    assert done.status == Status.SUCCESS and "r1" in st.knowledge.lost


def test_a_robot_home_greets_the_leader_until_it_answers():
    radio = Radio()
    ctx, storage, done, st = final_state("r1", {"radio": radio})
    done.tick_once()
    assert done.status == Status.RUNNING and [(to, kind, d["type"], d["home"]) for to, kind, d in radio.sent] == \
        [("base", "cops", "hello", True)]
    assert radio.sent[0][2]["payload"]["topology"] == st.knowledge.topology.to_dict()  # with what it holds
    radio.inbox.append(SimpleNamespace(sender="base", kind="cops", data={
        "type": "info", "id": "6:final:r1", "cycle": 6, "part": "done", "t": 0, "info": "m",
        "payload": {"topology": Topology().to_dict(), "freshness": {}, "declared": {}, "heard": {}}}))
    storage.tick_once()
    done.tick_once()
    assert done.status == Status.RUNNING  # greets a little longer, for the leader to hear the ack
    ctx.clock.now_s += 10.0
    done.tick_once()
    assert done.status == Status.SUCCESS


class ChangingMap:
    """An onboard map whose changes are handed out once each."""

    def __init__(self, *changes) -> None:
        self.changes = list(changes)

    def take_changes(self):
        return self.changes.pop(0) if self.changes else (np.zeros(0, np.int64), np.zeros(0, np.int8))


def test_map_chunks_travel_with_the_knowledge_and_are_never_taken_twice():
    robot, relay, base = Knowledge(), Knowledge(), Knowledge()
    onboard = ChangingMap((np.array([1, 2]), np.array([0, 1], np.int8)), (np.array([3]), np.array([0], np.int8)))
    robot.collect_map("r1", onboard)
    relay.absorb(robot.payload())
    robot.collect_map("r1", onboard)
    robot.collect_map("r1", onboard)          # nothing new: no chunk
    base.absorb(relay.payload())
    base.absorb(robot.payload())
    assert sorted(base.map_chunks) == sorted(robot.map_chunks) and len(base.map_chunks) == 2
    merged = np.concatenate([flat for flat, _ in base.map_chunks.values()])
    assert sorted(merged.tolist()) == [1, 2, 3]


def test_the_leader_counts_robots_whose_standing_order_fires_before_the_recall_reaches_them():
    """The last plan (made at t = 0, 2 + 1 steps of 60 s) left r1 and r2 away; their
    standing order fires at 3 * 60 + 1800 s. The recall reaches r1 at step 2 and r2 at
    step 30: from t = 1500 s, r2 will have left by then, r1 not."""
    py_trees.blackboard.Blackboard.clear()
    ctx = AgentContext(name="base", namespace="/base", clock=SimpleNamespace(now_s=1500.0),
                       log=lambda *a, **k: None, services={})
    solve = SolveCOPS("COPS", ctx, delta_t_s=60.0)
    st = solve.state
    away = {"base": ["s0"] * 3, "r1": ["s0", "s1", "s1"], "r2": ["s0", "s1", "s2"], "r3": ["s0"] * 3}
    last = Plan(horizon=2, trajectories=away, masters=["base"], phase="pre")
    st.plan = CyclePlan(last, Plan(horizon=1, trajectories={r: t[-1:] * 2 for r, t in away.items()},
                                   masters=["base"], phase="post"), {})
    st.planned_s, st.delta_t_s, st.recall_after_s, st.base_location = 0.0, 60.0, 1800.0, "s0"
    recall = Plan(horizon=30, trajectories={"base": ["s0"] * 31, "r1": ["s1"] * 31, "r2": ["s2"] * 31,
                                            "r3": ["s0"] * 31},
                  communications=[Communication(2, "base", "r1", "m"), Communication(30, "r1", "r2", "m"),
                                  Communication(0, "base", "r3", "m")],
                  masters=["base"], phase="recall")
    assert solve._gone_before_m(st, CyclePlan(recall, recall, {})) == {"r2"}
    ctx.clock.now_s = 100.0
    assert solve._gone_before_m(st, CyclePlan(recall, recall, {})) == set()
    py_trees.blackboard.Blackboard.clear()


def test_robots_coming_back_by_the_standing_order_are_planned_static_at_the_base():
    """s0 (base) - s1 - s2 explored, s3 beyond s2. r1 comes back by the standing order:
    it waits at the base in the plan and r2 explores; alone, r1 is sent out after all."""
    py_trees.blackboard.Blackboard.clear()
    ctx = AgentContext(name="base", namespace="/base", clock=SimpleNamespace(now_s=0.0),
                       log=lambda *a, **k: None, services={})
    solve = SolveCOPS("COPS", ctx, time_limit_s=5.0)
    st = solve.state
    st.base_location = "s0"
    for i in range(4):
        st.knowledge.topology.add_location(f"s{i}", (50.0 * i, 0.0, 0.0), explored=i < 3)
    for i in range(3):
        st.knowledge.topology.add_mobility_edge(f"s{i}", f"s{i + 1}", 50.0)
        st.knowledge.topology.add_communication_edge(f"s{i}", f"s{i + 1}")
    _, cyc = solve._plan(st, {"base": "s0", "r1": "s0", "r2": "s0"}, [])
    assert set(cyc.exploration) == {"r1", "r2"}  # not coming back: both explore
    _, cyc = solve._plan(st, {"base": "s0", "r1": "s0", "r2": "s0"}, ["r1"])
    assert set(cyc.exploration) == {"r2"} and set(cyc.pre.trajectories["r1"]) == {"s0"}
    _, cyc = solve._plan(st, {"base": "s0", "r1": "s0"}, ["r1"])
    assert set(cyc.exploration) == {"r1"}
    py_trees.blackboard.Blackboard.clear()


def walker_context(robot, events: list, **services) -> AgentContext:
    py_trees.blackboard.Blackboard.clear()
    return AgentContext(name="r1", namespace="/r1", clock=SimpleNamespace(now_s=0.0),
                        log=lambda event, **f: events.append((event, f)), robot=robot,
                        services={"network_view": robot, **services})


def test_a_failed_transition_is_an_event_with_its_reason():
    """The plan sends r1 from s0 to s1, which it cannot reach: the action fails, the
    log says who, from where, to where and why, and the state keeps why (the robot
    then leaves the plan for home, reason "transition failed: ...")."""
    events: list = []
    ctx = walker_context(BlockedWalker(at=0, blocked={"s1"}), events)
    action = TransitionAction("Transition action", ctx)
    step = Plan(horizon=1, trajectories={"r1": ["s0", "s1"]}, masters=["r1"], phase="pre")
    st = action.state
    st.plan, st.cycle, st.part, st.step = CyclePlan(step, step, {}), 2, "pre", 0
    action.tick_once()
    assert action.status == Status.FAILURE
    assert [f for e, f in events if e == "cops_transition_failed"] == [
        {"agent": "r1", "node": "Transition action", "robot": "r1", "cycle": 2, "part": "pre", "step": 0,
         "reason": "no route to s1", "from": "s0", "to": "s1"}]
    assert st.transition_failed == "no route to s1"
    leave = LeavePlan("Leave the plan", ctx)
    leave.tick_once()
    assert events[-1][1]["reason"] == "transition failed: no route to s1" and "r1" in st.knowledge.gone_home
    py_trees.blackboard.Blackboard.clear()


class RegionWalker(Walker):
    """A Walker whose view merged s1 and s2 into region s1 (it resolves names)."""

    def resolve(self, name: str) -> str | None:
        return {"s2": "s1"}.get(name, name)


def test_a_name_merged_into_a_region_is_driven_to_under_the_region_s_name():
    events: list = []
    robot = RegionWalker(at=0)
    ctx = walker_context(robot, events)
    action = TransitionAction("Transition action", ctx)
    step = Plan(horizon=1, trajectories={"r1": ["s0", "s2"]}, masters=["r1"], phase="pre")
    st = action.state
    st.plan, st.cycle, st.part, st.step = CyclePlan(step, step, {}), 2, "pre", 0
    action.tick_once()
    assert robot.goal == 1          # the region's name: s1
    robot.step()
    action.tick_once()
    assert action.status == Status.SUCCESS and st.step == 1 and events == []
    py_trees.blackboard.Blackboard.clear()


def test_a_robot_low_on_endurance_leaves_the_plan_goes_to_the_base_and_says_so():
    events: list = []
    robot = Walker(at=3)
    radio = Radio()
    ctx = walker_context(robot, events, base_location="s0", radio=radio)
    ctx.robot.radio = radio
    leave, home, greet = (LeavePlan("Leave the plan", ctx), TransitToBase("Transit to base", ctx),
                          GreetBase("Tell the base", ctx, greetings=2, greet_period_s=5.0))
    leave.tick_once()
    st = leave.state
    assert leave.status == Status.SUCCESS and st.knowledge.gone_home == {"r1": 0.0}
    assert [(e, f["at"], f["reason"]) for e, f in events] == [("cops_left_plan", "s3", "endurance")]
    for _ in range(3):
        home.tick_once()
        assert home.status == Status.RUNNING
        robot.step()
    home.tick_once()
    assert home.status == Status.SUCCESS and robot.location() == "s0"
    for now in (0.0, 5.0, 10.0):
        ctx.clock.now_s = now
        greet.tick_once()
    assert greet.status == Status.SUCCESS
    hellos = [d for to, _k, d in radio.sent if to == "base" and d["type"] == "hello"]
    assert len(hellos) == 2 and hellos[0]["payload"]["gone_home"] == {"r1": 0.0}
    py_trees.blackboard.Blackboard.clear()


def test_the_team_plans_without_a_robot_gone_home(relay):
    """r4 left the plan for home: r3 does not wait for it, and the leader neither plans
    it nor waits for it at the end."""
    relay.st.knowledge.gone_home["r4"] = 10.0
    relay.action.tick_once()
    assert [d["info"] for d in relay.radio.infos()] == ["r2"]
    ctx, storage, done, st = final_state("base", {"radio": Radio(), "team": {"r1": "s0"}})
    st.knowledge.gone_home["r1"] = 60.0
    done.tick_once()
    assert done.status == Status.SUCCESS and "r1" not in st.knowledge.lost
    st.base_location = "s0"
    positions, returning = SolveCOPS("COPS", ctx)._positions(st, {"r1": "s0", "r2": "s0"})
    assert positions == {"r2": "s0"} and returning == []
    py_trees.blackboard.Blackboard.clear()


def test_with_every_robot_gone_home_the_leader_plans_the_last_recall():
    """Frontiers are left, but nobody to explore them: the mission is over, not failed."""
    events: list = []
    py_trees.blackboard.Blackboard.clear()
    ctx = AgentContext(name="base", namespace="/base", clock=SimpleNamespace(now_s=0.0),
                       log=lambda event, **f: events.append(event),
                       services={"base_location": "s0", "team": {"r1": "s0"}})
    solve = SolveCOPS("COPS", ctx, time_limit_s=5.0)
    st = solve.state
    for i in range(3):
        st.knowledge.topology.add_location(f"s{i}", (50.0 * i, 0.0, 0.0), explored=i < 2)
    for i in range(2):
        st.knowledge.topology.add_mobility_edge(f"s{i}", f"s{i + 1}", 50.0)
    st.knowledge.gone_home["r1"] = 5.0
    solve.tick_once()
    assert solve.status == Status.SUCCESS and st.final and events == ["cops_plan"]
    py_trees.blackboard.Blackboard.clear()


class ShortSightedWalker(RegionWalker):
    """A Walker whose own map shows s0..s3 only; it can walk towards any point."""

    def location(self) -> str | None:
        return f"s{self.at}" if self.at < 4 else None

    def resolve(self, name: str) -> str | None:
        return name if int(name[1:]) < 4 else None

    @property
    def position(self) -> np.ndarray:
        return np.array([float(self.at), 0.0, 0.0])

    def route_towards(self, point) -> np.ndarray:
        return np.array([[float(point[0]), 0.0, 0.0]])

    def follow_path(self, path) -> None:
        super().follow_path([np.asarray(path, dtype=float)[-1][0]])

    def near(self, point) -> bool:
        return abs(self.at - point[0]) < 0.5


def test_a_location_only_a_partner_has_mapped_is_driven_to_where_the_knowledge_puts_it():
    events: list = []
    robot = ShortSightedWalker(at=3)
    ctx = walker_context(robot, events)
    action = TransitionAction("Transition action", ctx)
    step = Plan(horizon=1, trajectories={"r1": ["s3", "s6"]}, masters=["r1"], phase="pre")
    st = action.state
    st.knowledge.topology.add_location("s6", (6.0, 0.0, 0.0), explored=True)
    st.plan, st.cycle, st.part, st.step = CyclePlan(step, step, {}), 2, "pre", 0
    for _ in range(3):
        action.tick_once()
        assert action.status == Status.RUNNING and robot.goal == 6
        robot.step()
    action.tick_once()
    assert action.status == Status.SUCCESS and robot.at == 6 and events == []
    py_trees.blackboard.Blackboard.clear()


class MapEndWalker(ShortSightedWalker):
    """A ShortSightedWalker whose own map takes it no further than s4."""

    def route_towards(self, point) -> np.ndarray:
        return np.array([[min(float(point[0]), 4.0), 0.0, 0.0]])


def exploring_from_s3(robot, events: list) -> tuple[ExplorationAction, Topology]:
    """r1 explores from frontier s3 (explored) towards s6, which only its knowledge shows."""
    action = ExplorationAction("Exploration action", walker_context(robot, events))
    st = action.state
    topo = st.knowledge.topology
    for i in (3, 6):
        topo.add_location(f"s{i}", (float(i), 0.0, 0.0), explored=i == 3)
    topo.add_mobility_edge("s3", "s6")
    idle = Plan(horizon=0, trajectories={"r1": ["s3"]}, masters=["r1"], phase="pre")
    st.plan = CyclePlan(idle, idle, {"r1": ExplorationTask("s3", 0, 0, 4, 0)})
    for _ in range(6):
        action.tick_once()
        robot.step()
    return action, topo


def test_a_location_the_exploration_arrived_at_is_explored_though_the_robot_s_map_never_shows_it():
    """cops_mine (issue 16): robots arrived at cells that their own maps never counted
    as visited, and those cells stayed frontiers' targets: the mission never ended."""
    events: list = []
    robot = ShortSightedWalker(at=3)
    action, topo = exploring_from_s3(robot, events)
    assert robot.at == 6 and [f["choice"] for e, f in events if e == "exploration_choice"] == ["s6"]
    assert "s6" in topo.explored and topo.frontiers() == set()
    py_trees.blackboard.Blackboard.clear()


def test_where_its_own_map_takes_it_no_nearer_a_plan_s_move_is_done_and_an_exploration_s_choice_unreachable():
    events: list = []
    robot = MapEndWalker(at=4)
    ctx = walker_context(robot, events)
    move = TransitionAction("Transition action", ctx)
    step = Plan(horizon=1, trajectories={"r1": ["s4", "s6"]}, masters=["r1"], phase="pre")
    st = move.state
    st.knowledge.topology.add_location("s6", (6.0, 0.0, 0.0), explored=True)
    st.plan, st.cycle, st.part, st.step = CyclePlan(step, step, {}), 2, "pre", 0
    move.tick_once()
    assert move.status == Status.SUCCESS and st.step == 1 and events == []
    robot = MapEndWalker(at=3)
    events.clear()
    action, topo = exploring_from_s3(robot, events)
    assert robot.at == 4 and [f["choice"] for e, f in events if e == "exploration_unreachable"] == ["s6"]
    assert topo.unreachable == {"s6"} and "s6" not in topo.explored and topo.frontiers() == set()
    py_trees.blackboard.Blackboard.clear()
