"""Frontier selection (Williams et al., Section IV): the UGV's reward per unit distance
with the failure penalty (equation 15, Algorithm 3) and the UAV's size, distance and
momentum reward (equation 16).
"""
from __future__ import annotations

from collections import deque
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .frontier_types import Frontier
from .selection_params import CsiroSelectionParams
from .sharing import FrontierKey, FrontierSummary, discounted_rewards

#: Equation 16's estimate of a frontier's smallest dimension from its covariance:
#: EIGEN_SPAN * sqrt(EIGEN_SCALE * lambda_2).
EIGEN_SPAN, EIGEN_SCALE = 2.0, 5.0


class GoalProgress:
    """Progress towards one goal (Algorithm 3): navigation has failed once the closest
    approach to ``goal`` improved by less than ``progress_m`` over ``progress_window_s``.
    Feed it ``update(t_s, position)`` at increasing times; failure is final.

    The approach is the distance still to go: along the path the robot follows when the caller
    gives it (``distance_m``), else the straight line to ``goal``. Not the straight line alone: the
    way to a frontier in another drift first leads away from it, and that is progress too."""

    def __init__(self, goal: np.ndarray, params: CsiroSelectionParams):
        self.goal = np.asarray(goal, float)
        self.progress_m, self.window_s = params.progress_m, params.progress_window_s
        self.closest_m = float("inf")
        self.failed = False
        self._samples: deque[tuple[float, float]] = deque()  # (t_s, closest approach then)

    def update(self, t_s: float, position: np.ndarray, distance_m: float | None = None) -> bool:
        """Record the robot at ``position`` at time ``t_s``, ``distance_m`` from the goal along its
        path (default: the straight line); whether navigation has failed."""
        to_go = float(np.linalg.norm(np.asarray(position, float) - self.goal)) if distance_m is None else distance_m
        self.closest_m = min(self.closest_m, float(to_go))
        self._samples.append((t_s, self.closest_m))
        while len(self._samples) > 1 and self._samples[1][0] <= t_s - self.window_s:
            self._samples.popleft()  # keep one sample at or before the window's start
        start_s, closest_then = self._samples[0]
        if t_s - start_s >= self.window_s and closest_then - self.closest_m < self.progress_m:
            self.failed = True
        return self.failed


class FailedFrontiers:
    """Frontiers whose navigation failed: each keeps the penalty rho_fail until its owner
    updates it (Algorithm 3), and its observer stays a failed goal of equation 14's L."""

    def __init__(self) -> None:
        self._updated_s: dict[FrontierKey, float] = {}
        self._goals: list[np.ndarray] = []

    def mark(self, summary: FrontierSummary) -> None:
        """Navigation to ``summary``'s observer failed."""
        self._updated_s[summary.key] = summary.updated_s
        self._goals.append(np.asarray(summary.observer, float).copy())

    def penalised(self, summary: FrontierSummary) -> bool:
        """Whether ``summary`` failed and has not been updated since."""
        failed_at = self._updated_s.get(summary.key)
        return failed_at is not None and summary.updated_s <= failed_at

    @property
    def goals(self) -> np.ndarray:
        """(n, 3) the observers of every failed goal."""
        return np.array(self._goals, dtype=float).reshape(-1, 3)


@dataclass(frozen=True)
class UgvChoice:
    """The UGV's selected frontier: its key, utility u (equation 15), discounted (and
    penalised) reward and distance (m)."""

    key: FrontierKey
    utility: float
    reward: float
    distance_m: float


def ugv_utilities(summaries: Sequence[FrontierSummary], distances_m: Sequence[float], places: np.ndarray,
                  failed: FailedFrontiers, params: CsiroSelectionParams) -> tuple[np.ndarray, np.ndarray]:
    """(utility, reward) per summary: r~_f of equation 14 over ``places`` (L), times rho_fail
    for a failed frontier not updated since (Algorithm 3), per unit of ``distances_m`` (path
    distances from the agent to each observer, at least ``ugv_min_distance_m``; inf when
    unreachable) (equation 15)."""
    rewards = np.array([s.reward for s in summaries], dtype=float)
    observers = np.array([s.observer for s in summaries], dtype=float).reshape(-1, 3)
    reward = discounted_rewards(rewards, observers, places, params)
    reward *= np.where([failed.penalised(s) for s in summaries], params.rho_fail, 1.0)
    distance = np.maximum(np.asarray(distances_m, float), params.ugv_min_distance_m)
    return reward / distance, reward


