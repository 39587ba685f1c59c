"""What the simulator does for the executive's fault kinds: a flat battery, degraded
range sensors, a drifting pose, radio blackouts, cut links and dead breadcrumbs."""
import networkx as nx
import numpy as np
import pytest

from delve.sim.graph_radio import GraphRadioNetwork, GraphRadioSpec
from delve.sim.platforms import AERIAL, LEGGED
from delve.sim.radio import RadioNetwork, RadioSpec
from delve.sim.robot import SimRobot
from delve.sim.voxel_map import UNKNOWN
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_tunnel, free_space_mesh

from .graph_fixtures import robot as graph_robot
from .graph_fixtures import world as graph_world

V = 0.5


@pytest.fixture(scope="module")
def tunnel():
    """One straight tunnel along x from 0 to 60 m, 4 m wide and 3 m high."""
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([63.0, 3.0, 3.0]), V)
    carve_tunnel(canvas, [0.0, 0.0, 0.0], [60.0, 0.0, 0.0], 4.0, 3.0)
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="fault-test", voxel_size_m=V, origin=canvas.origin, free=canvas.free, mesh=mesh,
                 centreline=nx.Graph(), start=[1.0, 0.0, 0.01])


def make(world, platform=AERIAL, endurance_s=None, x=5.0):
    clock = {"t": 0.0}
    net = RadioNetwork(RadioSpec(), world, np.random.default_rng(0), lambda: clock["t"])
    holder = {}
    radio = net.add("r", lambda: holder["r"].true_position)
    r = holder["r"] = SimRobot("r", platform, world, np.array([x, 0.0, 0.5]), radio, endurance_s)
    net.add("base", lambda: np.array([1.0, 0.0, 1.0]))
    return r, net, clock


def known(r) -> int:
    return int(np.count_nonzero(r.onboard_map.occupancy != UNKNOWN))


# ---- battery ----------------------------------------------------------------------
def test_a_battery_drop_takes_a_share_of_what_is_left(tunnel):
    r, _, _ = make(tunnel, endurance_s=100.0)
    r.drain_battery(0.25)
    assert r.endurance_remaining_s == pytest.approx(75.0) and r.alive


def test_at_zero_endurance_the_robot_stops_and_its_radio_falls_silent(tunnel):
    r, net, _ = make(tunnel, endurance_s=100.0)
    r.follow_path(np.array([[40.0, 0.0, 1.5]]))
    r.step(0.1)
    r.radio.send("base", "x", 1)
    r.drain_battery(1.0)
    assert not r.alive
    r.step(0.1)
    assert r.path_status == "blocked" and r.blocked_reason == "endurance exhausted" and r.radio.silent
    moved = r.distance_m
    r.step(0.1)
    r.radio.send("base", "y", 2)
    assert r.distance_m == moved and r.radio.pending == 1, "what was queued stays undelivered, nothing new"
    net.update()
    assert not net.linked("r", "base")


def test_running_out_of_endurance_is_the_same_as_a_flat_battery(tunnel):
    r, _, _ = make(tunnel, endurance_s=0.35)
    r.follow_path(np.array([[40.0, 0.0, 1.5]]))
    for _ in range(5):
        r.step(0.1)
    assert not r.alive and r.radio.silent and r.blocked_reason == "endurance exhausted"


def test_a_graph_robot_falls_silent_when_its_battery_is_flat():
    w = graph_world()
    r, net, _ = graph_robot(w, endurance_s=100.0)
    net.add("base", lambda: w.pos("a"))
    assert net.linked("r", "base")
    r.drain_battery(1.0)
    r.step(1.0)
    assert not r.alive and r.radio.silent and not net.linked("r", "base")


# ---- range sensors ----------------------------------------------------------------
def test_a_lidar_dropout_maps_nothing_until_restored(tunnel):
    r, _, _ = make(tunnel)
    r.degrade_lidar(None, 0.0)
    r.scan()
    assert known(r) == 0
    r.restore_lidar()
    r.scan()
    assert known(r) > 0


