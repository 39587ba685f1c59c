"""delve.planners.csiro.selection: UGV equation 15 with Algorithm 3, UAV equation 16."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.csiro.frontier_types import Frontier
from delve.planners.csiro.selection import (
    FailedFrontiers,
    GoalProgress,
    UavBlacklist,
    UavMomentum,
    rank_uav_frontiers,
    select_uav_frontier,
    select_ugv_frontier,
    uav_frontier_size_m,
    uav_rewards,
    ugv_utilities,
    weighted_distance,
)
from delve.planners.csiro.selection_params import CsiroSelectionParams
from delve.planners.csiro.sharing import FrontierSummary

P = CsiroSelectionParams()
NO_PLACES = np.zeros((0, 3))


def summary(owner: str, id: int, reward: float, observer, updated_s: float = 0.0) -> FrontierSummary:
    return FrontierSummary(id=id, owner=owner, mean=np.asarray(observer, float), cov=np.eye(3), reward=reward,
                           observer=np.asarray(observer, float), updated_s=updated_s)


def frontier(id: int, mean, area: float = 4.0, spread: float = 1.0) -> Frontier:
    return Frontier(id=id, points=np.asarray([mean], float), normals=np.array([[1.0, 0.0, 0.0]]),
                    areas=np.array([area]), mean=np.asarray(mean, float), cov=np.diag([spread, spread, 0.01]))


# -- progress and failure ---------------------------------------------------------

def test_failure_after_15_s_without_1_m_progress_and_not_before():
    progress = GoalProgress(np.array([20.0, 0.0, 0.0]), P)
    for t in np.arange(0.0, 15.0, 0.5):
        assert not progress.update(t, np.array([0.3 * t / 15.0, 0.0, 0.0]))  # 0.3 m in 15 s
    assert progress.update(15.0, np.array([0.3, 0.0, 0.0]))
    assert progress.failed and progress.update(16.0, np.array([19.0, 0.0, 0.0]))  # failure is final


def test_no_failure_while_the_robot_makes_1_m_in_every_15_s():
    progress = GoalProgress(np.array([100.0, 0.0, 0.0]), P)
    assert not any(progress.update(t, np.array([0.1 * t, 0.0, 0.0])) for t in np.arange(0.0, 120.0, 0.5))
    assert progress.closest_m == pytest.approx(100.0 - 11.95)


def test_failure_once_progress_stops_later():
    progress = GoalProgress(np.array([100.0, 0.0, 0.0]), P)
    times = np.arange(0.0, 60.0, 0.5)
    failed = [progress.update(t, np.array([min(t, 20.0), 0.0, 0.0])) for t in times]  # stops at 20 s
    first = times[failed.index(True)]
    assert 34.0 <= first <= 35.0


def test_moving_away_is_no_progress():
    progress = GoalProgress(np.zeros(3), P)
    assert not progress.update(0.0, np.array([5.0, 0.0, 0.0]))
    assert progress.update(15.0, np.array([50.0, 0.0, 0.0]))


def test_the_distance_along_the_path_counts_though_the_robot_moves_away():
    progress = GoalProgress(np.array([0.0, 10.0, 0.0]), P)     # the goal in the next drift, 10 m across
    for t in np.arange(0.0, 40.0, 0.5):                       # 1 m/s away from it, then back along the next
        assert not progress.update(t, np.array([t, 0.0, 0.0]), distance_m=60.0 - t)
    assert progress.closest_m == pytest.approx(60.0 - 39.5)


def test_failure_penalty_lasts_until_the_frontier_is_updated():
    failed = FailedFrontiers()
    s = summary("ugv1", 1, 10.0, [10.0, 0.0, 0.0], updated_s=5.0)
    (u_before,), _ = ugv_utilities([s], [10.0], NO_PLACES, failed, P)
    failed.mark(s)
    assert failed.penalised(s)
    (u_after,), (r_after,) = ugv_utilities([s], [10.0], NO_PLACES, failed, P)
    assert u_after == pytest.approx(u_before * P.rho_fail) and r_after == pytest.approx(10.0 * P.rho_fail)
    updated = summary("ugv1", 1, 10.0, [10.0, 0.0, 0.0], updated_s=6.0)
    assert not failed.penalised(updated)
    assert np.array_equal(failed.goals, [[10.0, 0.0, 0.0]])


# -- UGV selection ---------------------------------------------------------------

def test_ugv_selects_the_highest_reward_per_unit_distance():
    far_big = summary("ugv1", 1, 10.0, [10.0, 0.0, 0.0])
    near_small = summary("ugv1", 2, 6.0, [3.0, 0.0, 0.0])
    choice = select_ugv_frontier([far_big, near_small], [10.0, 3.0], NO_PLACES, P)
    assert choice.key == ("ugv1", 2) and choice.utility == pytest.approx(2.0) and choice.distance_m == 3.0


def test_a_frontier_held_by_another_robot_is_not_chosen():
    mine = summary("ugv1", 1, 1.0, [10.0, 0.0, 0.0])
    theirs = summary("ugv2", 4, 100.0, [10.0, 5.0, 0.0])
    assert select_ugv_frontier([mine, theirs], [10.0, 10.0], NO_PLACES, P).key == ("ugv2", 4)
    choice = select_ugv_frontier([mine, theirs], [10.0, 10.0], NO_PLACES, P, held_by_others=[("ugv2", 4)])
    assert choice.key == ("ugv1", 1)
    assert select_ugv_frontier([theirs], [10.0], NO_PLACES, P, held_by_others={("ugv2", 4)}) is None


def test_visited_places_and_failures_steer_the_choice():
    a = summary("ugv1", 1, 10.0, [10.0, 0.0, 0.0])
    b = summary("ugv1", 2, 8.0, [-10.0, 0.0, 0.0])
    assert select_ugv_frontier([a, b], [10.0, 10.0], NO_PLACES, P).key == ("ugv1", 1)
    visited = np.array([[10.0, 1.0, 0.0]])  # someone walked past a's observer
    assert select_ugv_frontier([a, b], [10.0, 10.0], visited, P).key == ("ugv1", 2)
    failed = FailedFrontiers()
    failed.mark(a)
    assert select_ugv_frontier([a, b], [10.0, 10.0], NO_PLACES, P, failed=failed).key == ("ugv1", 2)


def test_unreachable_and_worthless_frontiers_are_not_chosen():
    a = summary("ugv1", 1, 10.0, [10.0, 0.0, 0.0])
    b = summary("ugv1", 2, 0.0, [5.0, 0.0, 0.0])
    assert select_ugv_frontier([a, b], [np.inf, 5.0], NO_PLACES, P) is None
    assert select_ugv_frontier([], [], NO_PLACES, P) is None
    with pytest.raises(ValueError):
        select_ugv_frontier([a], [], NO_PLACES, P)


def test_ugv_choice_is_deterministic_whatever_the_order():
    a = summary("ugv2", 1, 10.0, [10.0, 0.0, 0.0])
    b = summary("ugv1", 3, 10.0, [0.0, 10.0, 0.0])
    c = summary("ugv1", 2, 5.0, [0.0, -5.0, 0.0])
    picks = {select_ugv_frontier(s, [10.0 if x.reward == 10 else 5.0 for x in s], NO_PLACES, P).key
             for s in ([a, b, c], [c, b, a], [b, c, a])}
    assert picks == {("ugv1", 2)}  # all three tie at 1.0: the smallest key


# -- UAV selection ---------------------------------------------------------------

def test_weighted_distance_doubles_z():
    assert weighted_distance(np.zeros(3), np.array([3.0, 0.0, 2.0]), 2.0) == pytest.approx(5.0)


def test_uav_size_term_is_the_smallest_dimension_capped():
    assert uav_frontier_size_m(frontier(1, [0, 0, 0], area=4.0, spread=1.0), P) == pytest.approx(2.0)  # sqrt(A)
    thin = frontier(1, [0, 0, 0], area=100.0, spread=0.05)
    assert uav_frontier_size_m(thin, P) == pytest.approx(2.0 * np.sqrt(5.0 * 0.05))
    assert uav_frontier_size_m(frontier(1, [0, 0, 0], area=400.0, spread=100.0), P) == P.uav_max_size_m


def test_uav_prefers_frontiers_level_with_it():
    level = frontier(1, [10.0, 0.0, 0.0])
    above = frontier(2, [0.0, 8.0, 6.0])  # nearer in 3D, but 2 z makes it 14.4 m away
    assert select_uav_frontier([level, above], np.zeros(3), None, P)[0].id == 1


def test_uav_skips_small_blacklisted_and_complete_frontiers():
    small = frontier(1, [5.0, 0.0, 0.0], area=1.0)
    near = frontier(2, [2.0, 0.0, 0.0])  # within the blacklist radius: complete
    banned = frontier(3, [6.0, 0.0, 0.0])
    ok = frontier(4, [30.0, 0.0, 0.0])
    assert select_uav_frontier([small, near, banned, ok], np.zeros(3), None, P, blacklist=[3])[0].id == 4
    assert select_uav_frontier([small, near], np.zeros(3), None, P) is None


def test_uav_blacklist_holds_until_the_frontier_is_updated():
    blacklist = UavBlacklist()
    done = frontier(7, [10.0, 0.0, 0.0])
    blacklist.add(done)
    assert blacklist.holds(done) and blacklist.ids([done, frontier(8, [10.0, 0.0, 0.0])]) == [7]
    updated = frontier(7, [10.5, 1.0, 0.0])                              # same id, a new version (Algorithm 2)
    assert not blacklist.holds(updated) and blacklist.ids([updated]) == [] and 7 in blacklist
    assert select_uav_frontier([updated], np.zeros(3), None, P, blacklist=blacklist.ids([updated]))[0].id == 7


def test_uav_ranking_is_by_reward_then_id_and_its_first_is_the_selection():
    fs = [frontier(5, [30.0, 0.0, 0.0]), frontier(2, [10.0, 0.0, 0.0]), frontier(3, [-10.0, 0.0, 0.0]),
          frontier(4, [2.0, 0.0, 0.0]), frontier(6, [8.0, 0.0, 0.0], area=1.0), frontier(7, [12.0, 0.0, 0.0])]
    ranked = rank_uav_frontiers(fs, np.zeros(3), None, P, blacklist=[7])
    assert [f.id for f, _ in ranked] == [2, 3, 5]           # 4 complete, 6 too small, 7 blacklisted; 2 = 3 by reward
    assert all(m.frontier_id == f.id for f, m in ranked)
    assert select_uav_frontier(fs, np.zeros(3), None, P, blacklist=[7])[0] is ranked[0][0]


def test_uav_distance_is_at_least_the_blacklist_radius():
    r = uav_rewards([frontier(1, [3.0, 0.0, 0.0]), frontier(2, [3.5, 0.0, 0.0])], np.zeros(3), None, P)
    assert r[0] == pytest.approx(4.0 / 3.0) and r[1] == pytest.approx(4.0 / 3.5)


def test_uav_distance_is_the_way_there_where_it_is_longer_than_the_line():
    near, far = frontier(1, [10.0, 0.0, 0.0]), frontier(2, [-20.0, 0.0, 0.0])
    assert select_uav_frontier([near, far], np.zeros(3), None, P)[0].id == 1
    ways = {1: 100.0, 2: 20.0}                                # 10 m through rock, 100 m round by the tunnels
    r = uav_rewards([near, far], np.zeros(3), None, P, path_m=ways)
    assert r[0] == pytest.approx(4.0 / 100.0) and r[1] == pytest.approx(4.0 / 20.0)
    assert [f.id for f, _ in rank_uav_frontiers([near, far], np.zeros(3), None, P, path_m=ways)] == [2, 1]
    assert uav_rewards([near], np.zeros(3), None, P, path_m={1: 5.0})[0] == pytest.approx(4.0 / 10.0)  # never shorter


def test_uav_momentum_keeps_the_current_frontier_and_direction():
    ahead = frontier(1, [20.0, 0.0, 0.0])
    behind = frontier(2, [-10.0, 0.0, 0.0])
    _, momentum = select_uav_frontier([ahead], np.zeros(3), None, P)
    assert momentum.frontier_id == 1 and np.allclose(momentum.direction, [1, 0, 0])
    assert select_uav_frontier([ahead, behind], np.zeros(3), None, P)[0].id == 2  # without momentum: nearer
    chosen, kept = select_uav_frontier([ahead, behind], np.zeros(3), momentum, P)
    assert chosen.id == 1 and kept is momentum
    r = uav_rewards([ahead, behind], np.zeros(3), momentum, P)
    assert r[0] == pytest.approx(4.0 * 2.0 * 4.0 / 20.0) and r[1] == pytest.approx(0.5 * 4.0 / 10.0)
    other = UavMomentum(frontier_id=9, direction=np.array([-1.0, 0.0, 0.0]))
    _, new = select_uav_frontier([ahead, behind], np.array([1.0, 0.0, 0.0]), other, P)
    assert new.frontier_id == 2 and np.allclose(new.direction, [-1, 0, 0])