def select_ugv_frontier(summaries: Sequence[FrontierSummary], distances_m: Sequence[float],
                        places: np.ndarray, params: CsiroSelectionParams, *,
                        held_by_others: Collection[FrontierKey] = (),
                        failed: FailedFrontiers | None = None) -> UgvChoice | None:
    """Algorithm 3: the frontier of highest utility (equation 15) among ``summaries`` that no
    other robot holds (``held_by_others``) and that can be reached (finite distance, positive
    utility); equal utilities go to the smaller key. None when there is none."""
    if len(summaries) != len(distances_m):
        raise ValueError(f"{len(summaries)} summaries but {len(distances_m)} distances")
    utility, reward = ugv_utilities(summaries, distances_m, places, failed or FailedFrontiers(), params)
    held = set(held_by_others)
    ok = [i for i, s in enumerate(summaries) if s.key not in held and np.isfinite(utility[i]) and utility[i] > 0]
    if not ok:
        return None
    best = min(ok, key=lambda i: (-utility[i], summaries[i].key))
    return UgvChoice(key=summaries[best].key, utility=float(utility[best]), reward=float(reward[best]),
                     distance_m=float(distances_m[best]))


def weighted_distance(a: np.ndarray, b: np.ndarray, z_weight: float) -> np.ndarray:
    """d_w: the distance from ``a`` to ``b`` (each (3,) or (n, 3)) with the z component
    multiplied by ``z_weight``."""
    d = np.asarray(b, float) - np.asarray(a, float)
    return np.linalg.norm(d * np.array([1.0, 1.0, z_weight]), axis=-1)


@dataclass(frozen=True)
class UavMomentum:
    """The UAV's current frontier id and the unit vector v' from the UAV to it when it was
    first selected."""

    frontier_id: int
    direction: np.ndarray


def uav_frontier_size_m(frontier: Frontier, params: CsiroSelectionParams) -> float:
    """min{2 sqrt(5 lambda_2), sqrt(A_f), eta_size}: the frontier's smallest dimension, at most
    ``uav_max_size_m`` (lambda_2: the second-largest eigenvalue of its covariance)."""
    lambda_2 = float(np.linalg.eigvalsh(np.asarray(frontier.cov, float))[1])
    return min(EIGEN_SPAN * np.sqrt(EIGEN_SCALE * max(lambda_2, 0.0)), np.sqrt(frontier.area), params.uav_max_size_m)


def uav_frontier_complete(frontier: Frontier, agent_position: np.ndarray, params: CsiroSelectionParams) -> bool:
    """Whether the UAV at ``agent_position`` is within ``uav_blacklist_m`` of the frontier's centre."""
    return bool(np.linalg.norm(np.asarray(frontier.mean, float) - agent_position) <= params.uav_blacklist_m)


class UavBlacklist:
    """The frontiers a UAV completed or gave up on (Section IV-B), each as it was then.

    The UAV blacklists a frontier it made no progress towards in 15 s by "the same criterion" as
    the ground robot's failure penalty (Algorithm 3), which is cleared when the frontier is
    updated; a frontier it reached within eta_blacklist of its centre is complete. Algorithm 2
    keeps a frontier's id while it changes (the opening of a side passage the UAV flew past, the
    head of a tunnel), so an entry holds while the frontier of that id is the version blacklisted:
    updated, it is a new frontier to select (or to skip while the UAV is within eta_blacklist of
    its centre)."""

    def __init__(self) -> None:
        self._versions: dict[int, Frontier] = {}

    def add(self, frontier: Frontier) -> None:
        """Blacklist ``frontier`` as it is now."""
        self._versions[int(frontier.id)] = frontier

    def holds(self, frontier: Frontier) -> bool:
        """Whether ``frontier`` is blacklisted: the version of its id that was blacklisted."""
        return self._versions.get(int(frontier.id)) is frontier

    def ids(self, frontiers: Sequence[Frontier]) -> list[int]:
        """The ids of ``frontiers`` blacklisted, sorted."""
        return sorted(int(f.id) for f in frontiers if self.holds(f))

    def __contains__(self, frontier_id: object) -> bool:
        """Whether an entry of ``frontier_id`` exists (whether or not that version is current)."""
        return frontier_id in self._versions

    def clear(self) -> None:
        self._versions.clear()


