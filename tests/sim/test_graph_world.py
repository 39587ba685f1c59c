"""The graph world: tunnels, exploring by arriving, the datagram radio."""
import numpy as np
import pytest

from delve.sim.graph_world import GraphRadioNetwork, GraphRadioSpec, GraphRobot, GraphWorld
from delve.sim.platforms import LEGGED


def world():
    pos = {"a": (0, 0, 0), "b": (50, 0, 0), "c": (100, 0, 0), "d": (50, 50, 0)}
    return GraphWorld(pos, [("a", "b"), ("b", "c"), ("b", "d")], [("a", "b")], "a")


def robot(w, name="r", loss=0.0, seed=0):
    clock = {"t": 0.0}
    net = GraphRadioNetwork(GraphRadioSpec(loss=loss), w, np.random.default_rng(seed), lambda: clock["t"])
    holder = {}
    r = GraphRobot(name, LEGGED, w, w.start, net.add(name, lambda: holder["r"].position))
    holder["r"] = r
    return r, net, clock


def test_arriving_explores_a_location_and_reveals_its_tunnels():
    w = world()
    r, _, _ = robot(w)
    assert r.location() == "a" and r.explored == ["a"]
    assert r.topology()["locations"].keys() == {"a", "b"}
    r.follow_path(r.route("b"))
    for _ in range(49):
        r.step(1.0)
    assert r.location() is None  # on the way, not yet there
    r.step(1.0)
    assert r.location() == "b" and r.path_status == "arrived" and r.transitions == 1
    topo = r.topology()
    assert set(topo["explored"]) == {"a", "b"} and set(topo["locations"]) == {"a", "b", "c", "d"}
    assert ["a", "b"] in topo["communication"]


def test_a_path_off_the_tunnels_is_blocked():
    w = world()
    r, _, _ = robot(w)
    r.follow_path(np.array([w.pos("c")]))
    assert r.path_status == "blocked" and "no tunnel" in r.blocked_reason


def test_radio_links_over_communication_edges_only_and_can_lose():
    w = world()
    r, net, clock = robot(w)
    base = net.add("base", lambda: w.pos("a"))
    assert net.linked("r", "base")
    r.follow_path(np.array([w.pos("b"), w.pos("d")]))
    for _ in range(100):
        r.step(1.0)
    assert r.location() == "d" and not net.linked("r", "base")
    r.radio.send("base", "x", 1)
    net.update()
    assert base.receive() == [] and r.radio.dropped == 1


def test_a_lost_robot_stops_and_falls_silent():
    w = world()
    r, net, _ = robot(w)
    net.add("base", lambda: w.pos("a"))
    r.kill()
    r.radio.send("base", "x", 1)
    assert not r.alive and r.radio.pending == 0 and not net.linked("r", "base")


def test_start_must_be_at_a_location():
    assert world().start_problem([10, 0, 0]).startswith("not at a location")
    with pytest.raises(ValueError):
        GraphWorld({"a": (0, 0, 0)}, [], [], "zz")
