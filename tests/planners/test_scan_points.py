"""Unit tests for delve.planners.scan_points: minimum set cover of the unseen
workspace and the paper's full-scan threshold, on hand-made instances."""

import itertools

import numpy as np
import pytest

from delve.planners.scan_points import (AUTONOMOUS_FULL_SCAN, AUTONOMOUS_POINT_SCAN, _greedy_cover,
                                        minimum_set_cover, reachable_workspace, select_scan_points)

POSE = np.zeros(4)


def candidates(k):
    return np.stack([np.linspace(-120, 120, k), np.zeros(k)], axis=1)


def brute_force_min(a):
    for size in range(1, a.shape[1] + 1):
        for combo in itertools.combinations(range(a.shape[1]), size):
            if a[:, combo].any(axis=1).all():
                return size
    raise AssertionError("no cover")


def random_instance(rng, n, k, density):
    a = rng.random((n, k)) < density
    for i in np.flatnonzero(~a.any(axis=1)):
        a[i, rng.integers(k)] = True
    return a


def test_hand_made_instance_where_greedy_takes_three_and_the_optimum_two():
    # Points 0..13 in two rows of seven; each row is one scan (candidates 0, 1).
    # Candidates 2, 3, 4 see 8, 4 and 2 of the points across both rows: greedy takes
    # all three, the smallest cover is the two rows.
    sets = [set(range(7)), set(range(7, 14)), {0, 1, 2, 3, 7, 8, 9, 10}, {4, 5, 11, 12}, {6, 13}]
    vis = np.array([[i in s for s in sets] for i in range(14)])
    assert _greedy_cover(vis).tolist() == [2, 3, 4]
    sel = select_scan_points(np.zeros((14, 3)), POSE, candidates(5), vis, 14)
    assert sel.solver == "cbc" and sel.optimal
    assert sel.candidate_indices.tolist() == [0, 1] and brute_force_min(vis) == 2
    np.testing.assert_allclose(sel.scan_points, candidates(5)[[0, 1]])
    assert sel.covered.all() and sel.covered_fraction == 1.0


@pytest.mark.parametrize("seed", range(8))
def test_exact_cover_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    a = random_instance(rng, n=int(rng.integers(8, 25)), k=int(rng.integers(5, 11)), density=0.25)
    chosen, solver, optimal = minimum_set_cover(a)
    assert a[:, chosen].any(axis=1).all()
    assert optimal and len(chosen) == brute_force_min(a), (solver, chosen)


@pytest.mark.parametrize("seed", range(5))
def test_greedy_gives_a_valid_cover_no_smaller_than_the_optimum(seed):
    rng = np.random.default_rng(100 + seed)
    a = random_instance(rng, n=20, k=9, density=0.2)
    chosen, solver, _ = minimum_set_cover(a, exact_max_size=0)
    assert solver == "greedy" and a[:, chosen].any(axis=1).all()
    assert len(chosen) >= brute_force_min(a)
    # no chosen scan is redundant
    for j in chosen:
        rest = [c for c in chosen if c != j]
        assert not a[:, rest].any(axis=1).all()


def test_full_scan_threshold_is_more_than_half_the_reachable_workspace():
    vis = np.eye(6, dtype=bool)
    over = select_scan_points(np.zeros((6, 3)), POSE, candidates(6), vis, 10)
    assert over.full_scan and over.mode == AUTONOMOUS_FULL_SCAN and over.unseen_fraction == pytest.approx(0.6)
    half = select_scan_points(np.zeros((5, 3)), POSE, candidates(5), np.eye(5, dtype=bool), 10)
    assert not half.full_scan and half.mode == AUTONOMOUS_POINT_SCAN
    custom = select_scan_points(np.zeros((5, 3)), POSE, candidates(5), np.eye(5, dtype=bool), 10,
                                full_scan_fraction=0.3)
    assert custom.full_scan


def test_points_no_candidate_sees_are_left_uncovered():
    vis = np.array([[True, False], [False, True], [False, False], [True, True]])
    sel = select_scan_points(np.zeros((4, 3)), POSE, candidates(2), vis, 3)
    assert sel.covered.tolist() == [True, True, False, True]
    assert sel.covered_fraction == 0.75 and sel.coverable_fraction == 0.75
    assert sel.unseen_fraction == 1.0 and sel.full_scan


def test_nothing_unseen_means_nothing_to_scan():
    sel = select_scan_points(np.zeros((0, 3)), POSE, candidates(4), np.zeros((0, 4), bool), 50)
    assert sel.n_scan_points == 0 and sel.covered_fraction == 1.0 and not sel.full_scan
    assert sel.mode == "" and sel.solver == "none"
    blind = select_scan_points(np.zeros((3, 3)), POSE, candidates(4), np.zeros((3, 4), bool), 50)
    assert blind.n_scan_points == 0 and blind.covered_fraction == 0.0 and not blind.full_scan


def test_visibility_function_gets_points_pose_and_candidates():
    pts = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    cand = np.array([[0.0, 0.0], [90.0, 0.0], [180.0, 0.0], [45.0, 0.0]])
    calls = []

    def vis(points, pose, c):
        calls.append(pose)
        bearing = np.degrees(np.arctan2(points[:, 1], points[:, 0]))
        diff = np.abs((bearing[:, None] - c[None, :, 0] + 180) % 360 - 180)
        return diff <= 50

    ws = reachable_workspace(pts, POSE, cand, vis)
    sel = select_scan_points(pts, POSE, cand, vis, int(ws.sum()))
    assert calls and calls[-1] is POSE
    assert sel.n_scan_points == 2 and sel.covered.all()
    assert sel.scan_points[:, 0].tolist() == sorted(sel.scan_points[:, 0].tolist())


def test_bad_inputs():
    vis = np.eye(3, dtype=bool)
    with pytest.raises(ValueError, match="visibility must be"):
        select_scan_points(np.zeros((3, 3)), POSE, candidates(4), vis, 3)
    with pytest.raises(ValueError, match="reachable_workspace_size"):
        select_scan_points(np.zeros((3, 3)), POSE, candidates(3), vis, 2)
    with pytest.raises(ValueError, match="full_scan_fraction"):
        select_scan_points(np.zeros((3, 3)), POSE, candidates(3), vis, 3, full_scan_fraction=1.5)


def test_paper_sized_instance_is_fast_and_covers():
    """1170 candidates on a 90 x 13 grid, each seeing a 60° x 36° window of bearings,
    and 3000 unseen points: reduced, solved (or greedy within the limit), covered."""
    rng = np.random.default_rng(0)
    yaw, pitch = np.meshgrid(-133.5 + 3 * np.arange(90), -8 + 3 * np.arange(13), indexing="ij")
    cand = np.stack([yaw.ravel(), pitch.ravel()], axis=1)
    bearings = np.stack([rng.uniform(-160, 160, 3000), rng.uniform(-25, 45, 3000)], axis=1)
    vis = ((np.abs(bearings[:, None, 0] - cand[None, :, 0]) <= 30)
           & (np.abs(bearings[:, None, 1] - cand[None, :, 1]) <= 18))
    sel = select_scan_points(np.zeros((3000, 3)), POSE, cand, vis, 5000, node_limit=2000)
    assert sel.covered_fraction == 1.0 and sel.full_scan and sel.solver in ("cbc", "greedy")
    assert 10 <= sel.n_scan_points <= 20
