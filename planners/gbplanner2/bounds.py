"""The adaptive local bounding box D_L (CalculateAdaptiveLocalBound of Algorithm 2).

Principal Component Analysis of the local point cloud (the mapped, occupied and free,
voxels within mu_V of the robot) gives the box's axes: in a tunnel the first axis runs
along the tunnel, the second across it and the third, the smallest, is its height. The
box is centred on the robot; its half extent along each axis is a percentile of the
points' distances along that axis, clipped between the configured smallest and
largest sizes, so the box stretches along a tunnel and stays narrow across it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..occupancy import UNKNOWN, Grid
from .config import GBPlannerConfig


@dataclass(frozen=True)
class LocalBound:
    """An oriented box: ``centre``, unit ``axes`` (columns, largest spread first) and
    ``half_extents_m`` along them."""

    centre: np.ndarray
    axes: np.ndarray
    half_extents_m: np.ndarray
    num_points: int = 0

    def to_box(self, points: np.ndarray) -> np.ndarray:
        """World points -> coordinates along the box's axes, relative to its centre."""
        return (np.atleast_2d(points) - self.centre) @ self.axes

    def contains(self, points: np.ndarray) -> np.ndarray:
        return np.all(np.abs(self.to_box(points)) <= self.half_extents_m + 1e-9, axis=1)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` points drawn uniformly inside the box (SampleFree draws from these)."""
        u = rng.uniform(-1.0, 1.0, size=(n, 3))
        return self.centre + (u * self.half_extents_m) @ self.axes.T

    def corners(self) -> np.ndarray:
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
        return self.centre + (signs * self.half_extents_m) @ self.axes.T

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        c = self.corners()
        return c.min(axis=0), c.max(axis=0)

    @property
    def volume_m3(self) -> float:
        return float(np.prod(2.0 * self.half_extents_m))


def local_point_cloud(grid: Grid, position: np.ndarray, config: GBPlannerConfig) -> np.ndarray:
    """Centres of the mapped voxels within mu_V of ``position``, one every
    ``local_pointcloud_spacing_m`` along each axis."""
    vs = grid.voxel_size_m
    stride = max(1, round(config.local_pointcloud_spacing_m / vs))
    r = config.local_pointcloud_range_m
    p = np.asarray(position, float)
    lo = np.maximum(grid.to_index((p - r)[None])[0], 0)
    hi = np.minimum(grid.to_index((p + r)[None])[0] + 1, np.array(grid.shape))
    if np.any(hi <= lo):
        return np.zeros((0, 3))
    # Align the stride to the grid so that results do not depend on the robot's position.
    lo = lo + (-lo) % stride
    sub = grid.occupancy[lo[0]:hi[0]:stride, lo[1]:hi[1]:stride, lo[2]:hi[2]:stride]
    idx = np.argwhere(sub != UNKNOWN)
    pts = grid.to_world(lo + idx * stride)
    near = np.einsum("ij,ij->i", pts - p, pts - p) <= r * r
    return pts[near]


def adaptive_local_bound(grid: Grid, position: np.ndarray, config: GBPlannerConfig) -> LocalBound:
    """D_L: the local bounding box from PCA of the local point cloud around ``position``.

    With too few mapped points for a PCA (fewer than 10), the box is axis-aligned with
    the smallest configured sizes.
    """
    p = np.asarray(position, float)
    pts = local_point_cloud(grid, p, config)
    size_min = np.sort(np.asarray(config.bounding_box_size_min_m, float))[::-1]
    size_max = config.bounding_box_size_max_m
    if len(pts) < 10:
        return LocalBound(p.copy(), np.eye(3), 0.5 * size_min, len(pts))
    centred = pts - pts.mean(axis=0)
    cov = centred.T @ centred / len(pts)
    evals, evecs = np.linalg.eigh(cov)
    order = np.argsort(evals)[::-1]
    axes = evecs[:, order]
    # Deterministic signs: each axis points to the positive side of its largest component.
    for k in range(3):
        if axes[np.argmax(np.abs(axes[:, k])), k] < 0:
            axes[:, k] = -axes[:, k]
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    proj = np.abs((pts - p) @ axes)
    half = np.percentile(proj, config.bounding_box_percentile, axis=0)
    half = np.clip(half, 0.5 * size_min, 0.5 * size_max)
    return LocalBound(p.copy(), axes, half, len(pts))
