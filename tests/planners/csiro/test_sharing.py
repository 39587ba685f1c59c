"""delve.planners.csiro.sharing: frontier summaries, trajectory points, equation 14."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.csiro.frontier_types import Frontier
from delve.planners.csiro.observer import Observer
from delve.planners.csiro.selection_params import CsiroSelectionParams
from delve.planners.csiro.sharing import (
    FrontierSummary,
    TrajectoryPoints,
    discount_factor,
    discount_places,
    discounted_rewards,
    summarise,
)

P = CsiroSelectionParams()


def test_discount_is_rho_at_zero_and_one_at_eta_d():
    assert discount_factor(0.0, P.rho, P.eta_d_m) == pytest.approx(0.2)
    assert discount_factor(P.eta_d_m, P.rho, P.eta_d_m) == pytest.approx(1.0)
    assert discount_factor(2 * P.eta_d_m, P.rho, P.eta_d_m) == 1.0
    r = np.linspace(0.0, P.eta_d_m, 13)
    d = discount_factor(r, P.rho, P.eta_d_m)
    assert np.all(np.diff(d) > 0)
    assert d[6] == pytest.approx(0.2 + 0.8 * 0.5)  # sin^2(pi / 4) at half of eta_d


def test_discounted_reward_is_the_product_over_places_within_eta_d():
    observers = np.array([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
    rewards = np.array([10.0, 10.0])
    places = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 7.0, 0.0]])
    out = discounted_rewards(rewards, observers, places, P)
    assert out[0] == pytest.approx(10.0 * 0.2 * (0.2 + 0.8 * 0.5))  # the place 7 m away does not count
    assert out[1] == 10.0
    assert np.array_equal(discounted_rewards(rewards, observers, np.zeros((0, 3)), P), rewards)


def test_discount_places_joins_trajectories_and_goals():
    places = discount_places(np.zeros((2, 3)), np.ones(3), np.zeros((0, 3)))
    assert places.shape == (3, 3) and np.array_equal(places[2], np.ones(3))
    assert discount_places().shape == (0, 3)


def test_trajectory_keeps_a_point_every_period():
    trail = TrajectoryPoints(P)
    kept = [trail.add(t, np.array([t, 0.0, 0.0])) for t in np.arange(0.0, 12.0, 1.0)]
    assert [t for t, k in zip(range(12), kept) if k] == [0, 5, 10]
    assert np.array_equal(trail.points()[:, 0], [0.0, 5.0, 10.0])
    assert np.array_equal(trail.points(2), [[10.0, 0.0, 0.0]])
    assert len(trail) == 3


def test_a_visited_place_is_kept_whatever_the_period():
    trail = TrajectoryPoints(P)
    trail.add(0.0, np.zeros(3))
    trail.visit(np.array([2.0, 0.0, 0.0]))
    assert not trail.add(1.0, np.ones(3))                      # the period still counts from t = 0
    assert np.array_equal(trail.points(), [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])


def test_summary_round_trips_through_a_message():
    frontier = Frontier(id=7, points=np.zeros((1, 3)), normals=np.array([[1.0, 0, 0]]), areas=np.ones(1),
                        mean=np.array([1.0, 2.0, 3.0]), cov=np.eye(3))
    summary = summarise(frontier, "ugv1", Observer(np.array([0.0, 2.0, 0.0]), 12.5, 3), updated_s=40.0)
    assert summary.key == ("ugv1", 7) and summary.reward == 12.5
    back = FrontierSummary.from_message(summary.to_message())
    assert back.key == summary.key and back.reward == summary.reward and back.updated_s == 40.0
    for name in ("mean", "cov", "observer"):
        assert np.array_equal(getattr(back, name), getattr(summary, name))
