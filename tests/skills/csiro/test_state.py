"""delve.skills.csiro.state: one CSIRO state per agent, from the team's configuration."""
from __future__ import annotations

import numpy as np
from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.sharing import FrontierSummary
from delve.skills.csiro import CONFIG_SERVICE, CsiroConfig, csiro_state

from ..fakes import FakeRobot, body, make_ctx


def test_state_is_made_once_from_the_config_with_the_lidar_s_elevations(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a)))
    ctx.services[CONFIG_SERVICE] = CsiroConfig(frontier=CsiroFrontierParams(d_max_m=7.0), explore_sync_s=60.0)
    st = csiro_state(ctx, view_up_deg=45.0)
    assert st is csiro_state(ctx, view_up_deg=10.0)
    assert st.frontier_params.d_max_m == 7.0
    assert (st.frontier_params.elevation_min_deg, st.frontier_params.elevation_max_deg) == (-45.0, 45.0)
    assert not st.frontier_params.blind_frontiers


def test_a_flying_robot_s_blind_cones_hold_frontiers(tunnel):
    grid, a, _ = tunnel
    st = csiro_state(make_ctx(FakeRobot(grid, body(a), platform="aerial")), view_up_deg=45.0)
    assert st.frontier_params.blind_frontiers


def test_places_of_equation_14_hold_trajectories_goals_and_failed_goals(tunnel):
    grid, a, _ = tunnel
    st = csiro_state(make_ctx(FakeRobot(grid, body(a))))
    st.trajectory.add(0.0, np.array([1.0, 0.0, 0.0]))
    st.places["r2"] = np.array([[2.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    st.goals["r2"] = (("r2", 1), np.array([4.0, 0.0, 0.0]))
    st.failed.mark(FrontierSummary(0, "r1", np.zeros(3), np.eye(3), 1.0, np.array([5.0, 0.0, 0.0]), 0.0))
    assert st.places_set("r1")[:, 0].tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]
