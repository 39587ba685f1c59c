"""The graph world: locations, tunnels, what exploring a location reveals."""
import pytest

from delve.sim.graph_world import GraphWorld, Known

from .graph_fixtures import world


def test_exploring_reveals_the_location_its_tunnels_and_their_far_ends():
    w, known = world(), Known()
    assert w.reveal(known, "b") and not w.reveal(known, "b")
    assert known.explored == ["b"] and set(known.locations) == {"a", "b", "c", "d"}
    assert set(known.mobility) == {("a", "b"), ("b", "c"), ("b", "d")}
    assert known.communication == {("a", "b")}  # b reaches a, not c or d


def test_explored_topology_is_what_exploring_in_order_reveals():
    topo = world().explored_topology(["a"])
    assert topo["explored"] == ["a"] and set(topo["locations"]) == {"a", "b"}
    assert topo["mobility"] == [["a", "b", 50.0]]


def test_start_must_be_at_a_location():
    assert world().start_problem([10, 0, 0]).startswith("not at a location")
    assert world().start_problem([50, 0, 0.5]) is None
    with pytest.raises(ValueError):
        GraphWorld({"a": (0, 0, 0)}, [], [], "zz")
