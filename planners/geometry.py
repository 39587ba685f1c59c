"""Small geometry on polylines and points that planners and skills share: a path's
length, its first metres, the segment nearest to a point, and a point rounded for logs."""
from __future__ import annotations

import numpy as np


def path_length(path: np.ndarray) -> float:
    """Length (m) of the polyline ``path`` ((N, 3) waypoints); 0 for fewer than two."""
    p = np.asarray(path, float)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0


def cut_path(path: np.ndarray, distance_m: float | None) -> np.ndarray:
    """The first ``distance_m`` of ``path`` (all of it for None), ending on the point
    that far along it."""
    if distance_m is None or len(path) < 2:
        return path
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= distance_m:
        return path
    k = int(np.searchsorted(cum, distance_m, side="right"))  # path[k] is the first beyond
    t = (distance_m - cum[k - 1]) / max(seg[k - 1], 1e-12)
    return np.vstack([path[:k], path[k - 1] + t * (path[k] - path[k - 1])])


def nearest_segment(points: np.ndarray, position: np.ndarray) -> int:
    """Index ``k`` of the segment ``points[k] -> points[k + 1]`` of a polyline (at least
    two points) that passes nearest to ``position`` (the first of equals)."""
    a, b = points[:-1], points[1:]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", position - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12), 0.0, 1.0)
    return int(np.argmin(np.linalg.norm(a + t[:, None] * ab - position, axis=1)))


def xyz(point: np.ndarray, digits: int = 3) -> list[float]:
    """``point`` as a list of floats rounded to ``digits`` decimals (for logs and reports)."""
    return [round(float(v), digits) for v in point]


__all__ = ["cut_path", "nearest_segment", "path_length", "xyz"]
