"""A robot on a graph world: driving tunnels, exploring by arriving, faults, endurance."""
import numpy as np

from delve.sim.platforms import LEGGED

from .graph_fixtures import robot, world


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


def test_a_lost_robot_stops_and_falls_silent():
    w = world()
    r, net, _ = robot(w)
    net.add("base", lambda: w.pos("a"))
    r.kill()
    r.radio.send("base", "x", 1)
    assert not r.alive and r.radio.pending == 0 and not net.linked("r", "base")


def test_without_endurance_a_robot_has_its_platforms_and_stops_when_it_runs_out():
    w = world()
    r, _, _ = robot(w)
    assert r.endurance_remaining_s == LEGGED.endurance_s
    r, _, _ = robot(w, endurance_s=10.0)
    r.follow_path(r.route("b"))
    for _ in range(20):
        r.step(1.0)
    assert r.endurance_remaining_s == 0.0 and r.path_status == "blocked"
    assert r.blocked_reason == "endurance exhausted" and r.distance_m < 50.0
