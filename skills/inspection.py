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
planner's volumetric map (``delve.planners.visibility``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from py_trees.common import Status

from ..planners.geometry import path_length, xyz
from ..planners.scan_points import ScanPointSelection, select_scan_points
from ..planners.visibility import BodyCameras, first_hit_m, joint_directions, line_of_sight, surface_voxels
from .base import AgentContext, Param, Skill
from .navigation import navigator
from .robot import MapView, PathStatus, Payload, Robot

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


@dataclass
class _Job:
    """The inspection being carried out."""

    request: dict[str, Any]
    started_s: float
    point: np.ndarray | None = None
    phase: str = "start"
    #: The waypoints the robot had yet to walk when the request came, and where it was.
    paused_path: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pause_position: np.ndarray | None = None
    approached: bool = False
    #: What is re-issued to resume: the paused path, after a way back when the robot left it.
    resume_path: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    full_scan: bool = False
    mode: str = ""
    scans: list[ScanPoint] = field(default_factory=list)
    pending: list[int] = field(default_factory=list)
    current: int | None = None
    captured: int = 0
    skipped: int = 0
    due_s: float = 0.0
    unseen_ijk: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    unseen_pts: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    covered: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    info: dict[str, Any] = field(default_factory=dict)
    walking: bool = False
    walk_left: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    takeover_s: float | None = None


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
                    time_limit_s: float = 2.0) -> InspectionPlan:
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
                             full_scan_fraction=full_scan_fraction, time_limit_s=time_limit_s)
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


def _path(path: np.ndarray) -> list[list[float]]:
    return [xyz(p) for p in np.asarray(path).reshape(-1, 3)]


