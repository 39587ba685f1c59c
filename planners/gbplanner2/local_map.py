"""Map queries of one planning iteration: collision checks and ground projection.

A :class:`LocalMap` crops the occupancy grid to a region (the local bounding box plus
margins) and precomputes, once per iteration, the two arrays that make every later
query an O(1) lookup:

* ``box_free``: True where the robot's bounding box, centred on that voxel, holds only
  FREE voxels (UNKNOWN is *not* free for collision), by a separable box erosion;
* ``ground_index`` (legged robots): in each column, the index of the highest non-free
  voxel at or below each voxel, by a running maximum along z.

On top of these it answers the questions of Algorithm 2 for whole batches of points
and edges at once: is a point collision-free, where is the ground below it and is it
*attached* (mapped, occupied ground) or *hanging*, and is an edge admissible (a
collision-free straight segment for aerial robots; for legged robots a segment whose
points, projected onto the ground, are supported and whose inclination and steps are
within the limits).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from .config import GBPlannerConfig

#: Ground status of a projected point.
GROUND_ATTACHED = 1  # occupied ground found below (directly or on the circle)
GROUND_NONE = 0  # no mapped ground below: a hanging point
GROUND_BLOCKED = -1  # the point itself is not in free space


def box_half_voxels(size_m: tuple[float, float, float] | np.ndarray, voxel_size_m: float) -> np.ndarray:
    """Voxels on each side of the centre voxel that a box of ``size_m`` overlaps."""
    half = 0.5 * np.asarray(size_m, float) / voxel_size_m
    return np.maximum(np.ceil(half + 0.5).astype(np.int64) - 1, 0)


@dataclass(frozen=True)
class EdgeCheck:
    """Result of a batched edge check: which edges are admissible, and their lengths."""

    admissible: np.ndarray
    length_m: np.ndarray


class LocalMap:
    """A cropped copy of the grid with per-iteration lookup tables.

    ``lo_m``/``hi_m`` bound the region where points will be queried; the crop adds the
    robot box and, for legged robots, the ground search depth around it. Voxels outside
    the grid read as UNKNOWN. ``clear_box_at`` marks UNKNOWN voxels inside the robot
    box at that point FREE (the robot stands there, so the space it occupies is free).
    """

    def __init__(
        self,
        grid: Grid,
        lo_m: np.ndarray,
        hi_m: np.ndarray,
        config: GBPlannerConfig,
        clear_box_at: np.ndarray | None = None,
    ) -> None:
        self.config = config
        self.grid = grid
        vs = float(grid.voxel_size_m)
        self.voxel_size_m = vs
        self.box_half = box_half_voxels(config.robot_box_size_m, vs)
        pad = self.box_half + 2
        below = 0
        if config.is_legged:
            below = math.ceil((config.body_height_m + config.ground_search_depth_m) / vs) + 1
        lo_idx = grid.to_index(np.asarray(lo_m, float)[None])[0] - pad
        hi_idx = grid.to_index(np.asarray(hi_m, float)[None])[0] + pad + 1
        lo_idx[2] -= below
        self.lo_idx = lo_idx
        self.shape = tuple(int(v) for v in (hi_idx - lo_idx))
        self._shape_u = np.array(self.shape, dtype=np.uint64)
        self.origin = grid.origin + lo_idx * vs
        self.occupancy = _crop(grid.occupancy, lo_idx, hi_idx)
        if clear_box_at is not None:
            self._clear_unknown_box(np.asarray(clear_box_at, float))
        free = self.occupancy == FREE
        self.box_free = erode(free, self.box_half)
        self.ground_index: np.ndarray | None = None
        if config.is_legged:
            nz = self.shape[2]
            dtype = np.int8 if nz < 127 else (np.int16 if nz < 32000 else np.int32)
            levels = np.arange(nz, dtype=dtype)
            ground = np.where(~free, levels, dtype(-1))
            # The running maximum along z, one layer at a time: np.maximum.accumulate
            # along the last axis runs one short loop per column and is twice as slow.
            for k in range(1, nz):
                np.maximum(ground[:, :, k - 1], ground[:, :, k], out=ground[:, :, k])
            self.ground_index = ground
        self._strides = np.array([self.shape[1] * self.shape[2], self.shape[2], 1], dtype=np.int64)
        circle = np.linspace(0.0, 2.0 * math.pi, max(config.ground_circle_points, 1), endpoint=False)
        self._circle = config.ground_circle_radius_m * np.stack([np.cos(circle), np.sin(circle)], axis=1)

    # --- basic lookups ------------------------------------------------------------
    def index(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Crop indices (N, 3) of world points and a mask of those inside the crop.

        Computed on the transposed (3, N) coordinates and returned as an (N, 3) view of
        them: numpy broadcasts an (N, 3) array against a 3-vector one short row at a
        time, several times slower on the batches of Algorithm 2."""
        p = np.asarray(points, float).reshape(-1, 3)
        idx_t = np.floor((p.T - self.origin[:, None]) / self.voxel_size_m).astype(np.int64)
        below = idx_t.view(np.uint64) < self._shape_u[:, None]  # a negative index wraps to a huge one
        return idx_t.T, below[0] & below[1] & below[2]

    def _flat(self, idx: np.ndarray, inside: np.ndarray) -> np.ndarray:
        s = self._strides
        return np.where(inside, idx[:, 0] * s[0] + idx[:, 1] * s[1] + idx[:, 2], 0)

    def value(self, points: np.ndarray) -> np.ndarray:
        """Occupancy at world points (UNKNOWN outside the crop)."""
        idx, inside = self.index(np.atleast_2d(points))
        v = self.occupancy.reshape(-1)[self._flat(idx, inside)]
        return np.where(inside, v, UNKNOWN).astype(np.int8)

    def is_box_free(self, points: np.ndarray) -> np.ndarray:
        """Whether the robot box centred at each point holds only FREE voxels."""
        idx, inside = self.index(np.atleast_2d(points))
        return inside & self.box_free.reshape(-1)[self._flat(idx, inside)]

    # --- ground projection (legged robots) ------------------------------------------
    def project_to_ground(
        self, points: np.ndarray, max_depth_m: float | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Project points down onto the ground.

        Returns ``(ground_z, status)``: the world height of the top of the ground voxel
        below each point and its status (:data:`GROUND_ATTACHED`, :data:`GROUND_NONE`,
        :data:`GROUND_BLOCKED`). The column below the point is searched for the first
        non-free voxel; when it is not OCCUPIED (unknown: unmapped ground, or none
        within ``max_depth_m``), the columns on a circle of ``ground_circle_radius_m``
        around the point are searched too, and the shallowest occupied ground found
        there is used (ground voxels are sometimes mapped free by mistake). For a point
        with no ground, ``ground_z`` is the top of the first non-free voxel below it,
        or the point's height less ``max_depth_m`` (or the crop's floor).
        """
        if self.ground_index is None:
            raise ValueError("ground projection needs a legged configuration")
        pts = np.atleast_2d(np.asarray(points, float))
        gz, status = self._column_ground(pts, max_depth_m)
        need = np.flatnonzero(status == GROUND_NONE)
        if len(need) and len(self._circle):
            m = len(self._circle)
            ring = np.repeat(pts[need], m, axis=0)
            ring[:, :2] += np.tile(self._circle, (len(need), 1))
            rz, rstatus = self._column_ground(ring, max_depth_m)
            rz = np.where(rstatus == GROUND_ATTACHED, rz, -np.inf).reshape(len(need), m)
            best = rz.max(axis=1)
            found = np.isfinite(best)
            gz[need[found]] = best[found]
            status[need[found]] = GROUND_ATTACHED
        return gz, status

    def _column_ground(
        self, pts: np.ndarray, max_depth_m: float | None
    ) -> tuple[np.ndarray, np.ndarray]:
        assert self.ground_index is not None
        vs = self.voxel_size_m
        idx, inside = self.index(pts)
        flat = self._flat(idx, inside)
        start_free = inside & (self.occupancy.reshape(-1)[flat] == FREE)
        g = self.ground_index.reshape(-1)[flat].astype(np.int64)
        g = np.where(inside, g, -1)
        # Ground top (world z) of the first non-free voxel below the point.
        gz = self.origin[2] + (g + 1) * vs
        has = g >= 0
        gflat = np.where(has, flat - (idx[:, 2] - g), 0)
        kind = np.where(has, self.occupancy.reshape(-1)[gflat], UNKNOWN)
        depth = pts[:, 2] - gz
        depth_ok = has
        if max_depth_m is not None:
            depth_ok = has & (depth <= max_depth_m)
        status = np.where(start_free & depth_ok & (kind == OCCUPIED), GROUND_ATTACHED, GROUND_NONE)
        status = np.where(start_free, status, GROUND_BLOCKED).astype(np.int8)
        floor = pts[:, 2] - max_depth_m if max_depth_m is not None else np.full(len(pts), self.origin[2])
        gz = np.where(depth_ok, gz, floor)
        return gz, status

    # --- edges ------------------------------------------------------------------------
    def check_edges(
        self, a: np.ndarray, b: np.ndarray, hanging_end: np.ndarray | None = None
    ) -> EdgeCheck:
        """Admissibility of the edges ``a[i] -> b[i]`` (AdmissibleEdge of Algorithm 2).

        Aerial robots: the robot box is free at points along the straight segment, no
        farther apart than a voxel. Legged robots (``ProjectEdge``): the points along
        the segment are projected onto the ground; each must be supported, the body box
        above it free, neighbouring ground points at most ``max_step_m`` apart in height
        and the inclination over ``inclination_window_m`` at most
        ``max_inclination_deg``. An edge with a *hanging* end (``hanging_end``) has no
        ground to project onto: its straight segment must be collision-free and its
        inclination within the limit.
        """
        a = np.atleast_2d(np.asarray(a, float))
        b = np.atleast_2d(np.asarray(b, float))
        e = len(a)
        length = np.linalg.norm(b - a, axis=1)
        if e == 0:
            return EdgeCheck(np.zeros(0, bool), length)
        vs = self.voxel_size_m
        nseg = np.maximum(np.ceil(length / vs).astype(np.int64), 1)
        counts = nseg + 1
        first = np.cumsum(counts) - counts
        total = int(counts.sum())
        eid = np.repeat(np.arange(e), counts)
        i_in_edge = np.arange(total) - first[eid]
        t = i_in_edge / nseg[eid]
        # (3, total) then viewed as (total, 3): see index().
        pts = (np.take(a.T, eid, axis=1) + np.take((b - a).T, eid, axis=1) * t).T
        if not self.config.is_legged:
            ok_pts = self.is_box_free(pts)
            bad = np.bincount(eid[~ok_pts], minlength=e)
            return EdgeCheck(bad == 0, length)

        hang = np.zeros(e, bool) if hanging_end is None else np.asarray(hanging_end, bool)
        cfg = self.config
        tan_max = math.tan(math.radians(cfg.max_inclination_deg))
        # Straight-segment checks (used as they are for edges with a hanging end).
        dxy_edge = np.linalg.norm((b - a)[:, :2], axis=1)
        straight_incl_ok = np.abs(b[:, 2] - a[:, 2]) <= tan_max * dxy_edge + 1e-9
        # Projected checks.
        gz, status = self.project_to_ground(pts, max_depth_m=cfg.body_height_m + cfg.ground_search_depth_m)
        proj = pts.copy(order="K")
        proj[:, 2] = np.where(status == GROUND_ATTACHED, gz + cfg.body_height_m, pts[:, 2])
        hang_pt = hang[eid]
        use_straight = hang_pt
        check_pts = np.where(use_straight, pts.T, proj.T).T
        ok = self.is_box_free(check_pts)
        ok &= use_straight | (status == GROUND_ATTACHED)
        bad = np.bincount(eid[~ok], minlength=e) > 0
        # Steps between neighbouring ground points.
        same = eid[1:] == eid[:-1]
        dz = np.abs(np.diff(proj[:, 2]))
        step_bad = same & (dz > cfg.max_step_m + 1e-9) & ~hang_pt[1:]
        bad |= np.bincount(eid[1:][step_bad], minlength=e) > 0
        # Inclination over a window of neighbouring points (at least the whole edge).
        step_xy = np.where(nseg > 0, dxy_edge / nseg, 0.0)
        lag_e = np.maximum(1, np.minimum(nseg, np.ceil(cfg.inclination_window_m / np.maximum(step_xy, 1e-9)))).astype(np.int64)
        j = np.arange(total) + lag_e[eid]
        valid = (j < total)
        j = np.where(valid, j, 0)
        valid &= eid[j] == eid
        valid &= ~hang_pt
        dz_w = np.abs(proj[j, 2] - proj[:, 2])
        dx_w, dy_w = proj[j, 0] - proj[:, 0], proj[j, 1] - proj[:, 1]
        dxy_w = np.sqrt(dx_w * dx_w + dy_w * dy_w)
        incl_bad = valid & (dz_w > tan_max * dxy_w + 1e-9)
        bad |= np.bincount(eid[incl_bad], minlength=e) > 0
        admissible = ~bad & np.where(hang, straight_incl_ok, True)
        return EdgeCheck(admissible, length)

    def _clear_unknown_box(self, point: np.ndarray) -> None:
        idx, inside = self.index(point[None])
        if not inside[0]:
            return
        c = idx[0]
        lo = np.maximum(c - self.box_half, 0)
        hi = np.minimum(c + self.box_half + 1, np.array(self.shape))
        sub = self.occupancy[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        sub[sub == UNKNOWN] = FREE

    def box_has_occupied(self, point: np.ndarray) -> bool:
        """Whether an OCCUPIED voxel lies inside the robot box at ``point``."""
        idx, inside = self.index(np.asarray(point, float)[None])
        if not inside[0]:
            return False
        c = idx[0]
        lo = np.maximum(c - self.box_half, 0)
        hi = np.minimum(c + self.box_half + 1, np.array(self.shape))
        sub = self.occupancy[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        return bool(np.any(sub == OCCUPIED))


def erode(mask: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Binary erosion of a 3-D mask by a box of ``2 * half + 1`` voxels per axis (outside
    the array counts as False), by AND-ing shifted copies, doubling the window."""
    out = mask.copy()
    for axis in range(3):
        h = int(half[axis])
        if h <= 0:
            continue
        n = out.shape[axis]
        width = 2 * h + 1
        if width > n:
            out[...] = False
            return out
        # acc[i] = AND of out[i : i + w] for growing w (w doubles up to width).
        acc = out.copy()
        w = 1
        while w < width:
            step = min(w, width - w)
            a = [slice(None)] * 3
            b = [slice(None)] * 3
            a[axis] = slice(0, n - step)
            b[axis] = slice(step, n)
            acc[tuple(a)] &= acc[tuple(b)]
            tail = [slice(None)] * 3
            tail[axis] = slice(n - step, n)
            acc[tuple(tail)] = False
            w += step
        # Centre the window: out[i] = acc[i - h].
        res = np.zeros_like(out)
        src = [slice(None)] * 3
        dst = [slice(None)] * 3
        src[axis] = slice(0, n - h)
        dst[axis] = slice(h, n)
        res[tuple(dst)] = acc[tuple(src)]
        out = res
    return out


def _crop(occ: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """occ[lo:hi] as a new array, UNKNOWN where the window leaves the grid."""
    shape = np.array(occ.shape)
    out = np.full(tuple(int(v) for v in hi - lo), UNKNOWN, dtype=np.int8)
    src_lo = np.maximum(lo, 0)
    src_hi = np.minimum(hi, shape)
    if np.any(src_hi <= src_lo):
        return out
    dst_lo = src_lo - lo
    dst_hi = dst_lo + (src_hi - src_lo)
    out[dst_lo[0]:dst_hi[0], dst_lo[1]:dst_hi[1], dst_lo[2]:dst_hi[2]] = occ[
        src_lo[0]:src_hi[0], src_lo[1]:src_hi[1], src_lo[2]:src_hi[2]
    ]
    return out
