"""Synthetic point clouds (surfaces sampled on a regular grid) for the CSIRO frontier tests."""
from __future__ import annotations

import numpy as np

#: Sample spacing of the synthetic surfaces (m): three samples a side per 0.3 m voxel.
SPACING_M = 0.1


def rectangle(origin, u, v, spacing: float = SPACING_M) -> np.ndarray:
    """Points on the rectangle origin + s*u + t*v, s, t in [0, 1), ``spacing`` apart."""
    origin, u, v = (np.asarray(x, float) for x in (origin, u, v))
    s = np.arange(0.0, np.linalg.norm(u), spacing) / np.linalg.norm(u)
    t = np.arange(0.0, np.linalg.norm(v), spacing) / np.linalg.norm(v)
    s, t = np.meshgrid(s, t, indexing="ij")
    return origin + s.reshape(-1, 1) * u + t.reshape(-1, 1) * v


def corridor(x0: float, x1: float, width: float = 4.0, height: float = 3.0, *,
             closed_at: tuple[float, ...] = ()) -> np.ndarray:
    """A straight drift along x from x0 to x1 (floor z = 0, walls y = +-width/2, ceiling z =
    height), open at both ends unless an end wall is put at each x of ``closed_at``."""
    w, h, length = width, height, x1 - x0
    parts = [rectangle((x0, -w / 2, 0), (length, 0, 0), (0, w, 0)),
             rectangle((x0, -w / 2, h), (length, 0, 0), (0, w, 0)),
             rectangle((x0, -w / 2, 0), (length, 0, 0), (0, 0, h)),
             rectangle((x0, w / 2, 0), (length, 0, 0), (0, 0, h))]
    parts += [rectangle((x, -w / 2, 0), (0, w, 0), (0, 0, h)) for x in closed_at]
    return np.concatenate(parts)


def box(lo, hi, *, hole_at_x: float | None = None, hole: tuple | None = None) -> np.ndarray:
    """The six walls of the box lo..hi; with ``hole`` = ((y0, y1), (z0, z1)) the wall at
    x = ``hole_at_x`` has an opening there."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    d = hi - lo
    parts = [rectangle(lo, (d[0], 0, 0), (0, d[1], 0)), rectangle((lo[0], lo[1], hi[2]), (d[0], 0, 0), (0, d[1], 0)),
             rectangle(lo, (d[0], 0, 0), (0, 0, d[2])), rectangle((lo[0], hi[1], lo[2]), (d[0], 0, 0), (0, 0, d[2]))]
    for x in (lo[0], hi[0]):
        wall = rectangle((x, lo[1], lo[2]), (0, d[1], 0), (0, 0, d[2]))
        if hole is not None and x == hole_at_x:
            (y0, y1), (z0, z1) = hole
            inside = (wall[:, 1] > y0) & (wall[:, 1] < y1) & (wall[:, 2] > z0) & (wall[:, 2] < z1)
            wall = wall[~inside]
        parts.append(wall)
    return np.concatenate(parts)


def room_with_doorway(open_door: bool = True) -> np.ndarray:
    """A 6 x 6 x 3 m room around the origin whose wall at x = 3 has a 1.2 x 2 m doorway into a
    second room (x 3..7), all of it within 9 m of the origin: the door is an opening, no
    maximum-range frontier."""
    hole = ((-0.6, 0.6), (-1.0, 1.0)) if open_door else None
    first = box((-3, -3, -1), (3, 3, 2), hole_at_x=3.0, hole=hole)
    second = box((3, -3, -1), (7, 3, 2))
    second = second[second[:, 0] > 3.0 + 1e-9]       # the shared wall belongs to the first room
    return np.concatenate([first, second])


def banded_scan(surface: np.ndarray, sensor, band_deg: float = 15.0, range_m: float = 30.0) -> np.ndarray:
    """The points of ``surface`` a LiDAR at ``sensor`` returns when it sees only elevations within
    +-``band_deg`` (a legged robot's Velodyne Puck); a convex drift, so no point hides another."""
    d = surface - np.asarray(sensor, float)
    r = np.linalg.norm(d, axis=1)
    elevation = np.degrees(np.arcsin(d[:, 2] / r))
    return surface[(np.abs(elevation) <= band_deg) & (r <= range_m)]
