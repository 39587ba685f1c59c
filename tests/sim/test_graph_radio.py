"""The graph world's datagram radio: links over communication edges, losses."""
import numpy as np

from .graph_fixtures import robot, world


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


def test_a_linked_message_arrives_at_the_next_update_unless_lost():
    w = world()
    r, net, clock = robot(w, loss=0.0)
    base = net.add("base", lambda: w.pos("a"))
    r.radio.send("base", "x", 1)
    net.update()
    assert [m.data for m in base.receive()] == [1] and r.radio.delivered == 1
    r, net, clock = robot(w, loss=1.0)
    base = net.add("base", lambda: w.pos("a"))
    r.radio.send("base", "x", 2)
    net.update()
    assert base.receive() == [] and r.radio.dropped == 1
