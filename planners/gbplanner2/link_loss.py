"""Where the radio link was lost, and the exploration gain beyond it.

A robot exploring within radio range backs off when its pings to the base station
fail (the CERBERUS WiFi safety block). Left alone, GBPlanner2 picks the same target
beyond the radio edge again and again, since nothing it knows has changed. So the
robot remembers the points where it found the link lost, and the planner discounts
the gain of what lies beyond them: a vertex whose shortest path from the root (the
robot in the local graph, home in the global one) passes within ``radius_m`` of a
link-loss point has its gain multiplied by ``gain_factor`` (0: nothing beyond counts),
and a frontier beyond one is not repositioned to. Points within ``radius_m`` of the
root are left out (the robot stands there and hears the base again).

Pure numpy and networkx: no robot, no radio.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import networkx as nx
import numpy as np


def near_points(positions: np.ndarray, points: np.ndarray, radius_m: float) -> np.ndarray:
    """(N,) bool: which of ``positions`` (N, 3) lie within ``radius_m`` of any of ``points`` (K, 3)."""
    positions = np.atleast_2d(np.asarray(positions, float))
    points = np.asarray(points, float).reshape(-1, 3)
    if len(points) == 0 or len(positions) == 0:
        return np.zeros(len(positions), bool)
    d2 = ((positions[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
    return (d2 <= radius_m * radius_m).any(axis=1)


def beyond_in_tree(near: np.ndarray, predecessor: np.ndarray) -> np.ndarray:
    """(N,) bool: vertices of a shortest-path tree that are ``near`` or have a ``near``
    ancestor. ``predecessor[v]`` is v's parent, negative for the root and unreachable
    vertices (scipy's convention). Pointer doubling: log(depth) numpy steps."""
    beyond = np.asarray(near, bool).copy()
    parent = np.asarray(predecessor, np.int64).copy()
    while True:
        has = parent >= 0
        if not has.any():
            return beyond
        up = np.where(has, parent, 0)
        beyond |= has & beyond[up]
        parent = np.where(has, parent[up], -1)


@dataclass(frozen=True)
class LinkLoss:
    """The link-loss points a robot remembers and how much the gain beyond them counts."""

    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    radius_m: float = 3.0
    gain_factor: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", np.asarray(self.points, float).reshape(-1, 3))
        if not self.radius_m > 0:
            raise ValueError(f"link-loss radius_m must be > 0, got {self.radius_m}")
        if not 0.0 <= self.gain_factor <= 1.0:
            raise ValueError(f"link-loss gain_factor must lie in [0, 1], got {self.gain_factor}")

    def away_from(self, root: np.ndarray) -> np.ndarray:
        """The points farther than ``radius_m`` from ``root`` (the others are left out)."""
        far = ~near_points(self.points, np.asarray(root, float).reshape(1, 3), self.radius_m)
        return self.points[far]

    def discount_tree(self, positions: np.ndarray, predecessor: np.ndarray, gains: np.ndarray) -> np.ndarray:
        """``gains`` of the vertices of a shortest-path tree rooted at ``positions[root]``
        (the vertex without predecessor that others descend from; the first vertex in
        GBPlanner2's local graph), those beyond a link-loss point times ``gain_factor``."""
        positions = np.asarray(positions, float)
        if len(positions) == 0:
            return np.asarray(gains, float)
        points = self.away_from(positions[0])
        if len(points) == 0:
            return np.asarray(gains, float)
        beyond = beyond_in_tree(near_points(positions, points, self.radius_m), predecessor)
        return np.where(beyond, np.asarray(gains, float) * self.gain_factor, gains)

    def beyond_on_graph(self, graph: nx.Graph, root: int, targets: list[int], position_of) -> set[int]:
        """The ``targets`` whose shortest path from ``root`` on ``graph`` (edge attribute
        ``weight``) passes within ``radius_m`` of a link-loss point; ``position_of(v)``
        gives a vertex's position. Targets ``root`` does not reach are not beyond."""
        points = self.away_from(position_of(root))
        if len(points) == 0 or not targets:
            return set()
        paths = nx.single_source_dijkstra_path(graph, root, weight="weight")
        out = set()
        for v in targets:
            path = paths.get(v)
            if path and near_points(np.array([position_of(u) for u in path]), points, self.radius_m).any():
                out.add(v)
        return out


__all__ = ["LinkLoss", "beyond_in_tree", "near_points"]
