"""The onboard map as GBPlanner2 is given it, and where it starts planning from.

A robot's map has gaps in its rock surface and cannot show a step or trench finer
than its voxels; the exploration skill hands the planner a map with those gaps sealed
(:func:`sealed_grid`, kept up to date by :class:`MapSealer`) and with rock where a
commanded path turned out blocked (:func:`blocked_spot`, :func:`mark_blocked_spots`),
and starts it from a pose whose robot box is clear of rock (:func:`start_pose`). Pure
numpy on a :class:`~delve.planners.occupancy.Grid`.
"""
from __future__ import annotations

import numpy as np

from ..geometry import nearest_segment
from ..navgraph import FACES, around
from ..occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from .config import GBPlannerConfig
from .local_map import LocalMap


def sealed_grid(grid: Grid) -> Grid:
    """A copy of ``grid`` in which UNKNOWN voxels that share a face with an OCCUPIED one
    are OCCUPIED: the mapped rock surface, one voxel thick, has gaps where the LiDAR's
    returns fell on a neighbouring voxel, and the planner's gain rays (one voxel per
    step) slip through them into the unknown rock behind, which then looks like
    hundreds of m3 of unexplored space forever. Openings wider than two voxels stay
    open, so real frontiers keep their gain."""
    occ = grid.occupancy
    rock = occ == OCCUPIED
    near = np.zeros_like(rock)
    for ax in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax], hi[ax] = slice(None, -1), slice(1, None)
        near[tuple(lo)] |= rock[tuple(hi)]
        near[tuple(hi)] |= rock[tuple(lo)]
    out = occ.copy()
    out[near & (occ == UNKNOWN)] = OCCUPIED
    return Grid(out, grid.origin, grid.voxel_size_m, grid.free)


class MapSealer:
    """:func:`sealed_grid` of one map, updated from the voxels that changed: a voxel's
    sealed value depends only on it and its six face neighbours, so only the changed
    voxels and their neighbours are sealed again (a whole-grid pass every plan was a
    quarter of a six-robot mission's time on a 1 km course). Memory: one byte per
    voxel of the grid, kept between updates. The grid it returns is its own array,
    changed in place by the next update: read it, never write it."""

    def __init__(self) -> None:
        self._out: np.ndarray | None = None

    def update(self, grid: Grid, changed: np.ndarray | None = None) -> Grid:
        """``sealed_grid(grid)`` after the voxels ``changed`` (flat indices) changed
        since the last update; the whole grid is sealed when ``changed`` is None, on
        the first update, or for a grid of another shape."""
        occ = grid.occupancy
        if changed is None or self._out is None or self._out.shape != occ.shape:
            self._out = sealed_grid(grid).occupancy
        elif len(changed):
            retest = around(np.asarray(changed, dtype=np.int64), grid.shape, [(0, 0, 0), *FACES])
            self._out.reshape(-1)[retest] = _sealed_values(occ, retest)
        return Grid(self._out, grid.origin, grid.voxel_size_m, grid.free)


def _sealed_values(occ: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """The values of :func:`sealed_grid` at the voxels ``flat`` of the occupancy ``occ``."""
    values = occ.reshape(-1)[flat]
    unknown = np.flatnonzero(values == UNKNOWN)
    ijk = np.unravel_index(flat[unknown], occ.shape)
    rock = np.zeros(len(unknown), dtype=bool)
    for d in FACES:
        n = [c + o for c, o in zip(ijk, d)]
        inside = np.all([(c >= 0) & (c < s) for c, s in zip(n, occ.shape)], axis=0)
        rock[inside] |= occ[n[0][inside], n[1][inside], n[2][inside]] == OCCUPIED
    values[unknown[rock]] = OCCUPIED
    return values


def mark_blocked_spots(grid: Grid, spots: list[np.ndarray], radius_m: float, below_m: float) -> Grid:
    """A copy of ``grid`` with rock at each spot: every voxel within ``radius_m``
    horizontally, from ``below_m`` under the spot to ``radius_m`` above it."""
    if not spots or radius_m <= 0:
        return grid
    occ = grid.occupancy.copy()
    vs = grid.voxel_size_m
    r = radius_m / vs
    for p in spots:
        lo = grid.to_index(np.array([[p[0] - radius_m, p[1] - radius_m, p[2] - below_m]]))[0]
        hi = grid.to_index(np.array([[p[0] + radius_m, p[1] + radius_m, p[2] + radius_m]]))[0] + 1
        lo, hi = np.maximum(lo, 0), np.minimum(hi, np.array(occ.shape))
        if np.any(hi <= lo):
            continue
        c = grid.to_index(np.asarray(p, float)[None])[0]
        ii, jj = np.meshgrid(np.arange(lo[0], hi[0]), np.arange(lo[1], hi[1]), indexing="ij")
        disc = (ii - c[0]) ** 2 + (jj - c[1]) ** 2 <= r * r
        occ[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]][disc] = OCCUPIED
    return Grid(occ, grid.origin, grid.voxel_size_m, None)


def blocked_spot(position: np.ndarray, path: np.ndarray | None, ahead_m: float) -> np.ndarray | None:
    """The point ``ahead_m`` in front of ``position`` (horizontally) towards where
    ``path`` went on from the segment nearest to it; None without a direction."""
    if path is None or len(path) == 0:
        return None
    pts = np.vstack([position, path]) if len(path) == 1 else path
    k = nearest_segment(pts, position)
    for q in pts[k + 1:]:
        d = (q - position)[:2]
        n = float(np.hypot(d[0], d[1]))
        if n > 0.05:
            return np.array([position[0] + d[0] / n * ahead_m, position[1] + d[1] / n * ahead_m, position[2]])
    return None


def start_pose(grid: Grid, config: GBPlannerConfig, position: np.ndarray, max_shift_m: float) -> np.ndarray:
    """Where the planner starts: the robot's position or, when the robot box there
    touches mapped rock (the robot stands close to a wall or on a sloping floor, and
    the box is rounded up to whole voxels), the nearest point at most
    ``max_shift_m`` away (sideways, or up) whose box is clear; the position itself
    when there is none."""
    position = np.asarray(position, float)
    if max_shift_m <= 0:
        return position
    lm = LocalMap(grid, position - max_shift_m - 1.0, position + max_shift_m + 1.0, config)
    if not lm.box_has_occupied(position):
        return position
    vs = grid.voxel_size_m
    n = int(max_shift_m // vs + 1e-9)
    steps = np.arange(-n, n + 1) * vs
    dx, dy, dz = np.meshgrid(steps, steps, steps[steps >= 0], indexing="ij")
    shifts = np.stack([dx.ravel(), dy.ravel(), dz.ravel()], axis=1)
    shifts = shifts[np.linalg.norm(shifts, axis=1) <= max_shift_m + 1e-9]
    shifts = shifts[np.argsort(np.linalg.norm(shifts, axis=1), kind="stable")]
    for d in shifts[1:]:
        p = position + d
        if lm.value(p[None])[0] == FREE and not lm.box_has_occupied(p):
            return p
    return position


__all__ = ["MapSealer", "blocked_spot", "mark_blocked_spots", "sealed_grid", "start_pose"]