def test_a_degraded_lidar_sees_less_and_no_farther_than_its_range(tunnel):
    full, _, _ = make(tunnel)
    full.scan()
    short, _, _ = make(tunnel)
    short.degrade_lidar(range_m=4.0, ray_fraction=0.5)
    short.scan()
    assert 0 < known(short) < known(full) / 2
    idx = np.argwhere(short.onboard_map.occupancy != UNKNOWN)
    centres = short.onboard_map.origin + (idx + 0.5) * V
    assert np.linalg.norm(centres - short.true_position, axis=1).max() <= 4.0 + 2 * V


# ---- localisation drift ----------------------------------------------------------------
def test_a_drifting_robot_believes_it_is_elsewhere_and_walks_by_its_belief(tunnel):
    r, _, _ = make(tunnel, x=5.0)
    r.drift(np.array([0.1, 0.0, 0.0]))
    r.follow_path(np.array([[25.0, 0.0, 1.5]]))
    for _ in range(400):
        r.step(0.1)
    assert r.path_status == "arrived"
    drift = r.position - r.true_position
    assert drift[0] == pytest.approx(r.drift_m) and r.drift_m > 0.5
    assert r.position[0] == pytest.approx(25.0) and r.true_position[0] == pytest.approx(25.0 - r.drift_m)
    r.relocalise()
    assert r.drift_m == 0.0 and np.allclose(r.position, r.true_position)


def test_a_drifting_robot_maps_the_tunnel_at_its_believed_pose(tunnel):
    straight, _, _ = make(tunnel)
    straight.scan()
    drifting, _, _ = make(tunnel)
    drifting.drift(np.array([0.0, 1.0, 0.0]))
    drifting.follow_path(np.array([[5.0, 0.0, 1.5], [5.1, 0.0, 1.5]]))
    for _ in range(10):
        drifting.step(0.1)
    drifting.scan()
    # The walls land a metre to the side of where they are.
    assert not np.array_equal(np.argwhere(straight.onboard_map.occupancy == 1),
                              np.argwhere(drifting.onboard_map.occupancy == 1))


# ---- radio -------------------------------------------------------------------------
def test_a_blacked_out_radio_keeps_what_it_sends_until_it_is_back(tunnel):
    r, net, clock = make(tunnel)
    net.update()
    assert net.linked("r", "base")
    r.radio.blackout = True
    r.radio.send("base", "x", 1)
    clock["t"] += 1.0
    net.update()
    assert not net.linked("r", "base") and r.radio.pending == 1
    r.radio.blackout = False
    clock["t"] += 1.0
    net.update()
    assert r.radio.pending == 0 and len(net.endpoints["base"].receive()) == 1


def test_a_cut_link_is_no_link(tunnel):
    _, net, clock = make(tunnel)
    net.cut_links.add(("base", "r"))
    net.update()
    assert not net.direct_link("r", "base")
    net.cut_links.clear()
    clock["t"] += 1.0
    net.update()
    assert net.direct_link("r", "base")


def test_a_cut_graph_link_drops_datagrams():
    w = graph_world()
    r, net, _ = graph_robot(w)
    net.add("base", lambda: w.pos("a"))
    net.cut_links.add(("base", "r"))
    r.radio.send("base", "x", 1)
    net.update()
    assert not net.linked("r", "base") and r.radio.dropped == 1


def test_a_dead_breadcrumb_relays_nothing(tunnel):
    r, net, _ = make(tunnel, platform=LEGGED)
    net.set_breadcrumbs("r", 2)
    drop = r.deploy_breadcrumb()
    assert drop.ok and [b.name for b in net.active_breadcrumbs()] == [drop.name]
    net.dead_breadcrumbs.add(drop.name)
    assert net.active_breadcrumbs() == [] and drop.name not in net.node_positions()


def test_graph_radio_spec_has_no_cut_links_by_default():
    net = GraphRadioNetwork(GraphRadioSpec(), graph_world(), np.random.default_rng(0), lambda: 0.0)
    assert net.cut_links == set()
