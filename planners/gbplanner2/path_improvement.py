"""ImprovePath (Algorithm 1, line 11): a better version of the best path, still admissible.

A shortest path through a random graph zig-zags and may brush past rock. The path is

1. shortcut: from each waypoint, the farthest later waypoint that an admissible edge
   (the same check as the graph's edges: collision-free, and for legged robots
   supported, not too steep) reaches directly is the next one;
2. pushed away from obstacles: each inner waypoint probes how far the robot box can
   move in a set of directions (horizontal ones for legged robots, which are then put
   back on the ground) and moves towards the side with more room, at most
   ``path_safety_extension_m`` from where it was; a move is kept only when both
   edges to its neighbours stay admissible.

The first and the last waypoint do not move. :func:`truncate_path` then cuts the path
to ``traverse_length_max_m``.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from .config import GBPlannerConfig
from .local_map import GROUND_ATTACHED, LocalMap


def segments_admissible(local_map: LocalMap, path: np.ndarray) -> np.ndarray:
    """Admissibility of each segment of ``path``."""
    p = np.asarray(path, float)
    if len(p) < 2:
        return np.zeros(0, bool)
    return local_map.check_edges(p[:-1], p[1:]).admissible


def shortcut_path(local_map: LocalMap, path: np.ndarray, max_skip: int = 24) -> np.ndarray:
    """Greedy shortcutting: from each waypoint to the farthest of the next ``max_skip``
    that an admissible edge reaches; all candidate edges are checked in one batch."""
    p = np.asarray(path, float)
    n = len(p)
    if n <= 2:
        return p.copy()
    i_idx, j_idx = np.triu_indices(n, k=2)
    near = j_idx - i_idx <= max_skip
    i_idx, j_idx = i_idx[near], j_idx[near]
    ok = np.zeros((n, n), bool)
    ok[i_idx, j_idx] = local_map.check_edges(p[i_idx], p[j_idx]).admissible
    ok[np.arange(n - 1), np.arange(1, n)] = True  # the path's own edges
    out = [0]
    i = 0
    while i < n - 1:
        reach = np.flatnonzero(ok[i, i + 1:]) + i + 1
        i = int(reach.max())
        out.append(i)
    return p[out]


def _directions(legged: bool) -> np.ndarray:
    if legged:
        a = np.arange(8) * (math.pi / 4)
        return np.stack([np.cos(a), np.sin(a), np.zeros(8)], axis=1)
    d = np.array([v for v in itertools.product((-1, 0, 1), repeat=3) if any(v)], float)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _on_ground(local_map: LocalMap, pts: np.ndarray, config: GBPlannerConfig) -> tuple[np.ndarray, np.ndarray]:
    """Legged: put points at body height above the ground below them; which are supported."""
    gz, status = local_map.project_to_ground(pts, max_depth_m=config.body_height_m + config.ground_search_depth_m)
    out = pts.copy()
    ok = status == GROUND_ATTACHED
    out[ok, 2] = gz[ok] + config.body_height_m
    return out, ok


def push_away_from_obstacles(local_map: LocalMap, path: np.ndarray, config: GBPlannerConfig) -> np.ndarray:
    """Move inner waypoints towards the side with more room (see the module docstring)."""
    p = np.asarray(path, float).copy()
    n = len(p)
    if n <= 2 or config.path_improvement_iterations == 0:
        return p
    legged = config.is_legged
    vs = local_map.voxel_size_m
    ext = config.path_safety_extension_m
    dirs = _directions(legged)
    m = len(dirs)
    probes = np.arange(1, math.ceil(ext / vs) + 1) * vs
    probes = np.minimum(probes, ext)
    origin = p.copy()
    for it in range(config.path_improvement_iterations):
        # Alternate even and odd waypoints so that neighbours never move together.
        for parity in (1, 0):
            idx = np.arange(1, n - 1)
            idx = idx[idx % 2 == parity]
            if len(idx) == 0:
                continue
            q = p[idx]
            cand = q[:, None, None, :] + dirs[None, :, None, :] * probes[None, None, :, None]
            flat = cand.reshape(-1, 3)
            if legged:
                flat, sup = _on_ground(local_map, flat, config)
                free = sup & local_map.is_box_free(flat)
            else:
                free = local_map.is_box_free(flat)
            free = free.reshape(len(idx), m, len(probes))
            run = np.where(free.all(axis=2), len(probes), free.argmin(axis=2)) * vs
            run = np.minimum(run, ext)
            move = (dirs[None, :, :] * run[:, :, None]).sum(axis=1) / (m / 2.0) * 0.5
            if legged:
                move[:, 2] = 0.0
            target = q + move
            # Stay within the safety extension of the original waypoint.
            off = target - origin[idx]
            norm = np.linalg.norm(off, axis=1)
            scale = np.where(norm > ext, ext / np.maximum(norm, 1e-12), 1.0)
            target = origin[idx] + off * scale[:, None]
            if legged:
                target, sup = _on_ground(local_map, target, config)
            else:
                sup = np.ones(len(idx), bool)
            moved = sup & (np.linalg.norm(target - q, axis=1) > 1e-3)
            if not moved.any():
                continue
            before = p[idx - 1]
            after = p[idx + 1]
            ok_a = local_map.check_edges(before, target).admissible
            ok_b = local_map.check_edges(target, after).admissible
            accept = moved & ok_a & ok_b & local_map.is_box_free(target)
            p[idx[accept]] = target[accept]
    return p


def densify_path(local_map: LocalMap, path: np.ndarray, config: GBPlannerConfig, spacing_m: float) -> np.ndarray:
    """Waypoints at most ``spacing_m`` apart; legged robots' new ones on the ground."""
    p = np.asarray(path, float)
    if len(p) < 2:
        return p.copy()
    out = [p[:1]]
    for a, b in itertools.pairwise(p):
        k = max(1, math.ceil(np.linalg.norm(b - a) / spacing_m))
        t = (np.arange(1, k + 1) / k)[:, None]
        seg = a + (b - a) * t
        if config.is_legged and k > 1:
            inner, ok = _on_ground(local_map, seg[:-1], config)
            seg[:-1] = np.where(ok[:, None], inner, seg[:-1])
        out.append(seg)
    return np.concatenate(out)


