"""delve.planners.cops.distances: lower bounds on the steps information needs."""
from delve.planners.cops import information_distance

from .cops_networks import line


def test_a_move_costs_a_step_and_a_radio_hop_none():
    net = line(5, [], comm=[["s0", "s1"], ["s1", "s2"]])
    assert information_distance(net, ["s0"]) == {"s0": 0, "s1": 0, "s2": 0, "s3": 1, "s4": 2}
    assert information_distance(net, ["s4"], reverse=True) == {"s4": 0, "s3": 1, "s2": 2, "s1": 2, "s0": 2}
    assert information_distance(net, ["s3"], start={"s3": 2})["s4"] == 3
