"""Volumetric gain (Algorithm 3) and the exploration gain of paths (Algorithm 1).

VolumetricGain(v) is the unknown volume a depth sensor at ``v`` would see: rays are
cast over the sensor's field of view [F_H, F_V] up to its range d_max, and every
UNKNOWN voxel a ray passes before it hits an OCCUPIED one adds the volume that the
ray stands for at that range (solid angle x r^2 x step). Voxels outside the grid are
unknown, so a ray that leaves the grid adds the rest of its length analytically.

Rays are marched together, all vertices' rays in one numpy array, in chunks of
steps; a ray leaves the batch when it hits rock, leaves the grid or reaches d_max.

ComputeVolumetricGain(G_L) optionally computes the gain only on the leaves of the
shortest-path tree, clustered with radius rho (a vertex within rho of one whose gain
was computed takes that gain), and scales the gain of hanging vertices by
exp(-gamma_H).

ExplorationGain(sigma) of a path (GBPlanner1's formulation) sums the gains of its
vertices, each discounted by exp(-gamma_D * distance along the path), and scales the
sum by exp(-gamma_S * deviation of the path from the exploring direction).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.spatial import cKDTree

from ..occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from .config import GBPlannerConfig
from .graph import LocalGraph, ShortestPaths


@dataclass(frozen=True)
class SensorRays:
    """The gain rays: a ring of ``ring_bins`` azimuths over 360 deg times
    ``elevation_bins`` elevations over F_V (ray ``j * elevation_bins + e``), of which a
    sensor with heading h uses the ``fov_bins`` azimuths centred in [h - F_H/2, h + F_H/2].
    ``solid_angle_sr`` is the solid angle each ray stands for."""

    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    solid_angle_sr: np.ndarray
    ring_bins: int
    elevation_bins: int
    fov_bins: int
    ring_azimuth_rad: float = 0.0

    @property
    def count(self) -> int:
        """Rays per sensor pose."""
        return self.fov_bins * self.elevation_bins

    def unit_directions(self) -> np.ndarray:
        """(ring_bins * elevation_bins, 3) unit vectors of every ray of the ring."""
        ce = np.cos(self.elevation_rad)
        return np.stack([ce * np.cos(self.azimuth_rad), ce * np.sin(self.azimuth_rad), np.sin(self.elevation_rad)], axis=1)

    def ray_ids(self, headings_rad: np.ndarray) -> np.ndarray:
        """(N, count) indices of the rays a sensor with each heading casts."""
        h = np.atleast_1d(np.asarray(headings_rad, float))
        e = np.arange(self.elevation_bins)
        if self.fov_bins >= self.ring_bins:
            j = np.broadcast_to(np.arange(self.ring_bins), (len(h), self.ring_bins))
        else:
            step = 2.0 * math.pi / self.ring_bins
            fov = self.fov_bins * step
            # ray j points along ring_azimuth - pi + j * step
            j0 = np.ceil((h - fov / 2 - self.ring_azimuth_rad + math.pi) / step).astype(np.int64)
            j = (j0[:, None] + np.arange(self.fov_bins)[None, :]) % self.ring_bins
        return (j[:, :, None] * self.elevation_bins + e[None, None, :]).reshape(len(h), -1)


def sensor_rays(config: GBPlannerConfig, ring_azimuth_rad: float = 0.0) -> SensorRays:
    """Rays over 360 deg x F_V, about ``gain_ray_resolution_*`` apart: an odd number of
    elevations (one ring is level) and a ring of a multiple of 4 azimuths, one of which
    points along ``ring_azimuth_rad`` (the local bounding box's first axis: rays run
    straight along the tunnel and across it, both ways)."""
    ring = max(4, 4 * round(360.0 / config.gain_ray_resolution_horizontal_deg / 4.0))
    d_az = 2.0 * math.pi / ring
    fov_bins = min(ring, max(1, round(math.radians(config.sensor_fov_horizontal_deg) / d_az)))
    fv = math.radians(config.sensor_fov_vertical_deg)
    n_el = max(1, round(config.sensor_fov_vertical_deg / config.gain_ray_resolution_vertical_deg))
    n_el += 1 - n_el % 2
    d_el = fv / n_el
    az = ring_azimuth_rad - math.pi + np.arange(ring) * d_az
    el = -fv / 2 + (np.arange(n_el) + 0.5) * d_el
    A, E = np.meshgrid(az, el, indexing="ij")
    omega = d_az * (np.sin(E + d_el / 2) - np.sin(E - d_el / 2))
    return SensorRays(A.ravel(), E.ravel(), omega.ravel(), ring, n_el, fov_bins, float(ring_azimuth_rad))


def volumetric_gain(
    grid: Grid,
    origins: np.ndarray,
    config: GBPlannerConfig,
    headings_rad: np.ndarray | float = 0.0,
    ring_azimuth_rad: float = 0.0,
    ray_phase: np.ndarray | int | None = None,
) -> np.ndarray:
    """VolumetricGain at each of ``origins`` (N, 3): visible unknown volume in m^3.

    ``headings_rad`` (scalar or (N,)) turns the field of view; it matters only when
    F_H < 360 deg. ``ring_azimuth_rad``: the azimuth one ray of the ring points along
    (see :func:`sensor_rays`). ``ray_phase`` (per origin, modulo
    ``gain_ray_interleave``): origin with phase p turns its ring by p / interleave of the
    ray spacing, so that neighbouring vertices together sample the field of view more
    finely (stratified directions at the cost of one ring per vertex). Each sensor
    origin is taken at the centre of its voxel, so that the voxels every ray passes are
    one precomputed (and cached) table of flat index offsets per ray direction:
    marching a ray is then one addition and one lookup per sample.
    """
    origins = np.atleast_2d(np.asarray(origins, float))
    n = len(origins)
    if n == 0:
        return np.zeros(0)
    shape = np.array(grid.shape, dtype=np.int64)
    strides = np.array([shape[1] * shape[2], shape[2], 1], dtype=np.int64)
    vs = float(grid.voxel_size_m)
    t = _ray_tables(config, tuple(int(v) for v in shape), vs, _canonical_azimuth(config, ring_azimuth_rad))
    m = len(t.ray_sets)
    phase = np.zeros(n, np.int64) if ray_phase is None else np.broadcast_to(np.asarray(ray_phase, np.int64) % m, (n,))
    r = t.ray_sets[0].count
    headings = np.broadcast_to(np.asarray(headings_rad, float), (n,))
    ids = np.empty((n, r), np.int64)
    for p, rays_p in enumerate(t.ray_sets):
        rows = np.flatnonzero(phase == p)
        if len(rows):
            ids[rows] = rays_p.ray_ids(headings[rows]) + p * t.directions_per_ring
    k_max, w, tail, offsets, d, inv = t.k_max, t.weights, t.tail, t.offsets, t.steps, t.inverse_steps
    occ = np.ascontiguousarray(grid.occupancy).reshape(-1)
    # Sensor voxels, and how many samples of each ray stay inside the grid (slab method).
    o_idx = np.floor((origins + np.array([0.0, 0.0, config.sensor_offset_z_m]) - grid.origin) / vs).astype(np.int64)
    inside0 = np.all((o_idx >= 0) & (o_idx < shape), axis=1)
    oc = o_idx + 0.5
    t_exit = np.full((n, r), np.inf)
    for ax in range(3):
        da = d[ids, ax]
        te = np.where(da > 0, shape[ax] - oc[:, ax, None], -oc[:, ax, None]) * inv[ids, ax]
        te[da == 0] = np.inf
        np.minimum(t_exit, te, out=t_exit)
    n_in = np.clip(np.ceil(t_exit - 1e-6) - 1, 0, k_max).astype(np.int64)
    n_in[~inside0] = 0
    n_in = n_in.reshape(-1)
    ray_dir = ids.reshape(-1)
    omega = t.solid_angle_sr[ray_dir]
    base = np.where(inside0, o_idx @ strides, 0).astype(offsets.dtype)
    ray_base = np.repeat(base, r)
    gain = np.zeros(n * r)
    # Sensors outside the grid see only unknown space.
    out = np.repeat(~inside0, r)
    gain[out] = tail[0] * omega[out]

    # Rays are marched sensor by sensor in the order of their voxels in memory, so
    # that neighbouring sensors read neighbouring voxels while they are in the cache.
    by_voxel = (np.argsort(base, kind="stable")[:, None] * r + np.arange(r)).reshape(-1)
    active = by_voxel[n_in[by_voxel] > 0]
    # The active rays' directions, sensor voxels and samples inside the grid, kept
    # compact alongside ``active``.
    a_dir, a_base, a_nin = ray_dir[active], ray_base[active], n_in[active]
    k0 = 0
    chunk = 8
    while len(active) and k0 < k_max:
        c = min(chunk, k_max - k0)
        table = np.ascontiguousarray(offsets[:, k0:k0 + c])
        lim = np.minimum(a_nin - k0, c)  # samples of this chunk inside the grid (>= 1)
        flat = np.take(table, a_dir, axis=0)
        flat += a_base[:, None]
        part = np.flatnonzero(lim < c)
        if len(part):
            # Rays leaving the grid in this chunk: repeat their last inside sample.
            cols = np.minimum(np.arange(k0, k0 + c)[None, :], (a_nin[part] - 1)[:, None])
            flat[part] = offsets[a_dir[part][:, None], cols] + a_base[part, None]
        vals = np.take(occ, flat)
        # The first voxel that is not free decides most rays: rock ends them with no
        # gain; only rays whose first such voxel is unknown need a closer look.
        first = (vals != FREE).argmax(axis=1)
        first_val = vals.reshape(-1)[np.arange(0, len(active) * c, c) + first]
        event = (first_val != FREE) & (first < lim)
        ev_unknown = np.flatnonzero(event & (first_val == UNKNOWN))
        hit = event & (first_val == OCCUPIED)
        if len(ev_unknown):
            # In the order of the rays (the float32 sums below depend on the batch).
            ev_unknown = ev_unknown[np.argsort(active[ev_unknown], kind="stable")]
            v = vals[ev_unknown]
            h = v == OCCUPIED
            fh = h.argmax(axis=1)
            hh = h[np.arange(len(ev_unknown)), fh] & (fh < lim[ev_unknown])
            stop = np.where(hh, fh, lim[ev_unknown])
            unk = (v == UNKNOWN) & (_COLS[:c][None, :] < stop[:, None])
            sel = active[ev_unknown]
            gain[sel] += (unk.astype(np.float32) @ w[k0:k0 + c]) * omega[sel]
            hit[ev_unknown] = hh
        done = hit | (a_nin <= k0 + c)
        # Rays that left the grid without a hit: the rest of their range is unknown.
        left = done & ~hit & (a_nin < k_max)
        if left.any():
            idx = active[left]
            gain[idx] += tail[n_in[idx]] * omega[idx]
        more = ~done
        active, a_dir, a_base, a_nin = active[more], a_dir[more], a_base[more], a_nin[more]
        k0 += c
        chunk = min(chunk * 2, 32)
    return gain.reshape(n, r).sum(axis=1)


@dataclass(frozen=True)
class _RayTables:
    ray_sets: list
    directions_per_ring: int
    solid_angle_sr: np.ndarray
    steps: np.ndarray  # (directions, 3) voxel units per step
    inverse_steps: np.ndarray
    k_max: int
    weights: np.ndarray
    tail: np.ndarray
    offsets: np.ndarray  # (directions, k_max) flat index offsets from a voxel centre


def ring_phase(config: GBPlannerConfig, ring_azimuth_rad: float | np.ndarray) -> np.ndarray:
    """The ring azimuth modulo the ray spacing, in 1/interleave of it (0 to interleave
    - 1): rings turned by a whole spacing are the same rays, so a ring with azimuth a is
    the ring of azimuth 0 at ``ray_phase=ring_phase(config, a)`` of
    :func:`volumetric_gain`, and rays of several azimuths go in one call."""
    ring = sensor_rays(config).ring_bins
    m = int(config.gain_ray_interleave)
    sub = 2.0 * math.pi / ring / m
    return np.round(np.asarray(ring_azimuth_rad, float) / sub).astype(np.int64) % m


def _canonical_azimuth(config: GBPlannerConfig, ring_azimuth_rad: float) -> float:
    """:func:`ring_phase` as an azimuth: few ray tables serve all calls."""
    ring = sensor_rays(config).ring_bins
    return int(ring_phase(config, ring_azimuth_rad)) * (2.0 * math.pi / ring / int(config.gain_ray_interleave))


@lru_cache(maxsize=16)
def _ray_tables(config: GBPlannerConfig, shape: tuple[int, int, int], voxel_size_m: float, ring_azimuth_rad: float) -> _RayTables:
    """Rays of every phase and the voxels along them, for one grid shape (cached)."""
    m = int(config.gain_ray_interleave)
    base_rays = sensor_rays(config, ring_azimuth_rad)
    d_az = 2.0 * math.pi / base_rays.ring_bins
    ray_sets = [base_rays] + [sensor_rays(config, ring_azimuth_rad + p * d_az / m) for p in range(1, m)]
    unit = np.concatenate([rp.unit_directions() for rp in ray_sets])
    solid_angle = np.concatenate([rp.solid_angle_sr for rp in ray_sets])
    step_v = float(config.gain_ray_step_voxels)
    dr = step_v * voxel_size_m
    # Sample k (k = 1, 2, ...) stands for the shell ((k - 1/2) dr, (k + 1/2) dr) of the
    # ray's cone, clipped to the range: its volume per steradian is the weight.
    rng_m = float(config.sensor_range_m)
    k_max = max(1, math.ceil(rng_m / dr - 0.5))
    rk = (np.arange(k_max) + 1) * dr
    shell_lo = rk - 0.5 * dr
    shell_hi = np.minimum(rk + 0.5 * dr, rng_m)
    w = ((shell_hi**3 - shell_lo**3) / 3.0).astype(np.float32)
    tail = np.concatenate([np.cumsum(w[::-1], dtype=np.float64)[::-1], [0.0]])
    strides = np.array([shape[1] * shape[2], shape[2], 1], dtype=np.int64)
    itype = np.int32 if int(np.prod(shape)) < 2**31 - 1 else np.int64
    d = unit * step_v
    steps = np.arange(1, k_max + 1, dtype=np.float64)
    offsets = (np.floor(0.5 + d[:, None, :] * steps[None, :, None]).astype(np.int64) @ strides).astype(itype)
    with np.errstate(divide="ignore"):
        inv = np.where(d != 0, 1.0 / np.where(d != 0, d, 1.0), 0.0)
    for arr in (solid_angle, d, inv, w, tail, offsets):
        arr.setflags(write=False)
    return _RayTables(ray_sets, base_rays.ring_bins * base_rays.elevation_bins, solid_angle, d, inv, k_max, w,
                      tail, offsets)


_COLS = np.arange(64)


def vertex_headings(graph: LocalGraph, paths: ShortestPaths, root_yaw_rad: float) -> np.ndarray:
    """Heading of each vertex: the direction of the edge that reaches it (the root: the robot's yaw)."""
    pred = paths.predecessor
    h = np.full(graph.num_vertices, float(root_yaw_rad))
    has = pred >= 0
    dv = graph.vertices[has] - graph.vertices[pred[has]]
    h[has] = np.arctan2(dv[:, 1], dv[:, 0])
    return h


def ring_azimuth(graph: LocalGraph) -> float:
    """Azimuth of the local bounding box's first axis (0 without a box)."""
    if graph.bound is None:
        return 0.0
    a = graph.bound.axes[:, 0]
    return float(math.atan2(a[1], a[0])) if math.hypot(a[0], a[1]) > 1e-9 else 0.0


def compute_vertex_gains(
    grid: Grid,
    graph: LocalGraph,
    paths: ShortestPaths,
    config: GBPlannerConfig,
    root_yaw_rad: float = 0.0,
) -> tuple[np.ndarray, int]:
    """ComputeVolumetricGain(G_L) (Algorithm 3).

    Returns each vertex's gain (0 for the root, unreachable vertices and, with
    leaf-only gain, non-leaves) and how many ray casts were done.
    """
    n = graph.num_vertices
    gains = np.zeros(n)
    if n <= 1:
        return gains, 0
    if config.leaf_only_gain:
        targets = paths.leaves()
    else:
        targets = np.flatnonzero(paths.reachable)
        targets = targets[targets != 0]
    if len(targets) == 0:
        return gains, 0
    if config.clustering_enabled:
        centres, owner = cluster_vertices(graph.vertices[targets], config.clustering_radius_m)
    else:
        centres, owner = np.arange(len(targets)), np.arange(len(targets))
    headings = vertex_headings(graph, paths, root_yaw_rad)
    cast = targets[centres]
    raw = volumetric_gain(grid, graph.vertices[cast], config, headings[cast], ring_azimuth(graph), cast)
    g = raw[owner]
    g = np.where(graph.hanging[targets], g * config.hanging_gain_factor, g)
    gains[targets] = g
    return gains, len(cast)


def cluster_vertices(points: np.ndarray, radius_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Greedy clustering in order: a point not yet in a cluster starts one and takes
    every unclustered point within ``radius_m``. Returns the centres' indices and, for
    each point, the index (into centres) of its cluster."""
    n = len(points)
    owner = -np.ones(n, np.int64)
    centres: list[int] = []
    near = cKDTree(points).query_ball_point(points, radius_m)
    for i in range(n):
        if owner[i] >= 0:
            continue
        c = len(centres)
        centres.append(i)
        members = np.asarray(near[i], np.int64)
        members = members[owner[members] < 0]
        owner[members] = c
    return np.asarray(centres, np.int64), owner


@dataclass(frozen=True)
class PathGains:
    """Per vertex, for the shortest path from the root to it: the discounted gain sum,
    the direction deviation and the exploration gain (the product)."""

    accumulated: np.ndarray
    deviation: np.ndarray
    exploration_gain: np.ndarray


def exploration_gains(
    graph: LocalGraph,
    paths: ShortestPaths,
    vertex_gain: np.ndarray,
    config: GBPlannerConfig,
    exploring_direction_rad: float | None = None,
) -> PathGains:
    """ExplorationGain(sigma) for the shortest path to every vertex.

    gain(sigma) = exp(-gamma_S * S(sigma)) * sum_i g(v_i) * exp(-gamma_D * D(v_i)),
    with D the distance along the path to v_i and S the mean horizontal offset of the
    path's vertices from the straight line along the exploring direction (at the
    same distance along it), divided by their mean distance along the path (0 for a
    path straight ahead, about 2 for one straight back). Without an exploring
    direction, S = 0.
    """
    n = graph.num_vertices
    dist = paths.distance_m
    reach = paths.reachable
    contrib = np.where(reach, vertex_gain * np.exp(-config.path_length_penalty_per_m * np.where(reach, dist, 0.0)), 0.0)
    if exploring_direction_rad is not None:
        u = np.array([math.cos(exploring_direction_rad), math.sin(exploring_direction_rad)])
        rel = graph.vertices[:, :2] - graph.vertices[0, :2]
        s = np.where(reach, dist, 0.0)
        off = np.linalg.norm(rel - s[:, None] * u[None, :], axis=1)
    else:
        s = np.where(reach, dist, 0.0)
        off = np.zeros(n)
    acc = np.zeros(n)
    acc_off = np.zeros(n)
    acc_s = np.zeros(n)
    order = np.flatnonzero(reach)
    order = order[np.argsort(dist[order], kind="stable")]
    pred = paths.predecessor
    # Accumulate along the shortest-path tree (parents come before children).
    acc_l, off_l, s_l = acc.tolist(), acc_off.tolist(), acc_s.tolist()
    c_l, o_l, ss_l, p_l = contrib.tolist(), off.tolist(), s.tolist(), pred.tolist()
    for v in order.tolist():
        p = p_l[v]
        if p >= 0:
            acc_l[v] = acc_l[p] + c_l[v]
            off_l[v] = off_l[p] + o_l[v]
            s_l[v] = s_l[p] + ss_l[v]
        else:
            acc_l[v] = c_l[v]
    acc, acc_off, acc_s = np.array(acc_l), np.array(off_l), np.array(s_l)
    deviation = np.where(acc_s > 1e-9, acc_off / np.maximum(acc_s, 1e-9), 0.0)
    eg = acc * np.exp(-config.path_direction_penalty * deviation)
    eg[~reach] = 0.0
    return PathGains(acc, deviation, eg)
