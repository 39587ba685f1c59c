"""The pan-tilt-zoom inspection payload of the ANYmal C SubT Explorer (CERBERUS paper,
section 3.5 "Inspection payload" and "Autonomous scanning").

A zoom camera on a pan (yaw) and tilt (pitch) unit on the robot's body. Joint limits
are the paper's −135..135° in yaw and −10..30° in pitch; its joint space is sampled
on a 3° grid into the paper's 1170 candidate scan points. A point counts as seen
when it lies within 5 m of the camera, inside its field of view, with no rock in
between (a ray cast into the world's rock mesh).

Frames: the body frame is x forward, y left, z up. Yaw turns the camera about the
body's z axis (positive to the left); pitch raises it (positive up). The camera's
optical centre sits at the pan-tilt centre, ``mount_offset_m`` in the body frame,
so occlusion does not depend on the joint angles. A body pose is either a (4, 4)
homogeneous transform body -> world or ``(x, y, z, yaw_rad)``.

The field of view narrows with the zoom as a pinhole camera's does:
``tan(fov(zoom) / 2) = tan(fov / 2) / zoom``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .world import World


@dataclass(frozen=True)
class PayloadSpec:
    """Pan-tilt-zoom inspection camera parameters (the paper's values by default).

    Fields:
        yaw_limits_deg, pitch_limits_deg: joint limits (inclusive).
        horizontal_fov_deg, vertical_fov_deg: field of view at zoom 1 (pinhole, < 180°).
        range_m: a point farther than this from the camera is not seen.
        joint_grid_deg: resolution of the candidate scan points in joint space.
        max_zoom: largest optical zoom (the paper's 10x).
        zoom_reference_distance_m: distance up to which zoom 1 is used; beyond it the
            zoom grows with distance so that objects keep their size in the image.
        slew_rate_deg_s: joint speed, for the time a ``point_at`` takes.
        mount_offset_m: pan-tilt centre in the body frame.
    """

    yaw_limits_deg: tuple[float, float] = (-135.0, 135.0)
    pitch_limits_deg: tuple[float, float] = (-10.0, 30.0)
    horizontal_fov_deg: float = 60.0
    vertical_fov_deg: float = 36.0
    range_m: float = 5.0
    joint_grid_deg: float = 3.0
    max_zoom: float = 10.0
    zoom_reference_distance_m: float = 2.0
    slew_rate_deg_s: float = 90.0
    mount_offset_m: tuple[float, float, float] = (0.2, 0.0, 0.25)

    def __post_init__(self) -> None:
        for name in ("yaw_limits_deg", "pitch_limits_deg"):
            lo, hi = getattr(self, name)
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"payload {name} must be (low, high) with low < high, got {(lo, hi)}")
        lo, hi = self.pitch_limits_deg
        if lo < -90.0 or hi > 90.0:
            raise ValueError(f"payload pitch_limits_deg must lie within -90..90, got {(lo, hi)}")
        for name in ("horizontal_fov_deg", "vertical_fov_deg"):
            fov = getattr(self, name)
            if not 0.0 < fov < 180.0:
                raise ValueError(f"payload {name} must lie in (0, 180) for a camera, got {fov}")
        for name in ("range_m", "joint_grid_deg", "zoom_reference_distance_m", "slew_rate_deg_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"payload {name} must be > 0, got {value}")
        if not self.max_zoom >= 1.0:
            raise ValueError(f"payload max_zoom must be >= 1, got {self.max_zoom}")


def joint_space_grid(yaw_limits_deg: tuple[float, float], pitch_limits_deg: tuple[float, float],
                     joint_grid_deg: float) -> np.ndarray:
    """Candidate scan points: one (yaw, pitch) in degrees per ``joint_grid_deg`` cell.

    Each axis holds ``floor(span / step)`` cells, centred within the limits, and a
    candidate sits at each cell's centre. The paper's joint space, −135..135° by
    −10..30° at 3°, gives 90 x 13 = 1170 candidates (yaw −133.5..133.5, pitch −8..28).
    Rows are ordered by yaw, then pitch.
    """
    step = float(joint_grid_deg)
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"joint_grid_deg must be > 0, got {joint_grid_deg}")
    axes = []
    for lo, hi in (yaw_limits_deg, pitch_limits_deg):
        span = float(hi) - float(lo)
        n = math.floor(span / step + 1e-9)
        if n < 1:
            raise ValueError(f"joint_grid_deg {step} is larger than the joint range {span}")
        start = float(lo) + 0.5 * (span - n * step) + 0.5 * step
        axes.append(start + step * np.arange(n))
    yaw, pitch = np.meshgrid(axes[0], axes[1], indexing="ij")
    return np.stack([yaw.ravel(), pitch.ravel()], axis=1)


def body_transform(body_pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (3, 3) and translation (3,) of a body pose: a (4, 4) transform or (x, y, z, yaw_rad)."""
    pose = np.asarray(body_pose, dtype=float)
    if pose.shape == (4, 4):
        return pose[:3, :3], pose[:3, 3]
    if pose.shape == (4,):
        c, s = math.cos(pose[3]), math.sin(pose[3])
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), pose[:3]
    raise ValueError(f"body pose must be a (4, 4) transform or (x, y, z, yaw_rad), got shape {pose.shape}")


def camera_axes(yaw_deg: np.ndarray, pitch_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward, left and up unit vectors (K, 3) of the camera in the body frame."""
    y = np.radians(np.asarray(yaw_deg, dtype=float)).reshape(-1)
    p = np.radians(np.asarray(pitch_deg, dtype=float)).reshape(-1)
    cy, sy, cp, sp = np.cos(y), np.sin(y), np.cos(p), np.sin(p)
    forward = np.stack([cp * cy, cp * sy, sp], axis=1)
    left = np.stack([-sy, cy, np.zeros_like(y)], axis=1)
    up = np.stack([-sp * cy, -sp * sy, cp], axis=1)
    return forward, left, up


class PanTiltZoomCamera:
    """The inspection payload: joint state, commands and what it sees in a world."""

    def __init__(self, world: World, spec: PayloadSpec | None = None, *,
                 occlusion_tolerance_m: float | None = None):
        self.world = world
        self.spec = spec if spec is not None else PayloadSpec()
        #: A target this much behind the first rock hit still counts as visible
        #: (points on the rock surface, voxel centres). Default: one voxel.
        self.occlusion_tolerance_m = (float(world.voxel_size_m) if occlusion_tolerance_m is None
                                      else float(occlusion_tolerance_m))
        self.yaw_deg = 0.0
        self.pitch_deg = 0.0
        self.zoom = 1.0
        self.commands = 0

    # ---- joint space ------------------------------------------------------------
    def view_directions(self, joint_grid_deg: float | None = None) -> np.ndarray:
        """The candidate scan points (K, 2) = (yaw, pitch) in degrees (1170 at 3°)."""
        step = self.spec.joint_grid_deg if joint_grid_deg is None else joint_grid_deg
        return joint_space_grid(self.spec.yaw_limits_deg, self.spec.pitch_limits_deg, step)

    def within_limits(self, yaw_deg: float, pitch_deg: float) -> bool:
        """Whether (yaw, pitch) lies inside the joint limits."""
        (ylo, yhi), (plo, phi) = self.spec.yaw_limits_deg, self.spec.pitch_limits_deg
        return bool(ylo - 1e-9 <= yaw_deg <= yhi + 1e-9 and plo - 1e-9 <= pitch_deg <= phi + 1e-9)

    def point_at(self, yaw_deg: float, pitch_deg: float, zoom: float | None = None) -> float:
        """Command the joints (and optionally the zoom); returns the slew time in seconds.

        ValueError outside the joint limits or the zoom range; the state is then unchanged.
        """
        yaw_deg, pitch_deg = float(yaw_deg), float(pitch_deg)
        if not (math.isfinite(yaw_deg) and math.isfinite(pitch_deg)) or not self.within_limits(yaw_deg, pitch_deg):
            (ylo, yhi), (plo, phi) = self.spec.yaw_limits_deg, self.spec.pitch_limits_deg
            raise ValueError(f"payload command yaw {yaw_deg:g}°, pitch {pitch_deg:g}° is outside the joint "
                             f"limits yaw {ylo:g}..{yhi:g}°, pitch {plo:g}..{phi:g}°")
        if zoom is not None and not 1.0 <= float(zoom) <= self.spec.max_zoom:
            raise ValueError(f"payload zoom {zoom:g} is outside 1..{self.spec.max_zoom:g}")
        slew = max(abs(yaw_deg - self.yaw_deg), abs(pitch_deg - self.pitch_deg)) / self.spec.slew_rate_deg_s
        self.yaw_deg, self.pitch_deg = yaw_deg, pitch_deg
        if zoom is not None:
            self.zoom = float(zoom)
        self.commands += 1
        return slew

    def zoom_for_distance(self, distance_m: float) -> float:
        """The zoom that keeps an object at ``distance_m`` the size it has at the
        reference distance (the paper's distance-based zoom), within 1..max_zoom."""
        return float(np.clip(distance_m / self.spec.zoom_reference_distance_m, 1.0, self.spec.max_zoom))

    def fov_deg(self, zoom: float = 1.0) -> tuple[float, float]:
        """Horizontal and vertical field of view (degrees) at ``zoom``."""
        h, v = (math.degrees(2 * math.atan(math.tan(math.radians(f) / 2) / zoom))
                for f in (self.spec.horizontal_fov_deg, self.spec.vertical_fov_deg))
        return h, v

    # ---- visibility -------------------------------------------------------------
    def camera_position(self, body_pose: np.ndarray) -> np.ndarray:
        """World position (3,) of the camera's optical centre."""
        rot, trans = body_transform(body_pose)
        return trans + rot @ np.asarray(self.spec.mount_offset_m, dtype=float)

    def unoccluded(self, points: np.ndarray, body_pose: np.ndarray) -> np.ndarray:
        """(N,) bool: within ``range_m`` of the camera with no rock in between."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        cam = self.camera_position(body_pose)
        rel = pts - cam
        dist = np.linalg.norm(rel, axis=1)
        near = dist <= self.spec.range_m
        out = np.zeros(len(pts), dtype=bool)
        idx = np.flatnonzero(near & (dist > 1e-9))
        if len(idx):
            hit = self.world.cast_rays(np.broadcast_to(cam, (len(idx), 3)), rel[idx] / dist[idx, None],
                                       self.spec.range_m + self.occlusion_tolerance_m)
            out[idx] = hit.astype(float) >= dist[idx] - self.occlusion_tolerance_m
        out[near & (dist <= 1e-9)] = True
        return out

    def in_view(self, points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                zoom: float = 1.0) -> np.ndarray:
        """(N, K) bool: which points lie inside the field of view of each (yaw, pitch)
        candidate (K, 2), ignoring range and rock."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        cand = np.asarray(candidates, dtype=float).reshape(-1, 2)
        rot, _ = body_transform(body_pose)
        rel_body = (pts - self.camera_position(body_pose)) @ rot       # body-frame offsets (N, 3)
        fwd, left, up = camera_axes(cand[:, 0], cand[:, 1])
        x, y, z = rel_body @ fwd.T, rel_body @ left.T, rel_body @ up.T    # (N, K) each
        th = math.tan(math.radians(self.spec.horizontal_fov_deg) / 2) / zoom
        tv = math.tan(math.radians(self.spec.vertical_fov_deg) / 2) / zoom
        return (x > 1e-9) & (np.abs(y) <= x * th) & (np.abs(z) <= x * tv)

    def visibility_matrix(self, points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                          zoom: float = 1.0) -> np.ndarray:
        """(N, K) bool: which points each candidate scan point sees (range, view, rock)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        clear = self.unoccluded(pts, body_pose)
        out = np.zeros((len(pts), len(np.asarray(candidates).reshape(-1, 2))), dtype=bool)
        out[clear] = self.in_view(pts[clear], body_pose, candidates, zoom)
        return out

    def sees(self, points: np.ndarray, body_pose: np.ndarray, yaw_deg: float, pitch_deg: float,
             zoom: float = 1.0) -> np.ndarray:
        """(N,) bool: which points the camera sees at (yaw, pitch) from ``body_pose``:
        within ``range_m``, inside the field of view and with no rock in between."""
        return self.visibility_matrix(points, body_pose, np.array([[yaw_deg, pitch_deg]]), zoom)[:, 0]

    def capture(self, points: np.ndarray, body_pose: np.ndarray) -> np.ndarray:
        """(N,) bool: which points the camera sees where it points now (current zoom)."""
        return self.sees(points, body_pose, self.yaw_deg, self.pitch_deg, self.zoom)