def uav_rewards(frontiers: Sequence[Frontier], agent_position: np.ndarray, momentum: UavMomentum | None,
                params: CsiroSelectionParams, path_m: Mapping[int, float] | None = None) -> np.ndarray:
    """(F,) equation 16: p_f * size_f^2 / max{eta_blacklist, d_w(o_f, a)} with o_f the frontier's
    mean and momentum p_f = s_f * w^(v . v'): s_f for the frontier selected last, v the unit
    vector to the frontier, v' that of ``momentum`` (p_f = 1 without one).

    Not in the paper: ``path_m`` (by frontier id) is the length of the way there; where it is
    longer than d_w it is the distance (a frontier 20 m away through rock and 200 m round by
    the tunnels is not near)."""
    path_m = path_m or {}
    agent = np.asarray(agent_position, float)
    out = np.zeros(len(frontiers))
    for i, f in enumerate(frontiers):
        centre = np.asarray(f.mean, float)
        momentum_gain = 1.0
        if momentum is not None:
            v = centre - agent
            v = v / max(float(np.linalg.norm(v)), np.finfo(float).tiny)
            same = params.uav_same_frontier_gain if f.id == momentum.frontier_id else 1.0
            momentum_gain = same * params.uav_momentum_weight ** float(v @ momentum.direction)
        distance = max(params.uav_blacklist_m, float(weighted_distance(agent, centre, params.uav_z_weight)),
                       path_m.get(f.id, 0.0))
        out[i] = momentum_gain * uav_frontier_size_m(f, params) ** 2 / distance
    return out


def rank_uav_frontiers(frontiers: Sequence[Frontier], agent_position: np.ndarray, momentum: UavMomentum | None,
                       params: CsiroSelectionParams, *, blacklist: Collection[int] = (),
                       path_m: Mapping[int, float] | None = None) -> list[tuple[Frontier, UavMomentum]]:
    """Every frontier of at least ``uav_min_area_m2``, not in ``blacklist`` and not already
    complete, by decreasing equation-16 reward (with the ways there ``path_m``, see
    :func:`uav_rewards`; equal rewards: the smaller id first), each with
    the momentum to pass next time if it is selected (the direction kept while the same frontier
    stays selected)."""
    agent = np.asarray(agent_position, float)
    banned = set(blacklist)
    ok = [f for f in frontiers if f.area >= params.uav_min_area_m2 and f.id not in banned
          and not uav_frontier_complete(f, agent, params)]
    rewards = uav_rewards(ok, agent, momentum, params, path_m)
    ranked = [ok[j] for j in sorted(range(len(ok)), key=lambda j: (-rewards[j], ok[j].id))]
    return [(f, _momentum_for(f, agent, momentum)) for f in ranked]


def _momentum_for(frontier: Frontier, agent: np.ndarray, momentum: UavMomentum | None) -> UavMomentum:
    if momentum is not None and momentum.frontier_id == frontier.id:
        return momentum
    v = np.asarray(frontier.mean, float) - agent
    return UavMomentum(frontier_id=frontier.id, direction=v / np.linalg.norm(v))


def select_uav_frontier(frontiers: Sequence[Frontier], agent_position: np.ndarray, momentum: UavMomentum | None,
                        params: CsiroSelectionParams, *, blacklist: Collection[int] = ()
                        ) -> tuple[Frontier, UavMomentum] | None:
    """The first of :func:`rank_uav_frontiers`: the frontier of highest equation-16 reward with
    its momentum; None when there is none."""
    ranked = rank_uav_frontiers(frontiers, agent_position, momentum, params, blacklist=blacklist)
    return ranked[0] if ranked else None


__all__ = ["EIGEN_SCALE", "EIGEN_SPAN", "FailedFrontiers", "GoalProgress", "UavBlacklist", "UavMomentum",
           "UgvChoice", "rank_uav_frontiers", "select_ugv_frontier", "select_uav_frontier", "uav_frontier_complete",
           "uav_frontier_size_m", "uav_rewards", "ugv_utilities", "weighted_distance"]
