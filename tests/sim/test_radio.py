"""Unit tests for delve.sim.radio: link budgets in small carved worlds, the mesh
through breadcrumbs, pings, and outboxes that lose nothing."""

import itertools
import math

import networkx as nx
import numpy as np
import pytest

from delve.sim.platforms import LEGGED
from delve.sim.radio import BREADCRUMB_ANTENNA_HEIGHT_M, RadioNetwork, RadioSpec
from delve.sim.robot import SimRobot
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_chamber, carve_tunnel, free_space_mesh

V = 0.5
WIDTH, HEIGHT = 4.0, 3.0
Z = 0.5          # node height above the floor (a legged robot's body)


def _world(canvas: VoxelCanvas) -> World:
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="radio-test", voxel_size_m=V, origin=canvas.origin, free=canvas.free,
                 mesh=mesh, centreline=nx.Graph(), start=[1.0, 0.0, 0.01])


@pytest.fixture(scope="module")
def straight():
    """One straight tunnel along x from 0 to 260 m."""
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([263.0, 3.0, HEIGHT]), V)
    carve_tunnel(canvas, [0.0, 0.0, 0.0], [260.0, 0.0, 0.0], WIDTH, HEIGHT)
    return _world(canvas)


@pytest.fixture(scope="module")
def corner():
    """An L: along x from 0 to 60 m, then a right angle and along y from 0 to 60 m."""
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([63.0, 63.0, HEIGHT]), V)
    carve_tunnel(canvas, [0.0, 0.0, 0.0], [60.0, 0.0, 0.0], WIDTH, HEIGHT)
    carve_tunnel(canvas, [60.0, 0.0, 0.0], [60.0, 60.0, 0.0], WIDTH, HEIGHT)
    carve_chamber(canvas, [60.0, 0.0, 0.0], 0.5 * WIDTH, HEIGHT)
    return _world(canvas)


@pytest.fixture(scope="module")
def parallel():
    """Unconnected tunnels along x at y = 0, 6 and 31: 2 m and 21 m of rock between neighbours."""
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([43.0, 34.0, HEIGHT]), V)
    for y in (0.0, 6.0, 31.0):
        carve_tunnel(canvas, [0.0, y, 0.0], [40.0, y, 0.0], WIDTH, HEIGHT)
    return _world(canvas)


def at(x, y=0.0):
    return np.array([float(x), float(y), Z])


def make_net(world, seed=0, **spec):
    clock = {"t": 0.0}
    net = RadioNetwork(RadioSpec(**spec), world, np.random.default_rng(seed), lambda: clock["t"])
    return net, clock


def tick(net, clock, dt=1.0):
    clock["t"] += dt
    net.update()


# ---- the link model -------------------------------------------------------------
def test_default_budget_and_loss_curve():
    spec = RadioSpec()
    assert 110.0 <= spec.line_of_sight_range_m <= 140.0
    margins = np.array([0.0, 3.0, 10.0, 20.0, 40.0])
    loss = spec.attempt_loss(margins)
    assert np.all(np.diff(loss) < 0), "loss must rise as the margin falls"
    assert loss[0] == pytest.approx(1 - 0.95 * math.exp(-1.0))
    assert loss[-1] == pytest.approx(spec.loss, abs=1e-3)
    assert RadioSpec(loss=0.0).attempt_loss(10.0) == pytest.approx(1 - math.exp(-0.1))
    assert RadioSpec(loss=0.1, fading=False).attempt_loss(margins).tolist() == [0.1] * 5


@pytest.mark.parametrize("bad", [dict(range_m=0), dict(loss=1.5), dict(path_loss_exponent=-1),
                                 dict(rock_loss_db_per_m=-1), dict(breadcrumbs_per_robot=-1),
                                 dict(breadcrumbs_per_robot=2.5), dict(update_period_s=0)])
def test_spec_rejects_impossible_values(bad):
    with pytest.raises(ValueError, match="radio"):
        RadioSpec(**bad)


def test_straight_tunnel_links_past_100_m(straight):
    net, _ = make_net(straight)
    budgets = {d: net.link_budget(at(5), at(5 + d)) for d in (10, 50, 100, 110, 135)}
    for d in (10, 50, 100, 110):
        assert budgets[d].line_of_sight and budgets[d].rock_m == 0.0 and budgets[d].linked, d
    assert not budgets[135].linked and budgets[135].quality == 0.0
    q = [budgets[d].quality for d in (10, 50, 100, 110)]
    assert all(a > b for a, b in itertools.pairwise(q)), q
    assert budgets[10].quality > 0.9 and budgets[100].quality < 0.7


