"""Where the radio link was lost, and the exploration gain beyond it.

A robot exploring within radio range backs off when its pings to the base station
fail (the CERBERUS WiFi safety block). Left alone, GBPlanner2 picks the same target
beyond the radio edge again and again, since nothing it knows has changed. So the
robot remembers the points where it found the link lost, and the planner discounts
the gain of what lies beyond them: a vertex whose shortest path from the root (the
robot in the local graph, home in the global one) passes within ``radius_m`` of a
link-loss point has its gain multiplied by ``gain_factor`` (0: nothing beyond counts),
and a frontier beyond one is not repositioned to. The robot backs off only until it
hears the base again, so it often stands within ``radius_m`` of a point it
remembers: from there, only the steps that come nearer the point than the root is
lead beyond it.

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


def segments_near(starts: np.ndarray, ends: np.ndarray, points: np.ndarray, radius_m: float,
                  closer_than: np.ndarray | None = None) -> np.ndarray:
    """(N,) bool: which segments ``starts[i]``-``ends[i]`` (N, 3) pass within
    ``radius_m`` of some ``points[k]`` (K, 3) and, where ``closer_than[k]`` is given,
    come nearer that point than ``closer_than[k]`` metres: they end nearer, or pass
    within half of it."""
    starts, ends = np.atleast_2d(np.asarray(starts, float)), np.atleast_2d(np.asarray(ends, float))
    points = np.asarray(points, float).reshape(-1, 3)
    if len(points) == 0 or len(starts) == 0:
        return np.zeros(len(starts), bool)
    seg = ends - starts                                            # (N, 3)
    rel = points[None, :, :] - starts[:, None, :]                  # (N, K, 3)
    length2 = np.maximum((seg * seg).sum(axis=1), 1e-12)[:, None]  # (N, 1)
    t = np.clip((rel * seg[:, None, :]).sum(axis=2) / length2, 0.0, 1.0)
    gap = rel - t[:, :, None] * seg[:, None, :]
    gap2 = (gap * gap).sum(axis=2)                                 # (N, K)
    near = gap2 <= radius_m * radius_m
    if closer_than is not None:
        closer = np.asarray(closer_than, float)[None, :]
        end_distance = np.linalg.norm(points[None, :, :] - ends[:, None, :], axis=2)
        near &= (end_distance < closer) | (gap2 < (0.5 * closer) ** 2)
    return near.any(axis=1)


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

    def leading_beyond(self, root: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """(N,) bool: which steps ``starts[i]``-``ends[i]`` of paths from ``root`` lead
        beyond a link-loss point: they pass within ``radius_m`` of it and, where the
        root itself is that near, come nearer the point than the root is
        (:func:`segments_near`)."""
        distance = np.linalg.norm(self.points - np.asarray(root, float).reshape(1, 3), axis=1)
        closer_than = np.where(distance <= self.radius_m, distance, np.inf)
        return segments_near(starts, ends, self.points, self.radius_m, closer_than)

    def discount_tree(self, positions: np.ndarray, predecessor: np.ndarray, gains: np.ndarray) -> np.ndarray:
        """``gains`` of the vertices of a shortest-path tree rooted at ``positions[root]``
        (the vertex without predecessor that others descend from; the first vertex in
        GBPlanner2's local graph), those beyond a link-loss point times ``gain_factor``."""
        positions = np.asarray(positions, float)
        if len(positions) == 0:
            return np.asarray(gains, float)
        if len(self.points) == 0:
            return np.asarray(gains, float)
        parent = np.asarray(predecessor, np.int64)
        starts = positions[np.where(parent >= 0, parent, np.arange(len(positions)))]
        beyond = beyond_in_tree(self.leading_beyond(positions[0], starts, positions), predecessor)
        return np.where(beyond, np.asarray(gains, float) * self.gain_factor, gains)

    def beyond_on_graph(self, graph: nx.Graph, root: int, targets: list[int], position_of) -> set[int]:
        """The ``targets`` whose shortest path from ``root`` on ``graph`` (edge attribute
        ``weight``) leads beyond a link-loss point (:meth:`leading_beyond`);
        ``position_of(v)`` gives a vertex's position. Targets ``root`` does not reach
        are not beyond."""
        if len(self.points) == 0 or not targets:
            return set()
        root_xyz = position_of(root)
        paths = nx.single_source_dijkstra_path(graph, root, weight="weight")
        out = set()
        for v in targets:
            path = paths.get(v)
            if path and len(path) > 1:
                xyz = np.array([position_of(u) for u in path])
                if self.leading_beyond(root_xyz, xyz[:-1], xyz[1:]).any():
                    out.add(v)
        return out


__all__ = ["LinkLoss", "beyond_in_tree", "near_points", "segments_near"]
