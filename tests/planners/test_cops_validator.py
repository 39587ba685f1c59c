import pytest

from delve.planners.cops import Communication, Plan, Requirement, network_from_dict, validate_plan


@pytest.fixture
def net():
    # s0 - s1 - s2 - s3 in a line; radio only between neighbours s0~s1 and s1~s2
    return network_from_dict({
        "base": "s0",
        "locations": ["s0", "s1", "s2", "s3"],
        "mobility": [["s0", "s1"], ["s1", "s2"], ["s2", "s3"]],
        "communication": [["s0", "s1"], ["s1", "s2"]],
        "robots": [{"name": "base", "location": "s0", "static": True},
                   {"name": "r1", "location": "s0"}, {"name": "r2", "location": "s1"},
                   {"name": "r3", "location": "s1"}],
        "base_station": "base",
        "collision_locations": ["s2"],
    })


def plan(traj, comms=(), masters=("base",), reqs=()):
    T = len(next(iter(traj.values()))) - 1
    return Plan(horizon=T, trajectories=traj, communications=[Communication(*c) for c in comms],
                masters=list(masters), requirements=list(reqs))


def kinds(violations):
    return {v.kind for v in violations}


def test_a_valid_relay_plan_passes(net):
    p = plan({"base": ["s0", "s0", "s0"], "r1": ["s0", "s1", "s2"], "r2": ["s1", "s1", "s1"],
              "r3": ["s1", "s1", "s1"]},
             [(0, "base", "r1", "m"), (0, "base", "r2", "m"), (1, "r2", "r3", "m")])
    assert validate_plan(net, p) == []


def test_moving_before_receiving_m(net):
    p = plan({"base": ["s0", "s0"], "r1": ["s0", "s0"], "r2": ["s1", "s2"], "r3": ["s1", "s1"]})
    v = validate_plan(net, p)
    assert kinds(v) == {"move_without_master"}
    assert v[0].robot == "r2" and v[0].t == 0


def test_sending_information_it_does_not_have(net):
    p = plan({"base": ["s0"], "r1": ["s0"], "r2": ["s1"], "r3": ["s1"]},
             [(0, "base", "r2", "m"), (0, "r2", "base", "r3")])
    assert kinds(validate_plan(net, p)) == {"send_without_information"}


def test_sending_before_receiving_m(net):
    p = plan({"base": ["s0"], "r1": ["s0"], "r2": ["s1"], "r3": ["s1"]}, [(0, "r2", "base", "r2")])
    assert kinds(validate_plan(net, p)) == {"send_without_master"}


def test_a_communication_cycle(net):
    # r2 and r3 pass r1's information round in a loop: it appears out of nowhere
    p = plan({"base": ["s0"], "r1": ["s0"], "r2": ["s1"], "r3": ["s1"]},
             [(0, "base", "r2", "m"), (0, "base", "r3", "m"), (0, "r2", "r3", "r1"), (0, "r3", "r2", "r1")])
    assert "communication_cycle" in kinds(validate_plan(net, p))


def test_communication_with_no_link(net):
    p = plan({"base": ["s0", "s0"], "r1": ["s0", "s1"], "r2": ["s1", "s1"], "r3": ["s1", "s2"]},
             [(0, "base", "r1", "m"), (0, "base", "r2", "m"), (0, "r2", "r3", "m"), (1, "r3", "base", "r3")])
    v = validate_plan(net, p)
    assert kinds(v) == {"no_link"}
    assert "s2" in v[0].message and "s0" in v[0].message


def test_moving_along_a_non_edge(net):
    p = plan({"base": ["s0", "s0"], "r1": ["s0", "s2"], "r2": ["s1", "s1"], "r3": ["s1", "s1"]},
             [(0, "base", "r1", "m")])
    assert kinds(validate_plan(net, p)) == {"non_edge_move"}


def test_static_robots_collisions_and_requirements(net):
    p = plan({"base": ["s0", "s1"], "r1": ["s0", "s1"], "r2": ["s1", "s2"], "r3": ["s1", "s2"]},
             [(0, "base", "r1", "m"), (0, "base", "r2", "m"), (0, "r2", "r3", "m")],
             reqs=[Requirement(("r3",), ("base",))])
    v = validate_plan(net, p, collision_robots={"r2", "r3"})
    assert {"static_moved", "collision", "unmet_requirement"} <= kinds(v)
    assert all(isinstance(x.message, str) and "\n" not in x.message for x in v)


def test_receiving_earlier_in_the_same_step_counts(net):
    # a chain within one step (no cycle): base -> r2 -> r3, then r3 moves
    p = plan({"base": ["s0", "s0"], "r1": ["s0", "s0"], "r2": ["s1", "s1"], "r3": ["s1", "s2"]},
             [(0, "r2", "r3", "m"), (0, "base", "r2", "m")])
    assert validate_plan(net, p) == []