def test_range_cap(straight):
    net, _ = make_net(straight, range_m=40.0)
    assert net.link_budget(at(5), at(40)).linked
    assert not net.link_budget(at(5), at(50)).linked


def test_a_corner_cuts_the_range_to_tens_of_metres(corner):
    net, _ = make_net(corner)
    around = net.link_budget(at(54), at(60, 6))            # 6 m either side of the corner
    assert not around.line_of_sight and around.rock_crossings == 1 and 0 < around.rock_m < 5
    assert around.linked
    clear = net.link_budget(at(60 - 6 * math.sqrt(2)), at(60))   # the same distance in the clear
    assert clear.line_of_sight and clear.margin_db > around.margin_db + 10.0
    # Along either leg links reach 55 m; round the corner they stop within tens of metres.
    assert net.link_budget(at(5), at(60)).linked and net.link_budget(at(60), at(60, 55)).linked
    reach = max(r for r in np.arange(1.0, 40.0, 0.5) if net.link_budget(at(60 - r), at(60, r)).linked)
    assert 10.0 <= reach * math.sqrt(2) <= 40.0, reach
    assert not net.link_budget(at(5), at(60, 30)).linked


def test_rock_attenuates_and_tens_of_metres_block(parallel):
    net, _ = make_net(parallel)
    thin = net.link_budget(at(20, 0), at(20, 6))           # 2 m of rock between the tunnels
    assert not thin.line_of_sight and thin.rock_m == pytest.approx(2.0, abs=0.6) and thin.linked
    free = net.link_budget(at(20, 0), at(26, 0))           # same distance, clear line
    spec = net.spec
    expected = spec.corner_loss_db + spec.rock_loss_db_per_m * thin.rock_m
    assert free.rx_power_dbm - thin.rx_power_dbm == pytest.approx(expected, abs=0.01)
    thick = net.link_budget(at(20, 6), at(20, 31))         # 21 m of rock
    assert thick.rock_m > 18.0 and not thick.linked
    through_two = net.link_budget(at(20, 0), at(20, 31))
    assert through_two.rock_crossings == 2 and not through_two.linked


# ---- outboxes -------------------------------------------------------------------
def test_messages_wait_until_a_link_exists(straight):
    net, clock = make_net(straight, loss=0.0, fading=False)
    pos = {"a": at(5), "b": at(200)}
    a = net.add("a", lambda: pos["a"])
    b = net.add("b", lambda: pos["b"])
    a.send("b", "hello", 1)
    tick(net, clock)
    assert not a.linked_to("b") and a.pending == 1 and b.receive() == []
    pos["b"] = at(15)
    tick(net, clock)
    assert a.linked_to("b") and net.direct_link("a", "b")
    assert [m.data for m in b.receive()] == [1] and a.pending == 0 and a.delivered == 1


def test_updates_follow_the_period(straight):
    net, clock = make_net(straight, loss=0.0, fading=False, update_period_s=2.0)
    a = net.add("a", lambda: at(5))
    net.add("b", lambda: at(15))
    net.update()                           # t = 0: first update
    a.send("b", "x", 1)
    tick(net, clock, 1.0)                  # t = 1: not due
    assert a.pending == 1
    tick(net, clock, 1.0)                  # t = 2: due
    assert a.pending == 0


def test_lossy_link_eventually_delivers_everything_in_order(straight):
    net, clock = make_net(straight, loss=0.5)
    a = net.add("a", lambda: at(5))
    b = net.add("b", lambda: at(15))
    for i in range(20):
        a.send("b", "n", i)
    got = []
    for _ in range(200):
        tick(net, clock)
        got += [m.data for m in b.receive()]
        left = [m.data for m in a.outbox]
        assert left == sorted(left)
        if not a.pending:
            break
    assert sorted(got) == list(range(20)) and a.delivered == 20 and a.sent == 20


