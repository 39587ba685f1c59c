"""The multi-agent topometric map (Williams et al., Section IV-C).

A graph whose nodes are points along every robot's trajectory, about ``spacing_m`` (3 m) apart,
joined along each trajectory and by the edges that observer planning finds (a node reachable over
the current mesh from where the robot stands); each frontier hangs off the node of its owner's
trajectory closest in time to the frontier's last update. A* (networkx) gives the path to a
frontier; the distances of equation 15 come from one Dijkstra search from the robot's node, which
gives the same lengths as one A* search per frontier at a fraction of the work.

Robots share their maps when they meet over the radio: :meth:`TopometricMap.changes` hands out
what was added since a given point of the map's log, :meth:`TopometricMap.merge` adds another
map's changes (what it already knew is not logged again, so maps pass on what they learnt from
others without echoes).

Nodes are ``(robot, k)``: robot ``robot``'s k-th trajectory node; frontier nodes are
``("frontier", owner, id)``. Node attributes: ``pos`` (3,) and ``t_s``.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np
from scipy.spatial import cKDTree

#: The paper's node spacing along a trajectory (m).
DEFAULT_SPACING_M = 3.0

Node = tuple


@dataclass(frozen=True)
class TopometricPath:
    """A path on the map: the waypoints (N, 3) from the node nearest the start to the target,
    its length (m, including the straight step from the start to the first node) and the nodes."""

    points: np.ndarray
    length_m: float
    nodes: tuple[Node, ...]


def frontier_node(key: tuple[str, int]) -> Node:
    """The graph node of the frontier ``key`` = (owner, id)."""
    return ("frontier", key[0], int(key[1]))


class TopometricMap:
    """One robot's view of the team's topometric map (see the module's docstring)."""

    def __init__(self, spacing_m: float = DEFAULT_SPACING_M) -> None:
        if not spacing_m > 0:
            raise ValueError(f"spacing_m must be > 0, got {spacing_m}")
        self.spacing_m = float(spacing_m)
        self.graph = nx.Graph()
        #: What was added, in order: ("node", robot, k, [x, y, z], t_s) and ("edge", a, b).
        self._log: list[tuple] = []
        self._last: dict[str, Node] = {}          # each robot's newest trajectory node
        self._tree: cKDTree | None = None
        self._tree_nodes: list[Node] = []

    # ---- building --------------------------------------------------------------------
    def add_pose(self, robot: str, t_s: float, position: np.ndarray) -> Node | None:
        """Add ``robot``'s position at ``t_s`` as a node when it is at least ``spacing_m`` from
        that robot's newest node (the first pose always), joined to it; the node, or None."""
        pos = np.asarray(position, float)
        last = self._last.get(robot)
        if last is not None and np.linalg.norm(pos - self.position(last)) < self.spacing_m:
            return None
        node = (robot, 0 if last is None else last[1] + 1)
        self._add_node(node, pos, float(t_s))
        if last is not None:
            self._add_edge(last, node)
        return node

    def connect(self, a: Node, b: Node) -> bool:
        """Join trajectory nodes ``a`` and ``b`` (a path between them was found); whether the
        edge is new."""
        if a == b or self.graph.has_edge(a, b) or a not in self.graph or b not in self.graph:
            return False
        self._add_edge(a, b)
        return True

    def connect_reachable(self, node: Node, reachable: np.ndarray, radius_m: float) -> int:
        """Join ``node`` to every trajectory node within ``radius_m`` of one of the ``reachable``
        points (K, 3): the places observer planning found a path to from where the robot stands
        (Section III-C). Returns the number of new edges."""
        reachable = np.asarray(reachable, float).reshape(-1, 3)
        if not len(reachable) or node not in self.graph:
            return 0
        tree, nodes = self._kdtree()
        near = sorted({i for hits in tree.query_ball_point(reachable, radius_m) for i in hits})
        return sum(self.connect(node, nodes[i]) for i in near)

    def attach_frontier(self, key: tuple[str, int], owner: str, updated_s: float, position: np.ndarray) -> bool:
        """Hang the frontier ``key`` (its observer at ``position``) off the node of ``owner``'s
        trajectory closest in time to ``updated_s`` (moved there if it hung elsewhere); False
        when the map has no node of ``owner`` yet. Frontier nodes are not logged: each robot
        attaches the frontiers it knows from their summaries."""
        mine = [n for n in self.graph if n[0] == owner]
        if not mine:
            return False
        anchor = min(mine, key=lambda n: (abs(self.graph.nodes[n]["t_s"] - updated_s), n[1]))
        f = frontier_node(key)
        if f in self.graph:
            self.graph.remove_node(f)
        pos = np.asarray(position, float)
        self.graph.add_node(f, pos=pos, t_s=float(updated_s))
        self.graph.add_edge(anchor, f, weight=float(np.linalg.norm(pos - self.position(anchor))))
        return True

    def detach_frontier(self, key: tuple[str, int]) -> None:
        """Forget the frontier ``key`` (it was explored)."""
        f = frontier_node(key)
        if f in self.graph:
            self.graph.remove_node(f)

    # ---- queries -------------------------------------------------------------------
    def position(self, node: Node) -> np.ndarray:
        return self.graph.nodes[node]["pos"]

    def last_node(self, robot: str) -> Node | None:
        """``robot``'s newest trajectory node; None before its first."""
        return self._last.get(robot)

    def trajectory_nodes(self) -> list[Node]:
        """Every trajectory node, in a fixed order (robot, k)."""
        return sorted(n for n in self.graph if n[0] != "frontier")

    def nearest_node(self, position: np.ndarray) -> Node | None:
        """The trajectory node nearest ``position``; None on an empty map."""
        tree, nodes = self._kdtree()
        if not nodes:
            return None
        return nodes[int(tree.query(np.asarray(position, float))[1])]

    def distances(self, position: np.ndarray, targets: Sequence[Node]) -> np.ndarray:
        """(T,) path length (m) from ``position`` over the map to each of ``targets`` (the straight
        step to the nearest node included); inf where a target is not reachable or unknown."""
        start = self.nearest_node(position)
        out = np.full(len(targets), np.inf)
        if start is None:
            return out
        step = float(np.linalg.norm(self.position(start) - np.asarray(position, float)))
        # One Dijkstra search for all targets: the lengths A* would give one target at a time.
        lengths = nx.single_source_dijkstra_path_length(self.graph, start, weight="weight")
        for i, t in enumerate(targets):
            if t in lengths:
                out[i] = step + lengths[t]
        return out

    def path(self, position: np.ndarray, target: Node) -> TopometricPath | None:
        """The A* path (networkx, straight-line heuristic) from the node nearest ``position`` to
        ``target``; None when there is none. (A frontier node hangs off one node only, so no path
        runs through one.)"""
        start = self.nearest_node(position)
        if start is None or target not in self.graph:
            return None
        goal = self.position(target)
        try:
            nodes = nx.astar_path(self.graph, start, target, weight="weight",
                                  heuristic=lambda a, _b: float(np.linalg.norm(self.position(a) - goal)))
        except nx.NetworkXNoPath:
            return None
        points = np.array([self.position(n) for n in nodes])
        step = float(np.linalg.norm(points[0] - np.asarray(position, float)))
        length = step + float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
        return TopometricPath(points, length, tuple(nodes))

    # ---- sharing -------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._log)

    def changes(self, since: int = 0) -> list[tuple]:
        """The log's entries from the ``since``-th on (plain data for a radio message):
        ``("node", robot, k, [x, y, z], t_s)`` and ``("edge", robot_a, k_a, robot_b, k_b)``."""
        return list(self._log[since:])

    def merge(self, changes: Iterable[Sequence[Any]]) -> int:
        """Add another map's :meth:`changes` (nodes before the edges that join them); returns
        how many entries were new here."""
        added = 0
        for entry in changes:
            if entry[0] == "node":
                node = (str(entry[1]), int(entry[2]))
                if node not in self.graph:
                    self._add_node(node, np.asarray(entry[3], float), float(entry[4]))
                    added += 1
            else:
                a, b = (str(entry[1]), int(entry[2])), (str(entry[3]), int(entry[4]))
                added += self.connect(a, b)
        return added

    # ---- internals -----------------------------------------------------------------
    def _add_node(self, node: Node, pos: np.ndarray, t_s: float) -> None:
        self.graph.add_node(node, pos=pos.copy(), t_s=t_s)
        self._log.append(("node", node[0], node[1], [float(v) for v in pos], t_s))
        if node[0] not in self._last or node[1] > self._last[node[0]][1]:
            self._last[node[0]] = node
        self._tree = None

    def _add_edge(self, a: Node, b: Node) -> None:
        self.graph.add_edge(a, b, weight=float(np.linalg.norm(self.position(a) - self.position(b))))
        self._log.append(("edge", a[0], a[1], b[0], b[1]))

    def _kdtree(self) -> tuple[cKDTree, list[Node]]:
        if self._tree is None:
            self._tree_nodes = self.trajectory_nodes()
            pts = np.array([self.position(n) for n in self._tree_nodes]).reshape(-1, 3)
            self._tree = cKDTree(pts)
        return self._tree, self._tree_nodes


__all__ = ["DEFAULT_SPACING_M", "TopometricMap", "TopometricPath", "frontier_node"]
