"""Small synthetic underground worlds as occupancy grids, for unit tests and benchmarks.

Tunnels are carved out of solid rock: each :class:`Tunnel` is a straight segment with
a floor that may rise or fall (a slope), a width and a height. The result can look
like a robot's onboard map: only voxels within ``known`` are mapped, and with
``shell_only`` the rock is OCCUPIED only where it borders free space (a LiDAR sees
the surface, never the rock behind it), as in ``delve.sim``'s voxel maps.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..occupancy import FREE, OCCUPIED, UNKNOWN, Grid


@dataclass(frozen=True)
class Tunnel:
    """A straight tunnel with flat ends: floor centre line from ``start`` to ``end``
    (x, y, z of the floor)."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    width_m: float = 4.0
    height_m: float = 3.0


@dataclass(frozen=True)
class Box:
    """An axis-aligned box, lower and upper corners in metres."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


def carve(
    size_m: Sequence[float],
    voxel_size_m: float,
    tunnels: Sequence[Tunnel],
    *,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    holes: Sequence[Box] = (),
    known: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray] | Sequence[Box] | None = None,
    unknown: Sequence[Box] = (),
    shell_only: bool = True,
) -> Grid:
    """Carve ``tunnels`` (and free ``holes``) out of solid rock.

    ``known``: the mapped part, as boxes or as a function of the voxel centres' x, y, z
    (broadcast arrays) returning a boolean mask; everything else is UNKNOWN. ``unknown``
    boxes are set UNKNOWN afterwards (e.g. the unseen inside of a shaft).
    """
    vs = float(voxel_size_m)
    shape = tuple(math.ceil(s / vs) for s in size_m)
    origin_arr = np.asarray(origin, float)
    free = np.zeros(shape, dtype=bool)
    for t in tunnels:
        _carve_tunnel(free, origin_arr, vs, t)
    for h in holes:
        free[_box_slices(h, origin_arr, vs, shape)] = True
    occ = np.where(free, FREE, OCCUPIED).astype(np.int8)
    if shell_only:
        near_free = ndimage.binary_dilation(free, structure=np.ones((3, 3, 3), bool))
        occ[~free & ~near_free] = UNKNOWN
    if known is not None:
        mask = np.zeros(shape, dtype=bool)
        if callable(known):
            x, y, z = _centres(origin_arr, vs, shape)
            mask |= np.broadcast_to(known(x, y, z), shape)
        else:
            for b in known:
                mask[_box_slices(b, origin_arr, vs, shape)] = True
        occ[~mask] = UNKNOWN
    for b in unknown:
        occ[_box_slices(b, origin_arr, vs, shape)] = UNKNOWN
    return Grid(occupancy=occ, origin=origin_arr, voxel_size_m=vs)


def _centres(origin: np.ndarray, vs: float, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x = origin[0] + (np.arange(shape[0]) + 0.5) * vs
    y = origin[1] + (np.arange(shape[1]) + 0.5) * vs
    z = origin[2] + (np.arange(shape[2]) + 0.5) * vs
    return x[:, None, None], y[None, :, None], z[None, None, :]


def _box_slices(b: Box, origin: np.ndarray, vs: float, shape: tuple[int, ...]) -> tuple[slice, slice, slice]:
    lo = np.clip(np.floor((np.asarray(b.lo) - origin) / vs + 1e-9).astype(int), 0, shape)
    hi = np.clip(np.ceil((np.asarray(b.hi) - origin) / vs - 1e-9).astype(int), 0, shape)
    return tuple(slice(int(a), int(c)) for a, c in zip(lo, hi))  # type: ignore[return-value]


def _carve_tunnel(free: np.ndarray, origin: np.ndarray, vs: float, t: Tunnel) -> None:
    p0 = np.asarray(t.start, float)
    p1 = np.asarray(t.end, float)
    half_w = 0.5 * t.width_m
    lo = np.minimum(p0, p1) - np.array([half_w, half_w, 0.0])
    hi = np.maximum(p0, p1) + np.array([half_w, half_w, t.height_m])
    sl = _box_slices(Box(tuple(lo), tuple(hi)), origin, vs, free.shape)
    if any(s.stop <= s.start for s in sl):
        return
    x = origin[0] + (np.arange(sl[0].start, sl[0].stop) + 0.5) * vs
    y = origin[1] + (np.arange(sl[1].start, sl[1].stop) + 0.5) * vs
    z = origin[2] + (np.arange(sl[2].start, sl[2].stop) + 0.5) * vs
    d = p1[:2] - p0[:2]
    L2 = float(d @ d)
    rx = x[:, None] - p0[0]
    ry = y[None, :] - p0[1]
    if L2 > 0:
        s_raw = (rx * d[0] + ry * d[1]) / L2
        s = np.clip(s_raw, 0.0, 1.0)
        within = (s_raw >= 0.0) & (s_raw <= 1.0)
    else:
        s = np.zeros((len(x), len(y)))
        within = np.ones((len(x), len(y)), bool)
    dist = np.hypot(rx - s * d[0], ry - s * d[1])
    floor = p0[2] + s * (p1[2] - p0[2])
    inside_xy = (dist <= half_w) & within
    zz = z[None, None, :]
    inside = inside_xy[:, :, None] & (zz >= floor[:, :, None]) & (zz <= floor[:, :, None] + t.height_m)
    free[sl] |= inside


# --- ready-made worlds ------------------------------------------------------------------


def straight_tunnel(
    length_m: float = 30.0,
    width_m: float = 4.0,
    height_m: float = 3.0,
    voxel_size_m: float = 0.2,
    *,
    yaw_deg: float = 0.0,
    mapped_from_m: float = 0.0,
    mapped_to_m: float | None = None,
    closed_start: bool = True,
    shell_only: bool = True,
) -> tuple[Grid, np.ndarray, np.ndarray]:
    """A straight tunnel along ``yaw_deg`` with a flat floor at z = 1 m.

    The tunnel runs from 1 m to ``length_m`` - 1 m along its axis; it is mapped
    between ``mapped_from_m`` and ``mapped_to_m`` (default: all). ``closed_start``
    leaves rock (a mapped dead end) at the start. Returns the grid and the world
    positions of the tunnel's start and end floor centres.
    """
    yaw = math.radians(yaw_deg)
    u = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    margin = width_m + 2.0
    extent_xy = np.abs(u[:2]) * length_m + margin * 2
    size = (float(extent_xy[0]), float(extent_xy[1]), height_m + 3.0)
    centre = np.array([size[0] / 2, size[1] / 2, 1.0])
    start = centre - u * (length_m / 2 - 1.0)
    end = centre + u * (length_m / 2 - 1.0)
    first_floor = start if closed_start else centre - u * (length_m / 2 + margin)
    tunnel = Tunnel(tuple(first_floor), tuple(end), width_m, height_m)
    to = length_m if mapped_to_m is None else mapped_to_m
    first = centre - u * (length_m / 2)

    def known(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        along = (x - first[0]) * u[0] + (y - first[1]) * u[1]
        return (along >= mapped_from_m) & (along <= to) & (z > -np.inf)

    grid = carve(size, voxel_size_m, [tunnel], known=known, shell_only=shell_only)
    return grid, start, end


def t_junction(
    voxel_size_m: float = 0.2, width_m: float = 3.0, height_m: float = 3.0, arm_m: float = 12.0
) -> tuple[Grid, np.ndarray]:
    """A T junction: a tunnel along x with a branch along +y from its middle; fully
    mapped within 6 m of the junction, unknown beyond. Returns the grid and the junction."""
    size = (2 * arm_m + 4.0, arm_m + width_m + 4.0, height_m + 3.0)
    j = np.array([size[0] / 2, 2.0 + width_m / 2, 1.0])
    tunnels = [
        Tunnel((2.0, j[1], 1.0), (size[0] - 2.0, j[1], 1.0), width_m, height_m),
        Tunnel(tuple(j), (j[0], size[1] - 2.0, 1.0), width_m, height_m),
    ]

    def known(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        return (np.abs(x - j[0]) <= 6.0) & (y - j[1] <= 6.0) & (z > -np.inf)

    return carve(size, voxel_size_m, tunnels, known=known), j


def slope_tunnel(
    angle_deg: float,
    voxel_size_m: float = 0.2,
    width_m: float = 4.0,
    height_m: float = 3.0,
    flat_m: float = 6.0,
    slope_m: float = 8.0,
) -> tuple[Grid, np.ndarray, np.ndarray]:
    """A flat tunnel along x, then a ramp of ``angle_deg`` over ``slope_m`` horizontally,
    then flat again; fully mapped. Returns the grid, the bottom and the top of the ramp
    (floor points)."""
    rise = math.tan(math.radians(angle_deg)) * slope_m
    size = (2 * flat_m + slope_m + 4.0, width_m + 4.0, rise + height_m + 3.0)
    y = size[1] / 2
    z0 = 1.0
    bottom = np.array([2.0 + flat_m, y, z0])
    top = np.array([2.0 + flat_m + slope_m, y, z0 + rise])
    tunnels = [
        Tunnel((2.0, y, z0), tuple(bottom), width_m, height_m),
        Tunnel(tuple(bottom), tuple(top), width_m, height_m),
        Tunnel(tuple(top), (size[0] - 2.0, y, z0 + rise), width_m, height_m),
    ]
    return carve(size, voxel_size_m, tunnels), bottom, top


def shaft_tunnel(
    voxel_size_m: float = 0.2,
    width_m: float = 4.0,
    height_m: float = 3.0,
    length_m: float = 20.0,
    shaft_m: float = 3.0,
) -> tuple[Grid, np.ndarray, Box]:
    """A fully mapped flat tunnel along x whose floor has a hole (a shaft) across its
    whole width in the middle, ``shaft_m`` long; the shaft's inside was never seen, so
    it is UNKNOWN. Returns the grid, the tunnel's west end floor point and the shaft
    box (the hole)."""
    depth = 6.0
    size = (length_m + 4.0, width_m + 4.0, depth + height_m + 3.0)
    y = size[1] / 2
    z0 = depth + 1.0
    cx = size[0] / 2
    hole = Box((cx - shaft_m / 2, y - width_m / 2 - 0.5, 1.0), (cx + shaft_m / 2, y + width_m / 2 + 0.5, z0))
    grid = carve(
        size,
        voxel_size_m,
        [Tunnel((2.0, y, z0), (size[0] - 2.0, y, z0), width_m, height_m)],
        holes=[hole],
        unknown=[hole],
    )
    return grid, np.array([2.0, y, z0]), hole


def tunnel_network(
    voxel_size_m: float = 0.2,
    extent_m: float = 160.0,
    spacing_m: float = 40.0,
    width_m: float = 4.0,
    height_m: float = 3.5,
    ramp_rise_m: float = 3.0,
    shell_only: bool = True,
) -> tuple[Grid, list[Tunnel]]:
    """A grid of crossing tunnels (a few hundred metres of them) with ramps between
    two floor levels, fully mapped; callers hide the unexplored part themselves."""
    n = int(extent_m // spacing_m)
    size = (extent_m, extent_m, ramp_rise_m + height_m + 3.0)
    tunnels: list[Tunnel] = []
    z0 = 1.0
    lo, hi = spacing_m / 2, spacing_m / 2 + (n - 1) * spacing_m
    for i in range(n):
        c = spacing_m / 2 + i * spacing_m
        zc = z0 + (ramp_rise_m if i % 2 else 0.0)
        # east-west tunnel at y = c, floor at zc
        tunnels.append(Tunnel((lo - width_m / 2, c, zc), (hi + width_m / 2, c, zc), width_m, height_m))
    for i in range(n):
        c = spacing_m / 2 + i * spacing_m
        # north-south tunnel at x = c, ramping between the crossings' floor levels
        for k in range(n - 1):
            y0, y1 = spacing_m / 2 + k * spacing_m, spacing_m / 2 + (k + 1) * spacing_m
            za = z0 + (ramp_rise_m if k % 2 else 0.0)
            zb = z0 + (ramp_rise_m if (k + 1) % 2 else 0.0)
            w = width_m / 2 + 1.0
            tunnels.append(Tunnel((c, y0, za), (c, y0 + w, za), width_m, height_m))
            tunnels.append(Tunnel((c, y0 + w, za), (c, y1 - w, zb), width_m, height_m))
            tunnels.append(Tunnel((c, y1 - w, zb), (c, y1, zb), width_m, height_m))
    return carve(size, voxel_size_m, tunnels, shell_only=shell_only), tunnels