# ---- the mesh and breadcrumbs ------------------------------------------------------
def test_multi_hop_through_a_chain_of_breadcrumbs(straight):
    net, clock = make_net(straight, loss=0.0, fading=False)
    base = net.add("base", lambda: at(2))
    robot = net.add("robot", lambda: at(245))
    robot.send("base", "map", "delta")
    tick(net, clock)
    assert not net.link_budget(at(2), at(245)).linked
    assert not robot.linked_to("base") and robot.pending == 1
    first = net.deploy_breadcrumb("robot", at(85))
    second = robot.deploy_breadcrumb(at(165))
    assert first.ok and second.ok and first.name == "robot_breadcrumb_1"
    assert robot.breadcrumbs == 2
    tick(net, clock)
    assert net.route("robot", "base") == ["robot", "robot_breadcrumb_2", "robot_breadcrumb_1", "base"]
    assert robot.linked_to("base") and not net.direct_link("robot", "base")
    assert [m.data for m in base.receive()] == ["delta"] and robot.pending == 0
    names = {(s.a, s.b) for s in net.link_states}
    assert ("robot_breadcrumb_1", "robot_breadcrumb_2") in names
    assert all(0.0 < s.quality <= 1.0 and s.budget.linked for s in net.link_states)
    assert set(net.node_positions()) == {"base", "robot", "robot_breadcrumb_1", "robot_breadcrumb_2"}


def test_a_breadcrumb_at_the_corner_relays_round_it(corner):
    net, clock = make_net(corner, loss=0.0, fading=False)
    base = net.add("base", lambda: at(5))
    robot = net.add("robot", lambda: at(60, 45))
    tick(net, clock)
    assert not robot.ping("base")
    assert net.deploy_breadcrumb("robot", np.array([60.0, 0.0, BREADCRUMB_ANTENNA_HEIGHT_M])).ok
    tick(net, clock)
    assert robot.ping("base") and net.route("base", "robot")[1] == "robot_breadcrumb_1"
    robot.send("base", "k", 7)
    tick(net, clock)
    assert [m.data for m in base.receive()] == [7]


def test_multi_hop_loss_applies_per_hop_and_nothing_is_lost(straight):
    net, clock = make_net(straight, loss=0.3, seed=3)
    base = net.add("base", lambda: at(2))
    robot = net.add("robot", lambda: at(245))
    for x in (85, 165):
        net.deploy_breadcrumb("robot", at(x))
    for i in range(30):
        robot.send("base", "n", i)
    got = []
    for _ in range(300):
        tick(net, clock)
        got += [m.data for m in base.receive()]
        if not robot.pending:
            break
    assert sorted(got) == list(range(30))
    hops = [net._links[(min(u, v), max(u, v))].loss for u, v in itertools.pairwise(net.route("robot", "base"))]
    assert len(hops) == 3 and min(hops) >= 0.3


def test_breadcrumb_counts_and_refusals(straight):
    net, _ = make_net(straight)
    carrier = net.add("carrier", lambda: at(5))
    explorer = net.add("explorer", lambda: at(8), breadcrumbs=0)
    assert carrier.breadcrumbs == 4 and explorer.breadcrumbs == 0
    drops = [carrier.deploy_breadcrumb(at(10 + i)) for i in range(4)]
    assert all(d.ok for d in drops) and [d.remaining for d in drops] == [3, 2, 1, 0]
    fifth = carrier.deploy_breadcrumb(at(20))
    assert not fifth.ok and not fifth and fifth.name is None
    assert "no breadcrumbs left" in fifth.error and "carrier" in fifth.error
    none = explorer.deploy_breadcrumb(at(20))
    assert not none.ok and "explorer has no breadcrumbs left" in none.error
    net.set_breadcrumbs("explorer", 1)
    rock = explorer.deploy_breadcrumb(np.array([20.0, 10.0, Z]))
    assert not rock.ok and "inside rock" in rock.error and explorer.breadcrumbs == 1
    assert not net.deploy_breadcrumb("ghost", at(20)).ok
    assert len(net.breadcrumbs) == 4


def test_breadcrumbs_run_out_of_battery(straight):
    net, clock = make_net(straight, loss=0.0, fading=False, breadcrumb_battery_s=100.0)
    net.add("base", lambda: at(2))
    robot = net.add("robot", lambda: at(170))
    net.deploy_breadcrumb("robot", at(85))
    tick(net, clock)
    assert robot.linked_to("base")
    tick(net, clock, 100.0)
    assert not robot.linked_to("base") and net.active_breadcrumbs() == []


def test_clients_do_not_relay(straight):
    for relay, expected in ((False, None), (True, ["base", "drone", "robot"])):
        net, clock = make_net(straight, loss=0.0, fading=False)
        net.add("base", lambda: at(2))
        net.add("drone", lambda: at(85), relay=relay)
        net.add("robot", lambda: at(170))
        tick(net, clock)
        assert net.route("base", "robot") == expected
        assert net.route("drone", "base") == ["drone", "base"]


