"""Multi-agent frontiers (Williams et al., Section III-D): frontier summaries that robots
share, the trajectory points they keep, and the discount of equation 14.

A summary is the mean and covariance of a frontier, its reward and its observer position;
a frontier is known team-wide by its key (owner robot, id). The set L of equation 14 holds
every robot's trajectory points, the other robots' current goals and the failed goals.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from .frontier_types import Frontier
from .observer import Observer
from .selection_params import CsiroSelectionParams

FrontierKey = tuple[str, int]
"""A frontier team-wide: (owner robot, the owner's frontier id)."""


@dataclass(frozen=True)
class FrontierSummary:
    """What robots share of one frontier: its Gaussian (``mean`` (3,), ``cov`` (3, 3)),
    reward r_f and observer position o_f (equation 13), and the time (s) the owner last
    updated it (a failure penalty lasts until the frontier is updated)."""

    id: int
    owner: str
    mean: np.ndarray
    cov: np.ndarray
    reward: float
    observer: np.ndarray
    updated_s: float

    @property
    def key(self) -> FrontierKey:
        return (self.owner, self.id)

    def to_message(self) -> dict[str, Any]:
        """The summary as plain data for a radio message."""
        return {"id": self.id, "owner": self.owner, "mean": self.mean.tolist(), "cov": self.cov.tolist(),
                "reward": self.reward, "observer": self.observer.tolist(), "updated_s": self.updated_s}

    @classmethod
    def from_message(cls, data: Mapping[str, Any]) -> "FrontierSummary":
        """The summary that :meth:`to_message` wrote."""
        return cls(id=int(data["id"]), owner=str(data["owner"]), mean=np.asarray(data["mean"], float),
                   cov=np.asarray(data["cov"], float), reward=float(data["reward"]),
                   observer=np.asarray(data["observer"], float), updated_s=float(data["updated_s"]))


def summarise(frontier: Frontier, owner: str, observer: Observer, updated_s: float) -> FrontierSummary:
    """The summary of ``owner``'s ``frontier`` observed from ``observer``."""
    return FrontierSummary(id=frontier.id, owner=owner, mean=np.asarray(frontier.mean, float).copy(),
                           cov=np.asarray(frontier.cov, float).copy(), reward=observer.reward,
                           observer=np.asarray(observer.position, float).copy(), updated_s=updated_s)


class TrajectoryPoints:
    """One robot's trajectory, a point kept every ``params.trajectory_period_s`` (the
    first point at once)."""

    def __init__(self, params: CsiroSelectionParams):
        self.period_s = params.trajectory_period_s
        self._points: list[np.ndarray] = []
        self._last_s: float | None = None

    def add(self, t_s: float, position: np.ndarray) -> bool:
        """Keep ``position`` if a period has passed since the last point kept; whether it was kept."""
        if self._last_s is not None and t_s - self._last_s < self.period_s:
            return False
        self._points.append(np.asarray(position, float).copy())
        self._last_s = t_s
        return True

    def visit(self, position: np.ndarray) -> None:
        """Keep ``position`` now, whatever the period: a place the robot went to on purpose
        (a teammate's frontier's observer), so that equation 14 discounts what lies there."""
        self._points.append(np.asarray(position, float).copy())

    def __len__(self) -> int:
        return len(self._points)

    def points(self, start: int = 0) -> np.ndarray:
        """(M, 3) the points kept, from the ``start``-th on (to send only the new ones)."""
        return np.array(self._points[start:], dtype=float).reshape(-1, 3)


def discount_factor(distance_m: np.ndarray | float, rho: float, eta_d_m: float) -> np.ndarray:
    """d_{rho, eta_d}(r) = rho + (1 - rho) sin^2(pi r / (2 eta_d)) for r <= eta_d, 1 beyond
    (equation 14): rho at a visited place, rising to no discount at eta_d."""
    r = np.asarray(distance_m, float)
    d = rho + (1.0 - rho) * np.sin(np.pi * r / (2.0 * eta_d_m)) ** 2
    return np.where(r <= eta_d_m, d, 1.0)


def discount_places(*point_sets: np.ndarray) -> np.ndarray:
    """The set L as one (M, 3) array from point sets (each (k, 3) or one (3,) point): every
    robot's trajectory points, the other robots' current goals and the failed goals."""
    arrays = [np.asarray(p, float).reshape(-1, 3) for p in point_sets]
    return np.concatenate(arrays) if arrays else np.zeros((0, 3))


def discounted_rewards(rewards: np.ndarray, observers: np.ndarray, places: np.ndarray,
                       params: CsiroSelectionParams) -> np.ndarray:
    """(F,) r~_f = r_f times d_{rho, eta_d}(|p - o_f|) over every place p of L within eta_d
    of the observer o_f (equation 14). ``rewards`` (F,), ``observers`` (F, 3), ``places`` (M, 3)."""
    out = np.asarray(rewards, float).copy()
    places = np.asarray(places, float).reshape(-1, 3)
    observers = np.asarray(observers, float).reshape(-1, 3)
    if len(places) == 0 or len(observers) == 0:
        return out
    near = cKDTree(observers).sparse_distance_matrix(cKDTree(places), params.eta_d_m, output_type="ndarray")
    factors = discount_factor(near["v"], params.rho, params.eta_d_m)
    np.multiply.at(out, near["i"], factors)
    return out


__all__ = ["FrontierKey", "FrontierSummary", "TrajectoryPoints", "discount_factor", "discount_places",
           "discounted_rewards", "summarise"]
