"""delve.planners.cops.greedy: greedy information-consistent plans."""
from delve.planners.cops.greedy import greedy_post_plan, greedy_pre_plan

from .cops_networks import fork, team


def test_the_greedy_pre_plan_sends_robots_holding_m_to_the_best_frontier_slots():
    net = fork(team(3))
    traj = greedy_pre_plan(net, net.positions(), {"base"}, {"base"}, {"r1", "r2", "r3"},
                           {"a3": (50.0, 25.0), "b3": (50.0, 25.0)})
    assert len({len(tr) for tr in traj.values()}) == 1, "trajectories of equal length"
    assert all(traj[r][0] == "s0" for r in traj) and set(traj["base"]) == {"s0"}
    assert sorted(traj[r][-1] for r in ("r1", "r2", "r3")) == ["a3", "a3", "b3"]


def test_the_greedy_post_plan_sends_an_idle_robot_to_relay_rather_than_carrying_all_the_way():
    net = fork(team(3))
    pos = {"base": "s0", "r1": "a3", "r2": "b3", "r3": "s0"}
    traj = greedy_post_plan(net, pos, {"base", "r1", "r2", "r3"}, {"base"}, ["r1", "r2"], "base")
    assert len({len(tr) for tr in traj.values()}) == 1 and set(traj["base"]) == {"s0"}
    # r3 relays at s1; the sources walk only into radio range of it
    assert {r: tr[-1] for r, tr in traj.items()} == {"base": "s0", "r1": "a1", "r2": "b1", "r3": "s1"}