def test_a_breadcrumb_is_dropped_only_where_it_hears_the_mesh(corner):
    """The base station 10 m before the corner: 40 m down the second leg a breadcrumb
    would link to nothing, so the drop is refused (a result with an error, the
    breadcrumb kept); 5 m past the corner it links to the base and is dropped, and
    then the far spot hears the new breadcrumb down the leg. Neither the carrier
    itself nor a WiFi client counts as the mesh."""
    net, clock = make_net(corner, loss=0.0, fading=False)
    net.add("base", lambda: at(50))
    net.add("drone", lambda: at(60, 38), relay=False)
    carrier = net.add("carrier", lambda: at(60, 40), breadcrumbs=2)
    tick(net, clock)
    far = carrier.deploy_breadcrumb(at(60, 40))
    assert not far.ok and far.remaining == 2 and carrier.breadcrumbs == 2 and net.breadcrumbs == {}
    assert "would hear no mesh node (best: base, margin -" in far.error
    near = carrier.deploy_breadcrumb(at(60, 5))
    assert near.ok and near.remaining == 1
    tick(net, clock)
    assert net.mesh_heard_at(at(60, 40), "carrier") == (True, "")
    assert carrier.deploy_breadcrumb(at(60, 40)).ok


def test_clients_link_to_mesh_nodes_only(straight):
    """Two aerial robots (WiFi clients) side by side: each links to the mesh nodes (the
    legged robot, the base station), not to the other: they talk through an access point."""
    net, clock = make_net(straight, loss=0.0, fading=False)
    net.add("base", lambda: at(2))
    net.add("drone1", lambda: at(85), relay=False)
    net.add("drone2", lambda: at(90), relay=False)
    net.add("robot", lambda: at(95))
    tick(net, clock)
    assert not net.direct_link("drone1", "drone2")
    assert net.direct_link("drone1", "robot") and net.direct_link("drone2", "robot")
    route = net.route("drone2", "drone1")
    assert len(route) == 3 and route[1] in ("robot", "base")


def test_sim_robot_drops_breadcrumbs_on_the_ground(straight):
    net, _ = make_net(straight)
    net.add("base", lambda: at(2))
    holder = {}
    radio = net.add("anymal", lambda: holder["r"].position)
    robot = SimRobot("anymal", LEGGED, straight, np.array([30.0, 0.0, 0.0]), radio)
    holder["r"] = robot
    net.set_breadcrumbs("anymal", 1)
    drop = robot.deploy_breadcrumb()
    assert drop.ok and robot.breadcrumbs == 0
    np.testing.assert_allclose(net.breadcrumbs[drop.name].position, [30.0, 0.0, BREADCRUMB_ANTENNA_HEIGHT_M])
    again = robot.deploy_breadcrumb()
    assert not again.ok and "no breadcrumbs left" in again.error


# ---- pings and determinism -------------------------------------------------------
def test_ping_succeeds_fails_and_counts(straight):
    net, clock = make_net(straight, loss=0.0, fading=False)
    pos = {"b": at(30)}
    a = net.add("a", lambda: at(5))
    net.add("b", lambda: pos["b"])
    assert not a.ping("b"), "no links before the first update"
    tick(net, clock)
    assert a.ping("b") and net.ping("b", "a")
    pos["b"] = at(200)
    tick(net, clock)
    assert not a.ping("b") and not a.ping("nobody")
    assert a.pings == 4 and a.pings_answered == 1


def test_ping_fails_with_the_round_trip_loss(straight):
    net, clock = make_net(straight, loss=0.5, seed=11)
    a = net.add("a", lambda: at(5))
    net.add("b", lambda: at(10))
    tick(net, clock)
    p = net._links[("a", "b")].loss
    ok = np.mean([a.ping("b") for _ in range(2000)])
    assert ok == pytest.approx((1 - p) ** 2, abs=0.04)


def _scripted_run(world, seed):
    net, clock = make_net(world, loss=0.3, seed=seed)
    pos = {"robot": at(60)}
    base = net.add("base", lambda: at(2))
    robot = net.add("robot", lambda: pos["robot"])
    trace = []
    for step in range(40):
        pos["robot"] = at(60 + 5 * step)
        if step == 10:
            trace.append(robot.deploy_breadcrumb(at(100)).name)
        robot.send("base", "n", step)
        tick(net, clock)
        trace.append((robot.ping("base"), [m.data for m in base.receive()], robot.pending))
    return trace


def test_same_seed_same_run(straight):
    assert _scripted_run(straight, 5) == _scripted_run(straight, 5)
    assert _scripted_run(straight, 5) != _scripted_run(straight, 6)
