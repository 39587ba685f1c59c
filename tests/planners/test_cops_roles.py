"""delve.planners.cops.roles: positions, static robots, explorers and masters of a problem."""
import pytest

from delve.planners.cops.roles import master_robots, robot_sets

from .cops_networks import fork, team


def test_the_network_gives_what_the_caller_does_not():
    net = fork(team(2) + [{"name": "carrier", "location": "s1", "explorer": False}])
    pos, static, explorers = robot_sets(net, None, None, None)
    assert pos == {"base": "s0", "r1": "s0", "r2": "s0", "carrier": "s1"}
    assert static == {"base"} and explorers == {"r1", "r2"}
    _, static, explorers = robot_sets(net, None, {"r2"}, {"r1", "r2"})
    assert static == {"r2"} and explorers == {"r1"}, "a static robot does not explore"
    assert master_robots(net, pos, None) == {"base"}


def test_unknown_locations_and_unplaced_robots_are_rejected():
    net = fork(team(1))
    with pytest.raises(ValueError, match="unknown location 'zz'"):
        robot_sets(net, {"r1": "zz"}, None, None)
    with pytest.raises(ValueError, match="static robot 'x' has no position"):
        robot_sets(net, None, {"x"}, None)
    with pytest.raises(ValueError, match="master robot 'x' has no position"):
        master_robots(net, net.positions(), {"x"})
    net.base_station = None
    with pytest.raises(ValueError, match="no master robot"):
        master_robots(net, net.positions(), None)
