"""GBPlanner2's local planner (Algorithm 1).

::

    xi_0 <- GetCurrentConfiguration()
    G_L <- BuildLocalGraph(xi_0)                 # Algorithm 2 (graph.py)
    Sigma_L <- GetDijkstraShortestPaths(G_L, xi_0)
    ComputeVolumetricGain(G_L)                   # Algorithm 3 (gain.py)
    sigma_best <- argmax_sigma ExplorationGain(sigma)
    return ImprovePath(sigma_best)               # path_improvement.py

:meth:`LocalPlanner.plan` takes plain inputs (an occupancy :class:`~delve.planners.occupancy.Grid`,
the robot's position and yaw, a seeded ``numpy.random.Generator``) and returns a
:class:`LocalPlanResult`: the path to command ((N, 3) world points, or ``None`` with a
reason), its exploration gain, the graph and gains for the global planner and for
plots, and timings. Ordinary map situations never raise.

For legged robots the path never ends at, nor passes through, a hanging vertex: a
shortest path that reaches one is commanded only up to the vertex before it, while
the hanging vertex's (scaled) gain still counts for choosing it.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..occupancy import OCCUPIED, UNKNOWN, Grid
from .bounds import LocalBound, adaptive_local_bound
from .config import GBPlannerConfig
from .gain import PathGains, compute_vertex_gains, exploration_gains
from .graph import LocalGraph, ShortestPaths, build_local_graph, shortest_paths
from .link_loss import LinkLoss
from .local_map import GROUND_ATTACHED, LocalMap
from .path_improvement import improve_path, segments_admissible, truncate_path


@dataclass
class PlanDiagnostics:
    """Timings (wall-clock seconds) and sizes of one local planning iteration."""

    bound_s: float = 0.0
    map_s: float = 0.0
    graph_s: float = 0.0
    shortest_paths_s: float = 0.0
    gain_s: float = 0.0
    selection_s: float = 0.0
    improvement_s: float = 0.0
    total_s: float = 0.0
    num_vertices: int = 0
    num_edges: int = 0
    num_hanging: int = 0
    num_samples: int = 0
    num_gain_evaluations: int = 0
    reason: str = ""

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class LocalPlanResult:
    """The outcome of one local planning iteration.

    ``path`` is None when no path could be planned; ``reason`` then says why.
    ``gain`` is the chosen path's exploration gain (0 without a path). ``graph``,
    ``shortest_paths``, ``vertex_gains`` and ``path_gains`` describe G_L (for the
    global planner and for plots); ``best_vertex`` is the vertex whose shortest path
    was chosen (-1 without one).
    """

    path: np.ndarray | None
    gain: float
    reason: str
    diagnostics: PlanDiagnostics
    root: np.ndarray | None = None
    graph: LocalGraph | None = None
    shortest_paths: ShortestPaths | None = None
    vertex_gains: np.ndarray | None = None
    path_gains: PathGains | None = None
    best_vertex: int = -1
    vertex_path: list[int] = field(default_factory=list)
    local_map: LocalMap | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.path is not None

    @property
    def bound(self) -> LocalBound | None:
        return None if self.graph is None else self.graph.bound

    @property
    def direction_rad(self) -> float | None:
        """Heading from the path's start to its end (the next exploring direction)."""
        if self.path is None or len(self.path) < 2:
            return None
        d = self.path[-1] - self.path[0]
        if np.hypot(d[0], d[1]) < 1e-6:
            return None
        return float(math.atan2(d[1], d[0]))


