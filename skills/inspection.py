"""Inspections with the pan-tilt-zoom payload (CERBERUS paper, section 3.5, "Inspection
payload", "Scanning operation" and "Autonomous scanning"; the *inspections* block of
the ANYmal tree, Figure 13).

The body cameras (fixed, wide, on the robot's body) mark the surface they see within
5 m as *seen* while the robot walks. An inspection request looks at the *reachable
workspace* of the payload: the surface voxels of the onboard map that some of its
1170 joint configurations (a 3° grid of yaw −135..135° by pitch −10..30°) sees within
5 m. The scan points are the smallest set of joint configurations that covers the
unseen part (``delve.planners.scan_points``). When the unseen part exceeds 50 % of the
workspace, a full scan: pause the running motion, stop, scan every point, resume the
same path. Otherwise the points are scanned while the robot walks on.

Visibility is worked out on the robot's onboard map, as the paper's ray casting in the
planner's volumetric map (``delve.planners.visibility``). This module holds what the
inspection works out on the robot (the record of seen surface, the scan points of the
payload); the behaviours that carry it out, step by step, are in
:mod:`.inspection_steps` and form the subtree ``trees/subtrees/inspections.yaml``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..planners.geometry import xyz
from ..planners.scan_points import NODE_LIMIT, ScanPointSelection, select_scan_points
from ..planners.visibility import BodyCameras, first_hit_m, joint_directions, line_of_sight, surface_voxels
from .base import AgentContext
from .robot import MapView, Payload, Robot

#: ``ctx.services`` key of the agent's :class:`SeenRecord`.
SEEN_SERVICE = "body_camera_seen"
#: Mode of a requested point whose area is all seen: it is looked at once.
OPERATOR_POINT_SCAN = "operator_point_scan"
#: Surface points per block of the visibility matrix, to bound memory.
_ROWS = 512


def joints_toward(payload: Payload, body_pose: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """The (yaw, pitch) in degrees that points the payload at ``target``, clipped to its
    joint limits."""
    cam = payload.camera_position(body_pose)
    rel = np.asarray(target, float) - cam
    c, s = math.cos(body_pose[3]), math.sin(body_pose[3])
    x, y = c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]
    yaw = math.degrees(math.atan2(y, x))
    pitch = math.degrees(math.atan2(rel[2], math.hypot(x, y)))
    (ylo, yhi), (plo, phi) = payload.spec.yaw_limits_deg, payload.spec.pitch_limits_deg
    return float(np.clip(yaw, ylo, yhi)), float(np.clip(pitch, plo, phi))


@dataclass
class SeenRecord:
    """The onboard map's voxels seen so far, by the body cameras or by the payload."""

    seen: np.ndarray
    next_update_s: float = -math.inf
    updates: int = 0

    def mark(self, ijk: np.ndarray) -> None:
        ijk = np.asarray(ijk, dtype=np.int64).reshape(-1, 3)
        self.seen[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True

    def of(self, ijk: np.ndarray) -> np.ndarray:
        ijk = np.asarray(ijk, dtype=np.int64).reshape(-1, 3)
        return self.seen[ijk[:, 0], ijk[:, 1], ijk[:, 2]]

    def look(self, robot: Robot, cameras: BodyCameras) -> int:
        """Mark what the body cameras see from the robot's pose now; returns how many
        surface voxels they see for the first time."""
        ijk = cameras.visible(robot.onboard_map, robot.position, robot.yaw_rad, skip=self.seen)
        self.mark(ijk)
        self.updates += 1
        return len(ijk)


def seen_record(ctx: AgentContext, robot: Robot) -> SeenRecord:
    """The agent's shared :class:`SeenRecord`, created on first use."""
    rec = ctx.services.get(SEEN_SERVICE)
    if rec is None or rec.seen.shape != robot.onboard_map.occupancy.shape:
        rec = ctx.services[SEEN_SERVICE] = SeenRecord(np.zeros(robot.onboard_map.occupancy.shape, dtype=bool))
    return rec


@dataclass
class ScanPoint:
    """One scan: joint angles (degrees), zoom, and its target: the point on its optical
    axis as far away as the unseen surface it covers (what the payload tracks while
    the robot walks)."""

    yaw_deg: float
    pitch_deg: float
    zoom: float
    target: np.ndarray


def zoom_level(payload: Payload, distance_m: float, zoom_step: float) -> float:
    """The payload's zoom for a surface ``distance_m`` away, rounded down to a multiple
    of ``zoom_step`` (at least 1)."""
    return float(max(1.0, math.floor(payload.zoom_for_distance(distance_m) / zoom_step + 1e-9) * zoom_step))


def candidate_zooms(payload: Payload, onboard_map: MapView, body_pose: np.ndarray, candidates: np.ndarray,
                    zoom_step: float) -> np.ndarray:
    """(K,) zoom of each candidate: for the distance to the first surface along its
    axis on the onboard map (the paper's distance-based zoom)."""
    cam = payload.camera_position(body_pose)
    axes = joint_directions(candidates, float(body_pose[3]))
    dist = first_hit_m(onboard_map, cam, axes, payload.spec.range_m)
    return np.array([zoom_level(payload, d, zoom_step) for d in dist])


def payload_visibility(payload: Payload, onboard_map: MapView, points: np.ndarray, ijk: np.ndarray,
                       body_pose: np.ndarray, candidates: np.ndarray, zooms: np.ndarray) -> np.ndarray:
    """(N, K) bool: which surface voxels (centres ``points``, indices ``ijk``) each
    candidate (yaw, pitch) sees at its zoom: within the payload's range, inside its
    field of view, in line of sight on the onboard map."""
    cam = payload.camera_position(body_pose)
    out = np.zeros((len(points), len(candidates)), dtype=bool)
    if not len(points):
        return out
    clear = np.linalg.norm(points - cam, axis=1) <= payload.spec.range_m
    clear[clear] = line_of_sight(onboard_map, cam, ijk[clear])
    rows = np.flatnonzero(clear)
    groups = [(float(z), np.flatnonzero(zooms == z)) for z in np.unique(zooms)]
    for start in range(0, len(rows), _ROWS):
        block = rows[start:start + _ROWS]
        for zoom, cols in groups:
            out[np.ix_(block, cols)] = payload.in_view(points[block], body_pose, candidates[cols], zoom)
    return out


def body_pose(robot: Robot) -> np.ndarray:
    """The robot's body pose (x, y, z, yaw_rad)."""
    p = robot.position
    return np.array([p[0], p[1], p[2], robot.yaw_rad])


@dataclass
class InspectionPlan:
    """The scan points for the robot's pose now and what they are meant to cover.

    Fields:
        selection: the scan point selection (``select_scan_points``).
        scans: the scan points with their zoom and surface target, in scanning order.
        mode: ``autonomous_full_scan``, ``autonomous_point_scan``, ``operator_point_scan``
            (a requested point whose area is all seen, looked at once) or "".
        workspace_points: surface voxels in the reachable workspace.
        unseen_ijk, unseen_pts: indices and centres of its unseen voxels.
    """

    selection: ScanPointSelection
    scans: list[ScanPoint]
    mode: str
    workspace_points: int
    unseen_ijk: np.ndarray
    unseen_pts: np.ndarray


def plan_inspection(robot: Robot, record: SeenRecord, *, point: np.ndarray | None = None,
                    point_radius_m: float = 1.0, joint_grid_deg: float = 3.0, distance_zoom: bool = True,
                    zoom_step: float = 0.5, full_scan_fraction: float = 0.5,
                    node_limit: int = NODE_LIMIT) -> InspectionPlan:
    """Scan points of the robot's payload over the unseen part of its reachable
    workspace (around ``point`` within ``point_radius_m`` when given), as the paper's
    autonomous scanning algorithm. Raises ValueError when the robot has no payload."""
    payload, m = robot.payload, robot.onboard_map
    if payload is None:
        raise ValueError(f"{robot.name} carries no inspection payload")
    pose = body_pose(robot)
    cam = payload.camera_position(pose)
    ijk, pts = surface_voxels(m, cam, float(payload.spec.range_m))
    if point is not None:
        near = np.linalg.norm(pts - point, axis=1) <= point_radius_m
        ijk, pts = ijk[near], pts[near]
    cand = np.asarray(payload.view_directions(joint_grid_deg), float)
    zooms = candidate_zooms(payload, m, pose, cand, zoom_step) if distance_zoom else np.ones(len(cand))
    vis = payload_visibility(payload, m, pts, ijk, pose, cand, zooms)
    reachable = vis.any(axis=1)
    unseen = reachable & ~record.of(ijk)
    sel = select_scan_points(pts[unseen], pose, cand, vis[unseen], int(reachable.sum()),
                             full_scan_fraction=full_scan_fraction, node_limit=node_limit)
    unseen_pts, sub = pts[unseen], vis[unseen]
    axes = joint_directions(cand, float(pose[3]))
    scans = []
    for c in sel.candidate_indices:
        # The target: on the candidate's optical axis, as far as the voxels it covers
        # (median), so that aiming at it from here gives the candidate's joints.
        dist = np.linalg.norm(unseen_pts[sub[:, c]] - cam, axis=1)
        target = cam + axes[c] * float(np.median(dist))
        scans.append(ScanPoint(float(cand[c, 0]), float(cand[c, 1]), float(zooms[c]), target))
    mode = sel.mode
    if point is not None and not scans:
        yaw, pitch = joints_toward(payload, pose, point)
        zoom = zoom_level(payload, float(np.linalg.norm(point - cam)), zoom_step) if distance_zoom else 1.0
        scans.append(ScanPoint(yaw, pitch, zoom, np.asarray(point, float).copy()))
        mode = mode or OPERATOR_POINT_SCAN
    return InspectionPlan(sel, scans, mode, int(reachable.sum()), ijk[unseen], unseen_pts)


def path_points(path: np.ndarray) -> list[list[float]]:
    """The waypoints of ``path`` as rounded lists (for logs and results)."""
    return [xyz(p) for p in np.asarray(path).reshape(-1, 3)]
