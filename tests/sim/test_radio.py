import numpy as np

from delve.sim.radio import RadioNetwork, RadioSpec


class OpenWorld:
    def __init__(self):
        self.wall = False

    def line_of_sight(self, a, b):
        return not self.wall


def network(loss=0.0):
    clock = {"t": 0.0}
    world = OpenWorld()
    net = RadioNetwork(RadioSpec(range_m=50, loss=loss, update_period_s=1.0), world,
                       np.random.default_rng(0), lambda: clock["t"])
    pos = {"a": np.zeros(3), "b": np.array([10.0, 0, 0])}
    a = net.add("a", lambda: pos["a"])
    b = net.add("b", lambda: pos["b"])
    return net, world, clock, pos, a, b


def tick(net, clock):
    clock["t"] += 1.0
    net.update()


def test_messages_wait_until_a_link_exists():
    net, world, clock, pos, a, b = network()
    pos["b"] = np.array([100.0, 0, 0])
    a.send("b", "hello", 1)
    tick(net, clock)
    assert not a.linked_to("b") and a.pending == 1 and b.receive() == []
    pos["b"] = np.array([10.0, 0, 0])
    tick(net, clock)
    got = b.receive()
    assert [m.data for m in got] == [1] and a.pending == 0


def test_rock_blocks_the_link():
    net, world, clock, pos, a, b = network()
    world.wall = True
    a.send("b", "x", 1)
    tick(net, clock)
    assert a.pending == 1
    world.wall = False
    tick(net, clock)
    assert a.pending == 0


def test_lossy_link_eventually_delivers_everything():
    net, world, clock, pos, a, b = network(loss=0.5)
    for i in range(20):
        a.send("b", "n", i)
    got = []
    for _ in range(200):
        tick(net, clock)
        got += [m.data for m in b.receive()]
        if not a.pending:
            break
    assert sorted(got) == list(range(20))
    assert a.delivered == 20