class LocalPlanner:
    """Algorithm 1 for one robot; stateless between calls (the caller keeps the
    exploring direction and the random generator)."""

    def __init__(self, config: GBPlannerConfig) -> None:
        if not isinstance(config, GBPlannerConfig):
            raise TypeError("LocalPlanner needs a GBPlannerConfig")
        self.config = config

    def plan(
        self,
        grid: Grid,
        position: np.ndarray,
        rng: np.random.Generator,
        *,
        yaw_rad: float = 0.0,
        exploring_direction_rad: float | None = None,
        exploration_bounds: tuple[np.ndarray, np.ndarray] | None = None,
        bound: LocalBound | None = None,
        link_loss: LinkLoss | None = None,
    ) -> LocalPlanResult:
        """One local planning iteration from ``position`` (the body centre, metres).

        ``exploring_direction_rad``: heading of the previous path, for the direction
        penalty (None: no penalty). ``exploration_bounds``: an axis-aligned (lo, hi)
        box that vertices must lie in (e.g. the supervisor's exploration box).
        ``bound``: use this local bounding box instead of the adaptive one.
        ``link_loss``: the gain of vertices beyond where the radio link was lost is
        discounted (:mod:`.link_loss`).
        """
        cfg = self.config
        diag = PlanDiagnostics()
        t_start = time.perf_counter()
        position = np.asarray(position, float).reshape(3)

        def fail(reason: str, **extra) -> LocalPlanResult:
            diag.reason = reason
            diag.total_s = time.perf_counter() - t_start
            return LocalPlanResult(None, 0.0, reason, diag, **extra)

        if not np.all(np.isfinite(position)):
            return fail("robot position is not finite")
        if not grid.in_bounds(grid.to_index(position[None]))[0]:
            return fail("robot position is outside the map")

        t = time.perf_counter()
        if bound is None:
            bound = adaptive_local_bound(grid, position, cfg)
        diag.bound_s = time.perf_counter() - t

        t = time.perf_counter()
        lo, hi = bound.aabb()
        lo = np.minimum(lo, position)
        hi = np.maximum(hi, position)
        local_map = LocalMap(grid, lo, hi, cfg, clear_box_at=position)
        if local_map.box_has_occupied(position):
            diag.map_s = time.perf_counter() - t
            return fail("start position is invalid: occupied voxels inside the robot box")
        root = position.copy()
        if cfg.is_legged:
            _assume_ground_under_robot(local_map, root, cfg)
            gz, status = local_map.project_to_ground(root[None])
            if status[0] == GROUND_ATTACHED:
                root[2] = gz[0] + cfg.body_height_m
            if not local_map.is_box_free(root[None])[0]:
                # The projection moved the body into rock: plan from where the robot is.
                root = position.copy()
        diag.map_s = time.perf_counter() - t

        t = time.perf_counter()
        graph = build_local_graph(local_map, root, bound, cfg, rng, exploration_bounds=exploration_bounds)
        diag.graph_s = time.perf_counter() - t
        diag.num_vertices = graph.num_vertices
        diag.num_edges = graph.num_edges
        diag.num_hanging = int(graph.hanging.sum())
        diag.num_samples = graph.num_samples
        if graph.num_vertices < 2:
            return fail("the local graph has no vertex besides the robot (no free space connected to it)",
                        root=root, graph=graph)

        t = time.perf_counter()
        paths = shortest_paths(graph)
        diag.shortest_paths_s = time.perf_counter() - t

        t = time.perf_counter()
        vertex_gain, n_eval = compute_vertex_gains(grid, graph, paths, cfg, yaw_rad)
        if link_loss is not None:
            vertex_gain = link_loss.discount_tree(graph.vertices, paths.predecessor, vertex_gain)
        diag.gain_s = time.perf_counter() - t
        diag.num_gain_evaluations = n_eval

        t = time.perf_counter()
        pg = exploration_gains(graph, paths, vertex_gain, cfg, exploring_direction_rad)
        best, vpath = _select_best(graph, paths, pg)
        diag.selection_s = time.perf_counter() - t
        extra = {"root": root, "graph": graph, "shortest_paths": paths, "vertex_gains": vertex_gain, "path_gains": pg,
                     "local_map": local_map}
        if best < 0:
            return fail("no path in the local graph leads to exploration gain", **extra)

        t = time.perf_counter()
        raw = graph.vertices[vpath]
        path = improve_path(local_map, raw, cfg) if cfg.path_improvement_enable else raw.copy()
        cut = truncate_path(local_map, path, cfg.traverse_length_max_m, cfg)
        if len(cut) >= 2 and segments_admissible(local_map, cut).all():
            path = cut
        else:
            path = _truncate_at_vertex(path, cfg.traverse_length_max_m)
        diag.improvement_s = time.perf_counter() - t
        diag.total_s = time.perf_counter() - t_start
        return LocalPlanResult(
            path=path,
            gain=float(pg.exploration_gain[best]),
            reason="",
            diagnostics=diag,
            best_vertex=int(best),
            vertex_path=vpath,
            **extra,
        )


