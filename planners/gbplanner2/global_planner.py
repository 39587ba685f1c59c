"""GBPlanner2's global planner: the global graph, repositioning, homing and goals.

The *global graph* (a ``networkx.Graph``) grows with every local planning iteration:

* *visited* vertices: the robot's positions and the paths commanded to it;
* *frontier* vertices: vertices of G_L with high volumetric gain that the robot did not
  go to, added with the (shortcut) branch of G_L that leads to them, so that they stay
  reachable after the robot has left.

New vertices within ``global_vertex_merge_radius_m`` of an existing one reuse it.
Frontiers are re-evaluated (volumetric gain on the current map) when the robot comes
near them and before each repositioning; explored ones are dropped.

* **Repositioning**: when the local planner's gain stays below
  ``low_gain_threshold_m3`` for ``low_gain_iterations_max`` iterations in a row, the
  robot goes to the frontier with the best gain / (path length + offset) among those
  from which it can still get home within its endurance.
* **Homing**: at each iteration, the robot goes home along the global graph when its
  remaining endurance barely covers the way home (path length / speed) plus
  ``homing_margin_s`` (and, with ``homing_include_next_step``, one more local step out
  and back).
* **Goals**: a path to a point given by the supervisor or the behaviour tree, along the
  global graph, joined to the robot and to the goal by collision-checked local edges.

A global path is checked lazily on the current map: an edge that now crosses rock is
removed and the search repeated.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import count

import networkx as nx
import numpy as np
from scipy.spatial import cKDTree

from ..geometry import path_length
from ..occupancy import OCCUPIED, Grid
from .config import GBPlannerConfig
from .gain import ring_azimuth, ring_phase, volumetric_gain
from .local_map import LocalMap
from .local_planner import LocalPlanResult
from .path_improvement import shortcut_path


@dataclass
class Frontier:
    """A frontier vertex of the global graph: where it is, its last gain, when it was added."""

    vertex: int
    position: np.ndarray
    gain: float
    iteration: int
    ring_azimuth_rad: float = 0.0


@dataclass
class GlobalPlanResult:
    """A global path (``None`` with a ``reason`` when there is none).

    ``kind`` is ``reposition``, ``homing`` or ``goal``; ``target`` the frontier, home or
    goal position; ``gain`` the frontier's gain (repositioning only).
    """

    path: np.ndarray | None
    kind: str
    reason: str = ""
    length_m: float = 0.0
    target: np.ndarray | None = None
    gain: float = 0.0
    vertices: list[int] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.path is not None


@dataclass(frozen=True)
class HomingCheck:
    """Whether the robot must go home now: the time the way home takes at
    ``speed_mps``, the reserve kept, and the endurance left."""

    required: bool
    path_length_m: float
    time_home_s: float
    reserve_s: float
    endurance_remaining_s: float
    reason: str = ""
    home_path: GlobalPlanResult | None = None


class GlobalPlanner:
    """The global layer for one robot, from its ``home`` (where it started)."""

    def __init__(self, config: GBPlannerConfig, home: np.ndarray) -> None:
        if not isinstance(config, GBPlannerConfig):
            raise TypeError("GlobalPlanner needs a GBPlannerConfig")
        home = np.asarray(home, float).reshape(3)
        if not np.all(np.isfinite(home)):
            raise ValueError("home must be a finite (3,) position")
        self.config = config
        self.graph = nx.Graph()
        self._ids = count()
        self._positions: list[np.ndarray] = []
        self._tree: cKDTree | None = None
        self.frontiers: dict[int, Frontier] = {}
        self.low_gain_iterations = 0
        self.iteration = 0
        self.home = home
        self.home_vertex = self._add_vertex(home, "home", merge=False)
        self.robot_vertex = self.home_vertex

    # --- graph bookkeeping ------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        return np.asarray(self._positions) if self._positions else np.zeros((0, 3))

    def position_of(self, v: int) -> np.ndarray:
        return self._positions[v]

    def _kdtree(self) -> cKDTree:
        if self._tree is None or self._tree.n != len(self._positions):
            self._tree = cKDTree(self.positions)
        return self._tree

    def _add_vertex(self, p: np.ndarray, kind: str, merge: bool = True) -> int:
        p = np.asarray(p, float)
        if merge and self._positions and self.config.global_vertex_merge_radius_m > 0:
            d, i = self._kdtree().query(p, distance_upper_bound=self.config.global_vertex_merge_radius_m)
            if np.isfinite(d):
                return int(i)
        v = next(self._ids)
        self._positions.append(p.copy())
        self.graph.add_node(v, kind=kind)
        return v

    def _add_edge(self, u: int, v: int) -> None:
        if u != v:
            w = float(np.linalg.norm(self._positions[u] - self._positions[v]))
            self.graph.add_edge(u, v, weight=w)

    def _add_chain(self, points: np.ndarray, kind: str, start: int | None = None) -> list[int]:
        ids: list[int] = []
        prev = start
        for p in np.asarray(points, float):
            v = self._add_vertex(p, kind)
            if prev is not None:
                self._add_edge(prev, v)
            ids.append(v)
            prev = v
        return ids

    # --- recording what the robot did and saw -------------------------------------------
    def record_position(self, position: np.ndarray, grid: Grid | None = None) -> int:
        """The robot is at ``position``: add it as a visited vertex joined to the last one
        (the robot went from there to here, so the edge is traversable) and, with
        ``grid`` and unless it merged into an existing vertex, to its neighbours
        (:meth:`_link_neighbours`)."""
        first_new = len(self._positions)
        v = self._add_vertex(np.asarray(position, float), "visited")
        self._add_edge(self.robot_vertex, v)
        self.robot_vertex = v
        if grid is not None and v >= first_new:
            p, r = self._positions[v], self.config.neighbour_radius_m
            self._link_neighbours(LocalMap(grid, p - r, p + r, self.config, clear_box_at=p), np.array([v]))
        return v

    def add_local_result(self, result: LocalPlanResult, grid: Grid | None = None) -> list[Frontier]:
        """Grow the global graph with one local planning iteration and count low gain.

        The commanded path becomes visited vertices; vertices of G_L with gain of at
        least ``frontier_gain_min_m3`` become frontiers (at most
        ``frontiers_per_iteration_max``, ``frontier_spacing_m`` apart, not on the
        commanded path). With ``grid``, frontiers near the robot are re-evaluated.
        Returns the frontiers added.
        """
        cfg = self.config
        self.iteration += 1
        if result.gain < cfg.low_gain_threshold_m3:
            self.low_gain_iterations += 1
        else:
            self.low_gain_iterations = 0
        first_new = len(self._positions)
        if result.root is not None:
            self.record_position(result.root)
        root_v = self.robot_vertex
        if result.path is not None and len(result.path) > 1:
            self._add_chain(result.path[1:], "visited", start=root_v)
        added: list[Frontier] = []
        graph, paths, gains = result.graph, result.shortest_paths, result.vertex_gains
        if graph is not None and paths is not None and gains is not None and graph.num_vertices > 1:
            added = self._add_frontiers(result, root_v)
        if result.local_map is not None:
            self._link_neighbours(result.local_map, np.arange(first_new, len(self._positions)))
        if grid is not None and result.root is not None:
            self.update_frontiers(grid, near=result.root, radius_m=cfg.sensor_range_m)
        return added

    def _link_neighbours(self, local_map: LocalMap, new: np.ndarray) -> None:
        """Join each of the ``new`` vertices to its (at most ``neighbours_max``) nearest
        vertices within ``neighbour_radius_m`` where ``local_map`` admits the edge (an
        edge leaving its crop is not admitted), as gbplanner joins a vertex it adds to
        its global graph (``Rrg::expandGraphEdges``): the graph is a roadmap of the
        explored space, not the robot's track."""
        cfg = self.config
        if len(new) == 0:
            return
        pts = self.positions
        k = min(cfg.neighbours_max + 1, len(pts))
        d, near = self._kdtree().query(pts[new], k=k, distance_upper_bound=cfg.neighbour_radius_m)
        u, v = np.repeat(new, k), near.reshape(-1)
        keep = np.isfinite(d.reshape(-1)) & (u != v)
        # Each pair once, whichever of its two ends listed the other; not already joined.
        pairs = {(min(a, b), max(a, b)) for a, b in zip(u[keep].tolist(), v[keep].tolist())}
        pairs = sorted(p for p in pairs if not self.graph.has_edge(*p))
        if not pairs:
            return
        a, b = np.asarray(pairs).T
        ok = local_map.check_edges(pts[a], pts[b]).admissible
        for x, y in zip(a[ok], b[ok]):
            self._add_edge(int(x), int(y))

    def _add_frontiers(self, result: LocalPlanResult, root_v: int) -> list[Frontier]:
        cfg = self.config
        graph, paths, gains = result.graph, result.shortest_paths, result.vertex_gains
        assert graph is not None and paths is not None and gains is not None
        cand = np.flatnonzero((gains >= cfg.frontier_gain_min_m3) & ~graph.hanging & paths.reachable)
        cand = cand[cand != 0]
        if len(cand) == 0:
            return []
        cand = cand[np.argsort(-gains[cand], kind="stable")]
        taken: list[np.ndarray] = [f.position for f in self.frontiers.values()]
        if result.path is not None:
            taken.append(result.path[-1])
        added: list[Frontier] = []
        for v in cand:
            if len(added) >= cfg.frontiers_per_iteration_max:
                break
            p = graph.vertices[v]
            if self._crowded(p, taken):
                continue
            added.append(self._frontier_at_end(result, int(v), root_v))
            taken.append(p)
        return added

    def _crowded(self, p: np.ndarray, taken: list[np.ndarray]) -> bool:
        """Whether a frontier at ``p`` would lie within ``frontier_spacing_m`` of one of ``taken``."""
        return bool(taken) and float(np.min(np.linalg.norm(np.asarray(taken) - p, axis=1))) < \
            self.config.frontier_spacing_m

    def _frontier_at_end(self, result: LocalPlanResult, v: int, start: int) -> Frontier:
        """Join the path of G_L's vertex ``v`` (shortcut on the iteration's local map) to
        the global graph from vertex ``start`` (the iteration's root) and make its end a
        frontier with ``v``'s gain. Writes ``graph`` and ``frontiers``; returns the frontier."""
        graph, paths, gains = result.graph, result.shortest_paths, result.vertex_gains
        assert graph is not None and paths is not None and gains is not None
        chain = graph.vertices[paths.path(v)]
        if result.local_map is not None:
            chain = shortcut_path(result.local_map, chain)
        fv = self._add_chain(chain[1:], "visited", start=start)[-1]
        self.graph.nodes[fv]["kind"] = "frontier"
        f = Frontier(fv, self._positions[fv].copy(), float(gains[v]), self.iteration, ring_azimuth(graph))
        self.frontiers[fv] = f
        return f

    def add_unreached_goal(self, result: LocalPlanResult, start: int) -> Frontier | None:
        """The robot was stopped on the way to the vertex of G_L whose path ``result``
        commanded (``best_vertex``, left out of the frontiers because the robot was going
        there; ``start``: the global vertex of the iteration's root): make it a frontier as
        :meth:`add_local_result` makes the others (joined by its path, its new vertices
        to their neighbours), unless it could not have been one (gain under
        ``frontier_gain_min_m3``, hanging, unreachable) or lies within
        ``frontier_spacing_m`` of the start or of a frontier. Writes ``graph`` and
        ``frontiers``; returns the frontier added, if any."""
        graph, paths, gains = result.graph, result.shortest_paths, result.vertex_gains
        v, cfg = result.best_vertex, self.config
        if graph is None or paths is None or gains is None or v <= 0:
            return None
        near = [self._positions[start], *(f.position for f in self.frontiers.values())]
        if (gains[v] < cfg.frontier_gain_min_m3 or graph.hanging[v] or not paths.reachable[v]
                or self._crowded(graph.vertices[v], near)):
            return None
        first_new = len(self._positions)
        f = self._frontier_at_end(result, int(v), start)
        if result.local_map is not None:
            self._link_neighbours(result.local_map, np.arange(first_new, len(self._positions)))
        return f

    def update_frontiers(self, grid: Grid, near: np.ndarray | None = None, radius_m: float | None = None) -> None:
        """Recompute the gain of the frontiers (those within ``radius_m`` of ``near``, or
        all) on ``grid`` and drop the ones explored since."""
        if not self.frontiers:
            return
        ids = list(self.frontiers)
        pos = np.asarray([self.frontiers[i].position for i in ids])
        if near is not None and radius_m is not None:
            sel = np.linalg.norm(pos - np.asarray(near, float), axis=1) <= radius_m
            ids = [i for i, s in zip(ids, sel) if s]
            pos = pos[sel]
        if not ids:
            return
        # Each frontier keeps the ring alignment it was found with: one call for all.
        az = np.array([self.frontiers[i].ring_azimuth_rad for i in ids])
        g = volumetric_gain(grid, pos, self.config, 0.0, 0.0, ray_phase=ring_phase(self.config, az))
        for i, gain in zip(ids, g):
            if gain < self.config.frontier_gain_min_m3:
                del self.frontiers[i]
                self.graph.nodes[i]["kind"] = "visited"
            else:
                self.frontiers[i].gain = float(gain)

    # --- decisions ------------------------------------------------------------------------
    @property
    def reposition_due(self) -> bool:
        """The local gain stayed low for ``low_gain_iterations_max`` iterations."""
        return self.low_gain_iterations >= self.config.low_gain_iterations_max

    def homing_check(self, grid: Grid, position: np.ndarray, endurance_remaining_s: float) -> HomingCheck:
        """Whether the remaining endurance barely covers the way home plus the reserve."""
        cfg = self.config
        reserve = cfg.homing_margin_s
        if cfg.homing_include_next_step:
            reserve += 2.0 * cfg.traverse_length_max_m / cfg.speed_mps
        home = self.plan_home(grid, position)
        if home.ok:
            length = home.length_m
            reason = ""
        else:
            # No way home on the graph: the straight line is the most optimistic estimate.
            length = self._straight_home_m(position)
            reason = f"no path home on the global graph ({home.reason}); straight-line estimate"
        t_home = length / cfg.speed_mps
        required = endurance_remaining_s <= t_home + reserve
        return HomingCheck(required, length, t_home, reserve, float(endurance_remaining_s), reason, home)

    def _straight_home_m(self, position: np.ndarray) -> float:
        """The straight line home: the optimistic length of the way home where the graph
        has none."""
        return float(np.linalg.norm(np.asarray(position, float) - self.home))

    def plan_home(self, grid: Grid, position: np.ndarray) -> GlobalPlanResult:
        """The way home along the global graph."""
        res = self._plan_to_vertex(grid, position, self.home_vertex, "homing")
        if res.ok:
            res.target = self.home.copy()
        return res

    def plan_to_goal(self, grid: Grid, position: np.ndarray, goal: np.ndarray) -> GlobalPlanResult:
        """A path to ``goal`` (a point from the supervisor or the tree): along the global
        graph, with collision-checked edges from the robot and to the goal; a direct
        edge when the goal is in reach."""
        goal = np.asarray(goal, float).reshape(3)
        position = np.asarray(position, float).reshape(3)
        if not np.all(np.isfinite(goal)):
            return GlobalPlanResult(None, "goal", "the goal is not a finite point")
        if not grid.in_bounds(grid.to_index(goal[None]))[0]:
            return GlobalPlanResult(None, "goal", "the goal is outside the map", target=goal)
        if np.linalg.norm(goal - position) <= self.config.global_connection_radius_m:
            r = self.config.global_connection_radius_m
            lm = LocalMap(grid, np.minimum(position, goal) - r, np.maximum(position, goal) + r, self.config,
                          clear_box_at=position)
            if lm.check_edges(position[None], goal[None]).admissible[0]:
                path = np.stack([position, goal])
                return GlobalPlanResult(path, "goal", "", path_length(path), goal, vertices=[])
        goal_nodes = self._connections(grid, goal)
        if not goal_nodes:
            return GlobalPlanResult(None, "goal", "the goal cannot be connected to the global graph", target=goal)
        res = self._plan_between(grid, position, goal_nodes, "goal")
        if not res.ok:
            return res
        path = np.concatenate([res.path, goal[None]])
        return GlobalPlanResult(path, "goal", "", path_length(path), goal, vertices=res.vertices)

    def plan_reposition(
        self, grid: Grid, position: np.ndarray, endurance_remaining_s: float | None = None
    ) -> GlobalPlanResult:
        """A path to the best frontier: gain / (path length + ``frontier_distance_offset_m``),
        among frontiers from which the robot can still get home within its endurance:
        along the graph, or, where an edge found blocked cut a frontier off from home on
        the graph, in a straight line (an optimistic estimate, the one
        :meth:`homing_check` makes in that case too)."""
        cfg = self.config
        self.update_frontiers(grid)
        if not self.frontiers:
            return GlobalPlanResult(None, "reposition", "no frontier left in the global graph")
        start = self._connections(grid, np.asarray(position, float))
        if not start:
            return GlobalPlanResult(None, "reposition", "the robot cannot be connected to the global graph")
        dist, _prev = self._dijkstra_from(np.asarray(position, float), start)
        home_dist = nx.single_source_dijkstra_path_length(self.graph, self.home_vertex, weight="weight")
        best, best_score = None, -math.inf
        for v, f in self.frontiers.items():
            if v not in dist:
                continue
            if endurance_remaining_s is not None:
                back = home_dist[v] if v in home_dist else self._straight_home_m(f.position)
                need = (dist[v] + back) / cfg.speed_mps + cfg.homing_margin_s
                if need > endurance_remaining_s:
                    continue
            score = f.gain / (dist[v] + cfg.frontier_distance_offset_m)
            if score > best_score:
                best, best_score = v, score
        if best is None:
            why = "no frontier reachable" if endurance_remaining_s is None else "no frontier reachable within the endurance"
            return GlobalPlanResult(None, "reposition", why)
        res = self._plan_to_vertex(grid, position, best, "reposition", start=start)
        if res.ok:
            f = self.frontiers.pop(best)
            self.graph.nodes[best]["kind"] = "visited"
            res.target = f.position.copy()
            res.gain = f.gain
            self.low_gain_iterations = 0
        return res

    # --- search -------------------------------------------------------------------------
    def _connections(self, grid: Grid, point: np.ndarray, k: int = 12) -> dict[int, float]:
        """Global vertices that an admissible edge joins to ``point``, with its length."""
        if not self._positions:
            return {}
        r = self.config.global_connection_radius_m
        d, idx = self._kdtree().query(point, k=min(k, len(self._positions)), distance_upper_bound=r)
        d, idx = np.atleast_1d(d), np.atleast_1d(idx)
        ok = np.isfinite(d)
        d, idx = d[ok], idx[ok]
        if len(idx) == 0:
            return {}
        exact = d < 1e-6
        out = {int(i): float(x) for i, x in zip(idx[exact], d[exact])}
        rest = ~exact
        if rest.any():
            lm = LocalMap(grid, point - r, point + r, self.config, clear_box_at=point)
            targets = self.positions[idx[rest]]
            chk = lm.check_edges(np.repeat(point[None], len(targets), axis=0), targets)
            if not chk.admissible.any() and self.config.is_legged:
                # The robot may stand where its own map has no ground yet: accept
                # collision-free straight edges (checked on the body box only).
                aerial = self.config.replace(robot_type="aerial")
                lm2 = LocalMap(grid, point - r, point + r, aerial, clear_box_at=point)
                chk = lm2.check_edges(np.repeat(point[None], len(targets), axis=0), targets)
            for i, x, a in zip(idx[rest], d[rest], chk.admissible):
                if a:
                    out[int(i)] = float(x)
        if not out and self.robot_vertex in {int(i) for i in idx}:
            # The robot's own last vertex: it came from there.
            out[self.robot_vertex] = float(np.linalg.norm(self._positions[self.robot_vertex] - point))
        return out

    def _dijkstra_from(self, point: np.ndarray, start: dict[int, float]) -> tuple[dict, dict]:
        src = "_robot"
        self.graph.add_node(src)
        for v, w in start.items():
            self.graph.add_edge(src, v, weight=w)
        try:
            dist, paths = nx.single_source_dijkstra(self.graph, src, weight="weight")
        finally:
            self.graph.remove_node(src)
        dist.pop(src, None)
        return dist, paths

    def _plan_to_vertex(
        self, grid: Grid, position: np.ndarray, target: int, kind: str, start: dict[int, float] | None = None
    ) -> GlobalPlanResult:
        return self._plan_between(grid, np.asarray(position, float), {target: 0.0}, kind, start=start)

    def _plan_between(
        self,
        grid: Grid,
        position: np.ndarray,
        targets: dict[int, float],
        kind: str,
        start: dict[int, float] | None = None,
    ) -> GlobalPlanResult:
        """Shortest path from the robot to any of ``targets`` (vertex -> extra length),
        checked lazily on the current map."""
        position = np.asarray(position, float).reshape(3)
        if start is None:
            start = self._connections(grid, position)
        if not start:
            return GlobalPlanResult(None, kind, "the robot cannot be connected to the global graph")
        src, dst = "_robot", "_target"
        for _ in range(20):
            self.graph.add_node(src)
            self.graph.add_node(dst)
            for v, w in start.items():
                self.graph.add_edge(src, v, weight=w)
            for v, w in targets.items():
                self.graph.add_edge(v, dst, weight=w)
            try:
                nodes = nx.dijkstra_path(self.graph, src, dst, weight="weight")
            except nx.NetworkXNoPath:
                nodes = None
            finally:
                self.graph.remove_node(src)
                self.graph.remove_node(dst)
            if nodes is None:
                return GlobalPlanResult(None, kind, "no path on the global graph")
            verts = [int(v) for v in nodes[1:-1]]
            pts = [position] + [self._positions[v] for v in verts]
            path = np.asarray(pts)
            bad = self._blocked_edges(grid, path)
            if not bad:
                return GlobalPlanResult(_dedupe(path), kind, "", path_length(path), None, vertices=verts)
            for k in bad:
                if k == 0:
                    start.pop(verts[0], None)
                else:
                    u, v = verts[k - 1], verts[k]
                    if self.graph.has_edge(u, v):
                        self.graph.remove_edge(u, v)
            if not start:
                return GlobalPlanResult(None, kind, "the robot cannot be connected to the global graph")
        return GlobalPlanResult(None, kind, "no path on the global graph free of newly mapped rock")

    def _blocked_edges(self, grid: Grid, path: np.ndarray) -> list[int]:
        """Segments of ``path`` whose centre line crosses an OCCUPIED voxel now."""
        if len(path) < 2:
            return []
        a, b = path[:-1], path[1:]
        length = np.linalg.norm(b - a, axis=1)
        n = np.maximum(np.ceil(length / (0.5 * grid.voxel_size_m)).astype(np.int64), 1) + 1
        eid = np.repeat(np.arange(len(a)), n)
        first = np.cumsum(n) - n
        t = (np.arange(int(n.sum())) - first[eid]) / (n[eid] - 1).clip(min=1)
        pts = a[eid] + (b - a)[eid] * t[:, None]
        bad = grid.value_at(pts) == OCCUPIED
        return sorted(set(eid[bad].tolist()))


def _dedupe(path: np.ndarray) -> np.ndarray:
    keep = np.ones(len(path), bool)
    keep[1:] = np.linalg.norm(np.diff(path, axis=0), axis=1) > 1e-6
    return path[keep]
