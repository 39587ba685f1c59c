"""delve.planners.cops.ilp_constraints: the constraint families, seen in the plans they allow."""
from delve.planners.cops import Requirement, solve_connectivity, validate_plan
from delve.planners.cops.ilp_constraints import build_model

from .cops_networks import line, problem


def test_a_robot_without_m_waits_until_the_plan_reaches_it():
    # r2 stands at s2, out of radio range of the base; r1 must carry m to it first
    net = line(5, [{"name": "r1", "location": "s0", "explorer": False}, {"name": "r2", "location": "s2"}],
               comm=[["s0", "s1"]], frontiers=["s4"])
    p = problem(net, 4, location_rewards={"s4": (50.0,)}, frontiers={"s4"})
    plan = solve_connectivity(p)
    assert validate_plan(net, plan) == []
    assert plan.explore == {"r2": "s4"}
    got_m = min(c.t for c in plan.communications if c.receiver == "r2" and c.info == "m")
    first_move = next(t for t in range(plan.horizon) if plan.trajectories["r2"][t] != plan.trajectories["r2"][t + 1])
    assert got_m <= first_move
    assert got_m >= 1  # the plan could not reach r2 at t=0


def test_static_robots_stay_and_collision_robots_never_meet():
    net = line(4, [{"name": "r1", "location": "s0", "collision": True},
                   {"name": "r2", "location": "s0", "collision": True},
                   {"name": "relay", "location": "s1", "static": True, "explorer": False}],
               collision_locations=["s1", "s2"], frontiers=["s3"])
    p = problem(net, 6, location_rewards={"s3": (50.0, 40.0)}, frontiers={"s3"},
                collision_robots={"r1", "r2"}, collision_locations={"s1", "s2"})
    plan = solve_connectivity(p)
    assert validate_plan(net, plan, collision_robots={"r1", "r2"}) == []
    assert set(plan.trajectories["relay"]) == {"s1"}
    assert sorted(plan.explore) == ["r1", "r2"]
    for t in range(plan.horizon + 1):
        a, b = plan.trajectories["r1"][t], plan.trajectories["r2"][t]
        assert not (a == b and a in {"s1", "s2"})


def test_the_model_does_not_depend_on_the_order_the_network_was_built_in():
    robots = [{"name": "r1", "location": "s0"}, {"name": "r2", "location": "s3", "collision": True}]
    names = [f"s{i}" for i in range(5)]
    backwards = [[b, a] for a, b in zip(names, names[1:])][::-1]
    nets = [line(5, robots, frontiers=["s4"]),
            line(5, robots[::-1], comm=backwards, locations=names[::-1], mobility=backwards, frontiers=["s4"])]
    models = [build_model(problem(net, 5, location_rewards={"s4": (50.0, 25.0)}, frontiers={"s4"},
                                  requirements=[Requirement(("r2",), ("base",))],
                                  collision_robots={"r2"}, collision_locations={"s2"}))
              for net in nets]
    a, b = ([str(row) for row in m.rows] + [str(m.objective)] for m in models)
    assert len(a) > 10 and a == b