class ShrinkingLocalPlanner(LocalPlanner):
    """The local planner, re-run in a smaller local bounding box when the adaptive box
    gave a local graph of (almost) no vertices.

    The adaptive box spans the PCA of all mapped points within mu_V (50 m); where the
    robot stands in a narrow passage next to a wider network (a ramp up from a
    junction, say), the box is mostly rock and unknown space, and graph building stops
    after its first batch of samples because so few were free. Halving the box (down
    to ``bounding_box_size_min_m``) keeps its orientation and fills it with vertices.
    """

    #: A graph with fewer vertices than this is re-built in a smaller box.
    min_vertices = 10
    #: At most this many halvings.
    max_shrinks = 2

    def plan(self, grid: Grid, position: np.ndarray, rng: np.random.Generator, *,
             bound: LocalBound | None = None, **kw: Any) -> LocalPlanResult:
        res = super().plan(grid, position, rng, bound=bound, **kw)
        size_min = 0.5 * np.sort(np.asarray(self.config.bounding_box_size_min_m, float))[::-1]
        for _ in range(self.max_shrinks):
            g = res.graph
            if bound is not None or g is None or g.bound is None or g.num_vertices >= self.min_vertices:
                break
            b = g.bound
            half = np.maximum(0.5 * b.half_extents_m, size_min)
            if np.allclose(half, b.half_extents_m):
                break
            res = super().plan(grid, position, rng, bound=LocalBound(b.centre, b.axes, half, b.num_points), **kw)
        return res


def _select_best(graph: LocalGraph, paths: ShortestPaths, pg: PathGains) -> tuple[int, list[int]]:
    """The vertex whose path has the highest exploration gain, and the vertices to
    command: its shortest path, less the last vertex when that one is hanging. Paths
    that would command nothing (only the robot) are skipped."""
    score = pg.exploration_gain.copy()
    score[0] = 0.0
    score[~paths.reachable] = 0.0
    # A hanging end whose parent is the root would command nothing.
    pred = paths.predecessor
    score[graph.hanging & (pred == 0)] = 0.0
    if not np.any(score > 0):
        return -1, []
    best = int(np.argmax(score))
    vpath = paths.path(best)
    if graph.hanging[best]:
        vpath = vpath[:-1]
    return best, vpath


def _truncate_at_vertex(path: np.ndarray, max_length_m: float) -> np.ndarray:
    """The longest prefix of whole segments within ``max_length_m`` (at least one segment)."""
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    cum = np.cumsum(seg)
    k = int(np.searchsorted(cum, max_length_m, side="right"))
    return path[: max(k, 1) + 1].copy()


def _assume_ground_under_robot(local_map: LocalMap, root: np.ndarray, cfg: GBPlannerConfig) -> None:
    """A legged robot stands on ground its LiDAR cannot see (the blind circle below the
    sensor): UNKNOWN voxels of the ground layer under the robot, within
    ``assumed_ground_radius_m``, with no rock between them and the body, count as
    ground."""
    radius = cfg.assumed_ground_radius_m
    if radius <= 0:
        return
    vs = local_map.voxel_size_m
    ground_z = root[2] - cfg.body_height_m - 0.5 * vs
    c, inside = local_map.index(np.array([[root[0], root[1], ground_z]]))
    if not inside[0]:
        return
    c = c[0]
    kg = int(c[2])
    kb = int(local_map.index(root[None])[0][0, 2])
    r = math.ceil(radius / vs)
    lo = np.maximum(c[:2] - r, 0)
    hi = np.minimum(c[:2] + r + 1, np.array(local_map.shape[:2]))
    occ = local_map.occupancy
    ii, jj = np.meshgrid(np.arange(lo[0], hi[0]), np.arange(lo[1], hi[1]), indexing="ij")
    disc = (ii - c[0]) ** 2 + (jj - c[1]) ** 2 <= (radius / vs) ** 2
    layer = occ[lo[0]:hi[0], lo[1]:hi[1], kg]
    above = occ[lo[0]:hi[0], lo[1]:hi[1], kg + 1:kb + 1]
    clear = np.all(above != OCCUPIED, axis=2) if above.shape[2] else np.ones_like(disc)
    # A column whose ground is already mapped lower or higher keeps it.
    mapped_below = np.any(occ[lo[0]:hi[0], lo[1]:hi[1], max(kg - 2, 0):kg] == OCCUPIED, axis=2)
    fill = disc & clear & (layer == UNKNOWN) & ~mapped_below
    layer[fill] = OCCUPIED
