"""GBPlanner: local and global layers per iteration."""
import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.planner import GBPlanner

CFG = GBPlannerConfig.anymal_c(num_vertices_max=200, num_edges_max=3000)


@pytest.fixture(scope="module")
def tunnel():
    g, a, _b = s.straight_tunnel(length_m=50, mapped_to_m=30)
    return g, a


def test_explores_toward_unknown_space(tunnel):
    g, a = tunnel
    home = a + np.array([2.0, 0, 0.5])
    planner = GBPlanner(CFG, home)
    res = planner.plan(g, a + np.array([12.0, 0, 0.5]), np.random.default_rng(0), endurance_remaining_s=3000.0)
    assert res.mode == "explore" and res.ok
    assert res.path[-1][0] > res.path[0][0] + 5
    assert res.homing is not None and not res.homing.required
    assert planner.exploring_direction_rad is not None


def test_repositions_when_local_gain_stays_low(tunnel):
    g, a = tunnel
    home = a + np.array([2.0, 0, 0.5])
    cfg = CFG.replace(low_gain_threshold_m3=1e12, low_gain_iterations_max=3)  # every gain is "low"
    planner = GBPlanner(cfg, home)
    p = a + np.array([12.0, 0, 0.5])
    modes = [planner.plan(g, p, np.random.default_rng(i)).mode for i in range(3)]
    assert modes == ["explore", "explore", "reposition"]


def test_homes_when_endurance_is_short(tunnel):
    g, a = tunnel
    home = a + np.array([2.0, 0, 0.5])
    planner = GBPlanner(CFG, home)
    p = a + np.array([14.0, 0, 0.5])
    planner.plan(g, a + np.array([8.0, 0, 0.5]), np.random.default_rng(0), endurance_remaining_s=3000.0)
    res = planner.plan(g, p, np.random.default_rng(1), endurance_remaining_s=30.0)
    assert res.mode == "homing" and res.ok
    assert np.allclose(res.path[-1], home)
    assert res.homing.required


def test_no_gain_and_no_frontier_means_exploration_complete():
    g, a, _b = s.straight_tunnel(length_m=24)  # fully mapped
    planner = GBPlanner(CFG, a + np.array([2.0, 0, 0.5]))
    res = planner.plan(g, a + np.array([8.0, 0, 0.5]), np.random.default_rng(0))
    assert res.path is None and res.mode == "none"
    assert res.exploration_complete and res.reason


def test_goto_and_home_requests(tunnel):
    g, a = tunnel
    home = a + np.array([2.0, 0, 0.5])
    planner = GBPlanner(CFG, home)
    p = a + np.array([10.0, 0, 0.5])
    planner.plan(g, p, np.random.default_rng(0))
    goal = planner.goto(g, p, a + np.array([6.0, 1.0, 0.5]))
    assert goal.mode == "goal" and goal.ok
    back = planner.home(g, p)
    assert back.mode == "homing" and np.allclose(back.path[-1], home)
    bad = planner.goto(g, p, np.array([np.inf, 0, 0]))
    assert not bad.ok and bad.reason


def test_low_gain_with_no_frontier_left_completes_the_exploration():
    g, a, _b = s.straight_tunnel(length_m=40, mapped_to_m=38)  # almost all mapped
    cfg = CFG.replace(low_gain_threshold_m3=1e12, low_gain_iterations_max=2, frontier_gain_min_m3=1e12)
    planner = GBPlanner(cfg, a + np.array([2.0, 0, 0.5]))
    p = a + np.array([8.0, 0, 0.5])
    first = planner.plan(g, p, np.random.default_rng(0))
    assert first.mode == "explore"
    second = planner.plan(g, p, np.random.default_rng(1))
    assert second.mode == "none" and second.exploration_complete
    assert "exploration complete" in second.reason
