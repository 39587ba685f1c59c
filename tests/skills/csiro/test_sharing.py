"""delve.skills.csiro.sharing: robots share frontier summaries, trajectory points, goals and the
topometric map every 5 s while a link exists; the base station collects what reaches it."""
from __future__ import annotations

import numpy as np
from delve.planners.csiro.sharing import FrontierSummary
from delve.planners.csiro.topometric import TopometricMap, frontier_node
from delve.skills.base import AgentContext
from delve.skills.csiro import BASE_SERVICE, CONFIG_SERVICE, CollectFrontiers, CsiroConfig, ShareFrontiers, \
    UpdateFrontiers, csiro_state
from delve.skills.csiro.state import SHARE

from ..fakes import Clock, FakeRadio, FakeRobot, body, events, make_ctx
from .conftest import sweep


def sharing_robot(tunnel, tunnel_points):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 18.0))
    ctx = make_ctx(robot)
    ctx.services[CONFIG_SERVICE] = CsiroConfig(team=("r1", "r2"))
    update, share = UpdateFrontiers("update", ctx), ShareFrontiers("share", ctx)
    sweep(robot, tunnel_points)
    return robot, ctx, update, share


def tick(ctx, *nodes, dt: float = 1.0) -> None:
    for n in nodes:
        n.tick_once()
    ctx.clock.now_s += dt


def test_shares_every_period_with_each_linked_peer_only_what_is_new(tunnel, tunnel_points):
    robot, ctx, update, share = sharing_robot(tunnel, tunnel_points)
    tick(ctx, update, share)
    sent = [m for m in robot.radio.sent if m.kind == SHARE]
    assert sorted(m.recipient for m in sent) == ["base", "r2"]
    data = sent[0].data
    assert data["robot"] == "r1" and len(data["summaries"]) == 2 and data["goal"] is None
    assert len(data["trajectory"]) == 1 and data["topometric"][0][:3] == ("node", "r1", 0)
    for _ in range(4):                                          # within the 5 s period: nothing more
        tick(ctx, update, share)
    assert len([m for m in robot.radio.sent if m.kind == SHARE]) == 2
    robot._pos = robot.position + np.array([4.0, 0.0, 0.0])
    tick(ctx, update, share)                                    # t = 5 s
    later = [m for m in robot.radio.sent if m.kind == SHARE][2:]
    assert len(later) == 2
    assert len(later[0].data["trajectory"]) == 1                # only the new point
    assert [e[:3] for e in later[0].data["topometric"]] == [("node", "r1", 1), ("edge", "r1", 0)]


def test_nothing_is_sent_without_a_link(tunnel, tunnel_points):
    robot, ctx, update, share = sharing_robot(tunnel, tunnel_points)
    robot.radio.link_up = False
    for _ in range(12):
        tick(ctx, update, share)
    assert not [m for m in robot.radio.sent if m.kind == SHARE]
    assert not events(ctx, "csiro_shared")


def peer_message(t_s: float = 30.0) -> dict:
    """What r2 shares: its map (a walk along y at x = 30), one frontier and its goal."""
    peer = TopometricMap()
    for k in range(5):
        peer.add_pose("r2", 10.0 * k, [30.0, 6.0 + 3.0 * k, 1.5])
    summary = FrontierSummary(id=4, owner="r2", mean=np.array([30.0, 22.0, 2.0]), cov=np.eye(3), reward=5.0,
                              observer=np.array([30.0, 19.0, 1.0]), updated_s=t_s)
    return {"robot": "r2", "t_s": t_s, "summaries": [summary.to_message()],
            "trajectory": np.array([[30.0, 6.0, 1.5], [30.0, 12.0, 1.5]]),
            "goal": {"key": ["r2", 4], "observer": [30.0, 19.0, 1.0]}, "topometric": peer.changes()}


def test_a_peers_share_is_taken_in(tunnel, tunnel_points):
    robot, ctx, update, share = sharing_robot(tunnel, tunnel_points)
    robot.radio.deliver("r2", SHARE, peer_message())
    tick(ctx, update, share)
    st = csiro_state(ctx)
    assert ("r2", 4) in st.summaries and len(st.own_summaries("r1")) == 2
    f = frontier_node(("r2", 4))
    assert list(st.topometric.graph.neighbors(f)) == [("r2", 3)]            # closest in time to 30 s
    assert np.allclose(st.topometric.position(f), [30.0, 19.0, 1.5])        # observer + body height
    assert st.goals["r2"][0] == ("r2", 4) and len(st.places["r2"]) == 2
    # a newer share without that frontier: it is gone (explored by r2)
    robot.radio.deliver("r2", SHARE, {**peer_message(), "summaries": [], "goal": None, "trajectory": []})
    tick(ctx, share)
    assert ("r2", 4) not in st.summaries and f not in st.topometric.graph and "r2" not in st.goals
    assert len(st.places["r2"]) == 2


def test_base_station_collects_and_logs_each_uplink():
    radio = FakeRadio("base")
    events_: list = []
    ctx = AgentContext(name="base", namespace="/base", clock=Clock(), log=lambda e, **f: events_.append((e, f)),
                       services={"radio": radio})
    node = CollectFrontiers("collect", ctx)
    radio.deliver("r2", SHARE, peer_message())
    node.tick_once()
    ctx.clock.now_s += 5.0
    radio.deliver("r2", SHARE, {**peer_message(), "topometric": []})
    node.tick_once()                                         # the same uplink: no second event
    ctx.clock.now_s += 60.0
    radio.deliver("r2", SHARE, {**peer_message(), "topometric": []})
    node.tick_once()                                         # after a silence: a new uplink
    base = ctx.services[BASE_SERVICE]
    assert list(base.state.summaries) == [("r2", 4)]
    assert [f["robot"] for e, f in events_ if e == "csiro_uplink"] == ["r2", "r2"]
    assert len(base.state.topometric.trajectory_nodes()) == 5