def improve_path(local_map: LocalMap, path: np.ndarray, config: GBPlannerConfig) -> np.ndarray:
    """ImprovePath: shortcut, re-densify, push away from obstacles; never less admissible.

    Returns the improved path when all its segments are admissible, else the input.
    """
    p = np.asarray(path, float)
    if len(p) <= 2:
        return p.copy()
    short = shortcut_path(local_map, p)
    dense = densify_path(local_map, short, config, config.edge_length_max_m)
    if not segments_admissible(local_map, dense).all():
        dense = short
    pushed = push_away_from_obstacles(local_map, dense, config)
    if segments_admissible(local_map, pushed).all():
        return pushed
    if segments_admissible(local_map, dense).all():
        return dense
    return p.copy()


def truncate_path(local_map: LocalMap | None, path: np.ndarray, max_length_m: float, config: GBPlannerConfig) -> np.ndarray:
    """The first ``max_length_m`` of ``path``; a cut inside a segment ends at the point
    along it (for legged robots put on the ground below it)."""
    p = np.asarray(path, float)
    if len(p) < 2:
        return p.copy()
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= max_length_m:
        return p.copy()
    k = int(np.searchsorted(cum, max_length_m, side="right"))  # cum[k-1] <= L < cum[k]
    t = (max_length_m - cum[k - 1]) / max(seg[k - 1], 1e-12)
    end = p[k - 1] + (p[k] - p[k - 1]) * t
    if local_map is not None and config.is_legged:
        on, ok = _on_ground(local_map, end[None], config)
        if ok[0]:
            end = on[0]
    out = np.concatenate([p[:k], end[None]])
    if len(out) >= 2 and np.linalg.norm(out[-1] - out[-2]) < 1e-6:
        out = out[:-1]
    return out