class Inspect(Skill):
    """Inspections: scan the unseen part of the payload's reachable workspace.

    Every tick, idle or not, the body cameras mark the surface voxels they see (within
    ``body_camera_range_m``, in their view, in line of sight on the onboard map) as
    seen, at most every ``body_camera_period_s``; the record is kept per agent, so
    what the robot saw walking earlier counts. What the payload captures counts too.

    Reads ``inspection_request`` (``{"point": [x, y, z] or null, "requested_s": t}``,
    written by ProcessOperatorCommands on the supervisor's ``scan``). With no request
    it returns FAILURE at once, so the block is skipped.

    On a request, the path the robot was following (the waypoints not yet reached) is
    remembered, and the *reachable workspace* found: the surface voxels within the
    payload's range that some joint-space candidate (a ``joint_grid_deg`` grid: 1170
    at 3°) sees, around the robot, or, when the request names a point, within
    ``point_radius_m`` of it. A point out of the payload's reach (camera farther than
    its range less ``point_radius_m``, or no line of sight) is walked to first
    (``approach_point``; the robot leaves its path, a *pause*): along the navigation
    graph of the onboard map to the nearest pose that reaches it. With no such pose,
    or ``approach_point: false``, the request fails.

    The scan points are the smallest set of candidates covering the unseen part
    (``select_scan_points``), each zoomed for the distance to the surface along its
    axis (``distance_zoom``). When the unseen part exceeds ``full_scan_fraction`` of
    the workspace, a **full scan**: the robot is stopped (a *pause*), every point
    scanned in turn, one sweep of the pan joint, each taking its slew time plus
    ``dwell_s`` of sim time, then the robot **resumes the same path**: the remembered
    waypoints are re-issued (after a walk back to where it left them, when it walked
    to a point). Otherwise a **point scan**: the robot walks on along that path while
    the payload scans; each next scan is the one whose surface the payload, tracking
    it, would see most of where the robot will be, and scans that would see nothing
    new are dropped. With ``resume_until_path_end`` the block keeps running until the
    robot has walked the rest of the path, so the block it interrupted re-plans where
    it would have; else it ends with the scans. A requested point whose area is all
    seen is still looked at once.

    Writes ``inspection_result`` (``ok``, scan points, zooms, covered fraction of the
    unseen part, full_scan, mode, unseen fraction, workspace size, resumed path; on
    failure ``reason`` and ``detail``) and clears ``inspection_request`` when done or
    failed (unless a newer request has replaced it). Logs ``inspection_start``
    (trigger), ``inspection_approach``, ``inspection_scan_points``,
    ``inspection_pause``, ``inspection_scan`` (each capture), ``inspection_resume``,
    ``inspection_done`` and ``inspection_failed`` (reason: ``no_payload``,
    ``bad_point``, ``point_out_of_range``, ``no_path_to_point``,
    ``point_not_reached`` or ``error``).

    Returns FAILURE with no request or when the request fails; RUNNING while it walks
    to a point, scans, or walks the resumed path; SUCCESS when done.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "request_key": Param(str, "inspection_request", "blackboard key of the request", key=True),
        "result_key": Param(str, "inspection_result", "blackboard key the result is written to", key=True),
        "full_scan_fraction": Param(float, 0.5, "full scan when the unseen part exceeds this fraction of the "
                                    "reachable workspace", minimum=0, maximum=1),
        "joint_grid_deg": Param(float, 3.0, "resolution of the candidate scan points in joint space",
                                exclusive_minimum=0, maximum=90),
        "dwell_s": Param(float, 1.0, "time the camera holds still on each scan point", minimum=0),
        "distance_zoom": Param(bool, True, "zoom each scan for the distance to the surface along its axis"),
        "zoom_step": Param(float, 0.5, "zoom levels are multiples of this (rounded down)",
                           exclusive_minimum=0),
        "point_radius_m": Param(float, 1.0, "area around a requested point that a point request inspects",
                                exclusive_minimum=0),
        "approach_point": Param(bool, True, "walk toward a requested point out of the payload's reach; "
                                "false: such a request fails"),
        "resume_until_path_end": Param(bool, True, "keep running until the robot has walked the rest of "
                                       "the interrupted path"),
        "solver_time_limit_s": Param(float, 2.0, "time limit of the exact set cover (CBC, wall clock)",
                                     exclusive_minimum=0),
        "body_camera_range_m": Param(float, 5.0, "surface within this range of a body camera counts as seen",
                                     exclusive_minimum=0),
        "body_camera_horizontal_fov_deg": Param(float, 360.0, "horizontal view of the body cameras together",
                                                exclusive_minimum=0, maximum=360),
        "body_camera_vertical_fov_deg": Param(float, 60.0, "vertical view of the body cameras",
                                              exclusive_minimum=0, maximum=180),
        "body_camera_pitch_deg": Param(float, 0.0, "elevation of the middle of their vertical view",
                                       minimum=-90, maximum=90),
        "body_camera_height_m": Param(float, 0.1, "height of the body cameras above the body centre"),
        "body_camera_period_s": Param(float, 1.0, "how often the body cameras' view is recorded",
                                      exclusive_minimum=0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.k_request = self.key(self.p["request_key"])
        self.k_result = self.key(self.p["result_key"])
        p = self.p
        self.cameras = BodyCameras(
            range_m=p["body_camera_range_m"], horizontal_fov_deg=p["body_camera_horizontal_fov_deg"],
            vertical_fov_deg=p["body_camera_vertical_fov_deg"], pitch_deg=p["body_camera_pitch_deg"],
            height_m=p["body_camera_height_m"])
        self.job: _Job | None = None

    # ---- lifecycle ------------------------------------------------------------------
    def initialise(self) -> None:
        self.job = None

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.stop_own_motion()
        self.job = None

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        record = seen_record(self.ctx, r)
        if now + 1e-9 >= record.next_update_s:
            record.look(r, self.cameras)
            record.next_update_s = now + self.p["body_camera_period_s"]
        if self.job is None:
            request = self.get(self.k_request)
            if not request:
                self.feedback_message = "no inspection request"
                return Status.FAILURE
            self.job = _Job(dict(request), now)
        try:
            return self._step(self.job)
        except Exception as err:  # noqa: BLE001 -- a failed planner call never crashes the tree
            return self._fail("error", f"{type(err).__name__}: {err}")

    def _step(self, job: _Job) -> Status:
        if job.phase == "start":
            return self._start(job)
        if job.phase == "approach":
            return self._approach(job)
        if job.phase == "scan":
            return self._scan(job)
        return self._resume(job)

    # ---- phases ---------------------------------------------------------------------
    def _start(self, job: _Job) -> Status:
        r = self.robot
        point = job.request.get("point")
        self.event("inspection_start", trigger=True, point=point, requested_s=job.request.get("requested_s"),
                   position=xyz(r.position))
        if r.payload is None:
            return self._fail("no_payload", f"{r.name} carries no inspection payload")
        if point is not None:
            try:
                job.point = np.asarray(point, float).reshape(3)
            except (TypeError, ValueError):
                return self._fail("bad_point", f"point {point!r} is not [x, y, z]")
            if not np.all(np.isfinite(job.point)):
                return self._fail("bad_point", f"point {point!r} is not finite")
        # Remember the motion that was running before anything changes it.
        if r.path_status == PathStatus.FOLLOWING:
            job.paused_path = np.asarray(r.remaining_path, float).reshape(-1, 3)
            job.pause_position = r.position
        job.resume_path = job.paused_path
        if job.point is not None and not self._point_in_reach(job.point):
            if not self.p["approach_point"]:
                return self._fail("point_out_of_range", "the point is out of the payload's reach")
            path = self._approach_path(job.point)
            if path is None:
                return self._fail("no_path_to_point", "no pose on the onboard map's navigation graph "
                                                      "reaches the point")
            self._pause(job, "walk to the point")
            job.phase, job.approached = "approach", True
            self.follow(path)
            self.event("inspection_approach", point=xyz(job.point), path_length_m=round(path_length(path), 2))
            self.feedback_message = "walking toward the point"
            return Status.RUNNING
        return self._select(job)

    def _approach(self, job: _Job) -> Status:
        r = self.robot
        assert job.point is not None
        if self._point_in_reach(job.point):
            self.stop_own_motion()
            if len(job.paused_path):
                way = navigator(self.ctx, r).path_to_point(job.pause_position, force=True)[0]
                if way is None:
                    job.resume_path = np.zeros((0, 3))
                    self.event("inspection_resume_lost", detail="no way back to the interrupted path")
                else:
                    job.resume_path = np.vstack([way, job.paused_path])
            return self._select(job)
        if r.command_id == getattr(self, "_command_id", None) and r.path_status == PathStatus.FOLLOWING:
            return Status.RUNNING
        return self._fail("point_not_reached", f"the walk toward the point ended ({r.path_status})")

    def _select(self, job: _Job) -> Status:
        r = self.robot
        record = seen_record(self.ctx, r)
        record.look(r, self.cameras)                     # what the body cameras see from here counts too
        plan = plan_inspection(r, record, point=job.point, point_radius_m=self.p["point_radius_m"],
                               joint_grid_deg=self.p["joint_grid_deg"], distance_zoom=self.p["distance_zoom"],
                               zoom_step=self.p["zoom_step"], full_scan_fraction=self.p["full_scan_fraction"],
                               time_limit_s=self.p["solver_time_limit_s"])
        sel = plan.selection
        job.unseen_ijk, job.unseen_pts, job.scans = plan.unseen_ijk, plan.unseen_pts, plan.scans
        job.covered = np.zeros(len(job.unseen_pts), dtype=bool)
        job.full_scan, job.mode = sel.full_scan, plan.mode
        job.pending = list(range(len(job.scans)))
        job.info = {"workspace_points": plan.workspace_points, "unseen_points": len(plan.unseen_pts),
                    "unseen_fraction": round(sel.unseen_fraction, 4), "solver": sel.solver,
                    "optimal": sel.optimal, "planned_covered_fraction": round(sel.covered_fraction, 4)}
        self.event("inspection_scan_points", mode=job.mode, full_scan=job.full_scan,
                   scan_points=len(job.scans), position=xyz(r.position), **job.info)
        if job.full_scan:
            if not job.approached:
                self._pause(job, "full scan")
            r.stop()
        elif len(job.resume_path):
            # Walk on along the same path while scanning. The robot's motion is taken
            # over, so that the block this one interrupted does not stop the robot as
            # it is halted.
            job.walking, job.walk_left, job.takeover_s = True, job.resume_path, self.ctx.clock.now_s
            self.follow(job.resume_path)
            if job.approached:
                self._log_resume(job)
        job.phase = "scan"
        self._aim(job, self.ctx.clock.now_s)
        self.feedback_message = f"{job.mode or 'nothing to scan'}: {len(job.scans)} scan points"
        return self._scan(job)

    def _scan(self, job: _Job) -> Status:
        now = self.ctx.clock.now_s
        if job.walking:
            self._keep_walking(job)
        while job.current is not None and now + 1e-9 >= job.due_s:
            self._capture(job)
            self._aim(job, job.due_s)
        if job.current is not None:
            return Status.RUNNING
        job.info["covered_fraction"] = round(float(job.covered.mean()) if len(job.covered) else 1.0, 4)
        if job.full_scan and len(job.resume_path):
            self.follow(job.resume_path)
            self._log_resume(job)
            job.phase = "resume"
            return self._resume(job) if self.p["resume_until_path_end"] else self._done(job)
        if job.walking and self.p["resume_until_path_end"]:
            job.phase = "resume"
            return self._resume(job)
        return self._done(job)

    def _resume(self, job: _Job) -> Status:
        r = self.robot
        if r.command_id == getattr(self, "_command_id", None) and r.path_status == PathStatus.FOLLOWING:
            self.feedback_message = "walking the rest of the interrupted path"
            return Status.RUNNING
        return self._done(job)

    def _pause(self, job: _Job, why: str) -> None:
        self.event("inspection_pause", reason=why, position=xyz(self.robot.position),
                   path=_path(job.paused_path))

    def _log_resume(self, job: _Job) -> None:
        way = len(job.resume_path) - len(job.paused_path)
        self.event("inspection_resume", path=_path(job.resume_path), way_back_waypoints=way,
                   position=xyz(self.robot.position))

    # ---- scanning -------------------------------------------------------------------
    def _aim(self, job: _Job, start_s: float) -> None:
        """Point the payload at the next scan point (none left: ``current`` is None);
        its capture is due after the slew and the dwell, from ``start_s``."""
        payload = self.robot.payload
        assert payload is not None
        job.current = None
        if not job.pending:
            return
        if not job.full_scan:            # the robot walks, or has walked: track the targets
            ahead = max(start_s - self.ctx.clock.now_s, 0.0) + self.p["dwell_s"]
            pose = self._pose_ahead(ahead)
            joints = np.array([joints_toward(payload, pose, job.scans[i].target) for i in job.pending])
            zooms = np.array([job.scans[i].zoom for i in job.pending])
            vis = payload_visibility(payload, self.robot.onboard_map, job.unseen_pts, job.unseen_ijk, pose,
                                     joints, zooms)
            gain = (vis & ~job.covered[:, None]).sum(axis=0)
            best = int(np.argmax(gain)) if len(gain) else 0
            if len(gain) and gain[best] == 0 and len(job.unseen_pts):
                job.skipped += len(job.pending)      # out of reach from where the robot walks
                job.pending = []
                return
            job.current = job.pending.pop(best)
            yaw, pitch = joints[best]
        else:
            job.current = job.pending.pop(0)
            yaw, pitch = job.scans[job.current].yaw_deg, job.scans[job.current].pitch_deg
        slew = payload.point_at(float(yaw), float(pitch), job.scans[job.current].zoom)
        job.due_s = start_s + slew + self.p["dwell_s"]

    def _capture(self, job: _Job) -> None:
        """What the payload sees now, pointed at the current scan point, counts as seen
        (in a point scan the payload tracks the scan's target as the robot moves)."""
        r, payload = self.robot, self.robot.payload
        assert payload is not None and job.current is not None
        scan = job.scans[job.current]
        pose = body_pose(r)
        if not job.full_scan:
            yaw, pitch = joints_toward(payload, pose, scan.target)
            payload.point_at(yaw, pitch, scan.zoom)
        new = np.zeros(0, dtype=bool)
        if len(job.unseen_pts):
            joints = np.array([[payload.yaw_deg, payload.pitch_deg]])
            vis = payload_visibility(payload, r.onboard_map, job.unseen_pts, job.unseen_ijk, pose, joints,
                                     np.array([payload.zoom]))[:, 0]
            new = vis & ~job.covered
            job.covered |= vis
            seen_record(self.ctx, r).mark(job.unseen_ijk[vis])
        job.captured += 1
        self.event("inspection_scan", index=job.current, yaw_deg=round(payload.yaw_deg, 2),
                   pitch_deg=round(payload.pitch_deg, 2), zoom=payload.zoom, newly_covered=int(new.sum()),
                   position=xyz(r.position), moving=r.path_status == PathStatus.FOLLOWING)

    def _keep_walking(self, job: _Job) -> None:
        """Keep the robot walking on the interrupted path while the payload scans."""
        r, now = self.robot, self.ctx.clock.now_s
        mine = getattr(self, "_command_id", None)
        if r.command_id == mine and r.path_status == PathStatus.FOLLOWING:
            job.walk_left = np.asarray(r.remaining_path, float).reshape(-1, 3)
        elif (job.takeover_s is not None and now > job.takeover_s and r.path_status == PathStatus.IDLE
              and len(job.walk_left) and mine is not None and r.command_id == mine + 1):
            # On the tick after the take-over: the block this one interrupted stopped
            # the robot as it was halted. Walk on along the same path.
            self.follow(job.walk_left)
        else:
            job.walking = False          # arrived, blocked, or another behaviour took over
        if job.takeover_s is not None and now > job.takeover_s:
            job.takeover_s = None

    def _pose_ahead(self, dt_s: float) -> np.ndarray:
        """Where the robot will be in ``dt_s``, walking on its path at its speed."""
        r = self.robot
        pose = body_pose(r)
        if r.path_status != PathStatus.FOLLOWING or dt_s <= 0:
            return pose
        budget = r.mobility.speed_mps * dt_s
        pts = np.vstack([r.position, np.asarray(r.remaining_path, float).reshape(-1, 3)])
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            d = b - a
            seg = float(np.linalg.norm(d if r.mobility.aerial else d[:2]))
            if seg < 1e-9:
                continue
            pose = np.array([*(a + d * min(budget / seg, 1.0)), math.atan2(d[1], d[0])])
            if seg >= budget:
                break
            budget -= seg
        return pose

    # ---- approaching a point --------------------------------------------------------
    def _point_in_reach(self, point: np.ndarray) -> bool:
        """The camera is within range of the point (less ``point_radius_m``) and sees it
        on the onboard map."""
        payload, m = self.robot.payload, self.robot.onboard_map
        assert payload is not None
        cam = payload.camera_position(body_pose(self.robot))
        if np.linalg.norm(point - cam) > payload.spec.range_m - self.p["point_radius_m"]:
            return False
        ijk = np.floor((point - np.asarray(m.origin, float)) / m.voxel_size_m).astype(np.int64)
        return bool(line_of_sight(m, cam, ijk[None])[0])

    def _approach_path(self, point: np.ndarray) -> np.ndarray | None:
        """Shortest path on the navigation graph to a node from which the camera would
        be within reach of the point, in line of sight; None when there is none."""
        r, payload = self.robot, self.robot.payload
        assert payload is not None
        plan = navigator(self.ctx, r).from_robot()
        if plan is None:
            return None
        reach = payload.spec.range_m - self.p["point_radius_m"]
        # The robot arrives facing any way: the camera is its mount offset from the
        # pan-tilt axis above the node, so the node must reach the point with that to spare.
        mount = payload.camera_position(np.zeros(4))
        spare = float(np.hypot(mount[0], mount[1]))
        nodes = np.array(plan.graph.kdtree.query_ball_point(point, reach + float(np.linalg.norm(mount))),
                         dtype=int)
        if not len(nodes):
            return None
        nodes = nodes[np.isfinite(plan.distances[nodes])]
        m = r.onboard_map
        ijk = np.floor((point - np.asarray(m.origin, float)) / m.voxel_size_m).astype(np.int64)
        for node in nodes[np.argsort(plan.distances[nodes], kind="stable")]:
            above = plan.graph.positions[node] + np.array([0.0, 0.0, mount[2]])
            if np.linalg.norm(point - above) + spare <= reach and line_of_sight(m, above, ijk[None])[0]:
                return plan.path_to(int(node))
        return None

    # ---- endings --------------------------------------------------------------------
    def _done(self, job: _Job) -> Status:
        covered = job.info.get("covered_fraction", 1.0)
        result = {
            "ok": True,
            "point": None if job.point is None else xyz(job.point),
            "requested_s": job.request.get("requested_s"),
            "done_s": round(self.ctx.clock.now_s, 3),
            "mode": job.mode,
            "full_scan": job.full_scan,
            "scan_points": [[round(s.yaw_deg, 2), round(s.pitch_deg, 2)] for s in job.scans],
            "zooms": [s.zoom for s in job.scans],
            "scans_taken": job.captured,
            "scans_skipped": job.skipped,
            "paused_path": _path(job.paused_path),
            "resumed_path": _path(job.resume_path) if job.full_scan or job.approached else [],
            **job.info,
        }
        self.bb.set(self.k_result, result)
        self._clear_request(job)
        self.event("inspection_done", mode=job.mode, full_scan=job.full_scan, scan_points=len(job.scans),
                   scans_taken=job.captured, covered_fraction=covered,
                   unseen_fraction=job.info.get("unseen_fraction", 0.0),
                   duration_s=round(self.ctx.clock.now_s - job.started_s, 2))
        self.feedback_message = f"done: {job.captured} scans, covered {covered:.0%} of the unseen part"
        self.job = None
        return Status.SUCCESS

    def _fail(self, reason: str, detail: str) -> Status:
        job = self.job
        self.stop_own_motion()
        self.bb.set(self.k_result, {"ok": False, "reason": reason, "detail": detail,
                                    "point": None if job is None else job.request.get("point"),
                                    "requested_s": None if job is None else job.request.get("requested_s")})
        if job is not None:
            self._clear_request(job)
        self.event("inspection_failed", reason=reason, detail=detail)
        self.feedback_message = f"{reason}: {detail}"
        self.job = None
        return Status.FAILURE

    def _clear_request(self, job: _Job) -> None:
        """Clear the request this job answered (a newer one stays for the next run)."""
        if self.get(self.k_request) == job.request:
            self.bb.set(self.k_request, None)

