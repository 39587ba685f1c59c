"""The CERBERUS inspection (paper section 3.5; the *inspections* block of Figure 13) as
a subtree of small behaviours, ``trees/subtrees/inspections.yaml``::

    Sequence (no memory)
      LookWithBodyCameras            every tick: what the body cameras see counts as seen
      Selector
        Sequence (memory)
          TakeInspectionRequest      FAILURE without a request
          ApproachInspectionPoint    walk toward a requested point out of reach
          ChooseScanPoints           the scan points over the unseen workspace
          ScanWithPayload            point the payload at each, capture
          ResumeInterruptedPath      re-issue the path the robot was on, walk it
          ReportInspection           write the result, clear the request
        ReportInspectionFailure      a step failed: write why, clear the request

The steps share the inspection under way (:class:`InspectionJob`) through the agent's
:class:`InspectionState` (``ctx.services["inspection"]``), and with it the last motion
command any of them issued: whichever step is stopped stops only the inspection's own
motion. A step that fails records why in the job and returns FAILURE; the reporter
below writes the result. Interrupted (a higher-priority block takes over), the steps
stop the robot if it still follows the inspection's command and drop the job; the
request stays, and the next run starts it again.
"""
from __future__ import annotations

from abc import abstractmethod

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ..planners.geometry import path_length, xyz
from ..planners.scan_points import NODE_LIMIT
from ..planners.unseen_wall import unseen_wall
from ..planners.visibility import BodyCameras, line_of_sight
from .base import AgentContext, Param, ParamNamedPort, Skill
from .inspection import (
    ScanPoint,
    body_pose,
    joints_toward,
    path_points,
    payload_visibility,
    plan_inspection,
    seen_record,
)
from .navigation import navigator
from .robot import PathStatus

#: ``ctx.services`` key of the agent's :class:`InspectionState`.
STATE_SERVICE = "inspection"

#: The request (``{"point": [x, y, z] or null, "requested_s": t}``), as the steps read it.
REQUEST_IN = ParamNamedPort(dict, required=False, description="the inspection request: {point: [x, y, z] or null, "
                            "requested_s}; null or none: no request", key_param="request_key")


@dataclass
class InspectionJob:
    """The inspection under way: the request, what the robot was doing when it came,
    the scan points and how far the scanning has got."""

    request: dict[str, Any]
    started_s: float
    point_radius_m: float
    point: np.ndarray | None = None
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
    scanning: bool = False
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
    resuming: bool = False
    #: Why it failed (reason, detail), once a step has failed.
    failure: tuple[str, str] | None = None


@dataclass
class InspectionState:
    """What the inspection steps of one agent share: the job under way, the body
    cameras (as ``LookWithBodyCameras`` is configured), and the last motion command an
    inspection step issued."""

    job: InspectionJob | None = None
    cameras: BodyCameras = field(default_factory=BodyCameras)
    command_id: int | None = None


def inspection_state(ctx: AgentContext) -> InspectionState:
    """The agent's shared :class:`InspectionState`, created on first use."""
    state = ctx.services.get(STATE_SERVICE)
    if state is None:
        state = ctx.services[STATE_SERVICE] = InspectionState()
    return state


class LookWithBodyCameras(Skill):
    """Mark what the body cameras see as seen: the surface voxels within
    ``body_camera_range_m``, in their view and in line of sight on the onboard map, at
    most every ``body_camera_period_s``. The record is kept per agent
    (``ctx.services["body_camera_seen"]``), so what the robot saw walking earlier
    counts when it inspects. Always SUCCESS.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
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

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        p = self.p
        self.cameras = BodyCameras(
            range_m=p["body_camera_range_m"], horizontal_fov_deg=p["body_camera_horizontal_fov_deg"],
            vertical_fov_deg=p["body_camera_vertical_fov_deg"], pitch_deg=p["body_camera_pitch_deg"],
            height_m=p["body_camera_height_m"])
        inspection_state(ctx).cameras = self.cameras

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        record = seen_record(self.ctx, r)
        if now + 1e-9 >= record.next_update_s:
            record.look(r, self.cameras)
            record.next_update_s = now + self.p["body_camera_period_s"]
        return Status.SUCCESS


class NoticeUnseenWall(Skill):
    """The exploration planner's inspection request: wall of the onboard map within
    ``radius_m`` that no camera has covered (the body cameras' and payload's record)
    and that the robot sees from where it stands.

    Only once the supervisor enabled it (``autonomous_scans``, the paper's autonomous
    scanning; off by default). Cheap and rate-limited: looks at most every
    ``check_period_s``, only in mode ``when_mode`` (null: any), only when the robot
    carries a payload and no request is pending, and not within ``min_spacing_m`` of
    where it last asked. When the unseen
    wall is at least ``min_unseen_area_m2`` and ``min_unseen_fraction`` of the wall
    within reach, writes ``request_key`` (``{point: null, requested_s, source:
    planner}``: scan the area, as the supervisor's ``scan``) and logs
    ``inspection_requested`` (trigger). Always SUCCESS (the inspection steps that
    follow take the request up).
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "request_key": Param(str, "inspection_request", "blackboard key of the request", key=True),
        "check_period_s": Param(float, 10.0, "how often the unseen wall is measured", exclusive_minimum=0),
        "radius_m": Param(float, 5.0, "wall within this distance counts", exclusive_minimum=0),
        "min_unseen_area_m2": Param(float, 6.0, "unseen wall that calls for a scan", minimum=0),
        "min_unseen_fraction": Param(float, 0.3, "... and its least share of the wall within reach",
                                     minimum=0, maximum=1),
        "min_spacing_m": Param(float, 10.0, "no new request this close to where the last was made", minimum=0),
        "when_mode": Param(str, "explore", "the mode the robot must be in (null: any)", nullable=True),
    }
    INPUT_PORTS = {"inspection_request": REQUEST_IN,
                   "mode": PortInformation(str, required=False, description="the mode of operation"),
                   "autonomous_scans": PortInformation(bool, required=False, default_value=False,
                                                       description="True once the supervisor enabled them")}
    OUTPUT_PORTS = {"inspection_request": ParamNamedPort(dict | None, description="the planner's request",
                                                         key_param="request_key")}

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.next_check_s = -math.inf
        self.last_at: np.ndarray | None = None

    def update(self) -> Status:
        r, now, p = self.robot, self.ctx.clock.now_s, self.p
        if not self.read("autonomous_scans", False) or now + 1e-9 < self.next_check_s or r.payload is None \
                or self.read("inspection_request"):
            return Status.SUCCESS
        if p["when_mode"] is not None and self.read("mode") != p["when_mode"]:
            return Status.SUCCESS
        if self.last_at is not None and np.linalg.norm(r.position - self.last_at) < p["min_spacing_m"]:
            return Status.SUCCESS
        self.next_check_s = now + p["check_period_s"]
        eye = r.payload.camera_position(body_pose(r))
        wall = unseen_wall(r.onboard_map, eye, p["radius_m"], seen_record(self.ctx, r).seen)
        if wall.area_m2 >= p["min_unseen_area_m2"] and wall.fraction >= p["min_unseen_fraction"]:
            self.last_at = r.position
            self.write("inspection_request", {"point": None, "requested_s": round(now, 3), "source": "planner"})
            self.event("inspection_requested", trigger=True, source="planner", unseen_area_m2=round(wall.area_m2, 1),
                       unseen_fraction=round(wall.fraction, 3), centroid=xyz(wall.centroid))
        return Status.SUCCESS


class InspectionStep(Skill):
    """Base of the inspection's steps: each works on the shared job (``step``); an
    exception fails the inspection with reason ``error``; motion commands are the
    inspection's, whichever step issued them."""

    ABSTRACT = True

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.state = inspection_state(ctx)

    @abstractmethod
    def step(self, job: InspectionJob) -> Status:
        """This step's part of the inspection ``job``."""

    def update(self) -> Status:
        job = self.state.job
        if job is None:
            return Status.FAILURE
        return self._guarded(job)

    def _guarded(self, job: InspectionJob) -> Status:
        try:
            return self.step(job)
        except Exception as err:  # noqa: BLE001 -- a failed planner call never crashes the tree
            return self.fail(job, "error", f"{type(err).__name__}: {err}")

    def fail(self, job: InspectionJob, reason: str, detail: str) -> Status:
        """The inspection failed: ``ReportInspectionFailure`` writes why."""
        job.failure = (reason, detail)
        self.feedback_message = f"{reason}: {detail}"
        return Status.FAILURE

    def follow(self, path: Any) -> None:
        self.robot.follow_path(path)
        self.state.command_id = self.robot.command_id

    def owns_motion(self) -> bool:
        """Whether the robot still follows the inspection's last command."""
        return self.state.command_id is not None and self.state.command_id == self.robot.command_id

    def stop_own_motion(self) -> None:
        if self.ctx.robot is not None and self.owns_motion():
            self.robot.stop()

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.state.job is not None:
            self.stop_own_motion()
            self.state.job = None

    def pause(self, job: InspectionJob, why: str) -> None:
        self.event("inspection_pause", reason=why, position=xyz(self.robot.position),
                   path=path_points(job.paused_path))

    def log_resume(self, job: InspectionJob) -> None:
        way = len(job.resume_path) - len(job.paused_path)
        self.event("inspection_resume", path=path_points(job.resume_path), way_back_waypoints=way,
                   position=xyz(self.robot.position))


class TakeInspectionRequest(InspectionStep):
    """Take up an inspection request (``{"point": [x, y, z] or null, "requested_s": t}``,
    written by ProcessOperatorCommands on the supervisor's ``scan``) and remember the
    path the robot was following (its waypoints not yet reached) to resume it later.

    Reads ``request_key``. Logs ``inspection_start`` (trigger). Returns FAILURE at once
    without a request (the block is skipped), and when the robot carries no payload
    (``no_payload``) or the point is not three finite numbers (``bad_point``);
    SUCCESS otherwise.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "request_key": Param(str, "inspection_request", "blackboard key of the request", key=True),
        "point_radius_m": Param(float, 1.0, "area around a requested point that a point request inspects",
                                exclusive_minimum=0),
    }
    INPUT_PORTS = {"inspection_request": REQUEST_IN}

    def update(self) -> Status:
        request = self.read("inspection_request")
        if not request:
            self.feedback_message = "no inspection request"
            return Status.FAILURE
        job = self.state.job = InspectionJob(dict(request), self.ctx.clock.now_s, self.p["point_radius_m"])
        return self._guarded(job)

    def step(self, job: InspectionJob) -> Status:
        r = self.robot
        point = job.request.get("point")
        self.event("inspection_start", trigger=True, point=point, requested_s=job.request.get("requested_s"),
                   position=xyz(r.position))
        if r.payload is None:
            return self.fail(job, "no_payload", f"{r.name} carries no inspection payload")
        if point is not None:
            try:
                job.point = np.asarray(point, float).reshape(3)
            except (TypeError, ValueError):
                return self.fail(job, "bad_point", f"point {point!r} is not [x, y, z]")
            if not np.all(np.isfinite(job.point)):
                return self.fail(job, "bad_point", f"point {point!r} is not finite")
        # Remember the motion that was running before anything changes it.
        if r.path_status == PathStatus.FOLLOWING:
            job.paused_path = np.asarray(r.remaining_path, float).reshape(-1, 3)
            job.pause_position = r.position
        job.resume_path = job.paused_path
        return Status.SUCCESS


class ApproachInspectionPoint(InspectionStep):
    """Walk toward a requested point out of the payload's reach (camera farther than
    its range less the request's ``point_radius_m``, or no line of sight on the onboard
    map): along the navigation graph of the onboard map to the nearest pose from which
    the camera reaches it. The robot leaves its path (an ``inspection_pause``); once in
    reach, the way back to where it left the path goes in front of the path to resume.

    Logs ``inspection_approach``. Returns SUCCESS at once without a point or with one
    in reach, and when the point comes in reach; RUNNING on the way; FAILURE with
    ``point_out_of_range`` (``approach_point: false``), ``no_path_to_point`` (no pose
    reaches it) or ``point_not_reached`` (the walk ended short).
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "approach_point": Param(bool, True, "walk toward a requested point out of the payload's reach; "
                                "false: such a request fails"),
    }

    def step(self, job: InspectionJob) -> Status:
        if job.approached:
            return self._approach(job)
        if job.point is None or self._point_in_reach(job, job.point):
            return Status.SUCCESS
        if not self.p["approach_point"]:
            return self.fail(job, "point_out_of_range", "the point is out of the payload's reach")
        path = self._approach_path(job, job.point)
        if path is None:
            return self.fail(job, "no_path_to_point", "no pose on the onboard map's navigation graph reaches the "
                                                      "point")
        self.pause(job, "walk to the point")
        job.approached = True
        self.follow(path)
        self.event("inspection_approach", point=xyz(job.point), path_length_m=round(path_length(path), 2))
        self.feedback_message = "walking toward the point"
        return Status.RUNNING

    def _approach(self, job: InspectionJob) -> Status:
        r = self.robot
        assert job.point is not None
        if self._point_in_reach(job, job.point):
            self.stop_own_motion()
            if len(job.paused_path):
                way = navigator(self.ctx, r).path_to_point(job.pause_position, force=True)[0]
                if way is None:
                    job.resume_path = np.zeros((0, 3))
                    self.event("inspection_resume_lost", detail="no way back to the interrupted path")
                else:
                    job.resume_path = np.vstack([way, job.paused_path])
            return Status.SUCCESS
        if self.owns_motion() and r.path_status == PathStatus.FOLLOWING:
            return Status.RUNNING
        return self.fail(job, "point_not_reached", f"the walk toward the point ended ({r.path_status})")

    def _point_in_reach(self, job: InspectionJob, point: np.ndarray) -> bool:
        """The camera is within range of the point (less ``point_radius_m``) and sees it
        on the onboard map."""
        payload, m = self.robot.payload, self.robot.onboard_map
        assert payload is not None
        cam = payload.camera_position(body_pose(self.robot))
        if np.linalg.norm(point - cam) > payload.spec.range_m - job.point_radius_m:
            return False
        ijk = np.floor((point - np.asarray(m.origin, float)) / m.voxel_size_m).astype(np.int64)
        return bool(line_of_sight(m, cam, ijk[None])[0])

    def _approach_path(self, job: InspectionJob, point: np.ndarray) -> np.ndarray | None:
        """Shortest path on the navigation graph to a node from which the camera would
        be within reach of the point, in line of sight; None when there is none."""
        r, payload = self.robot, self.robot.payload
        assert payload is not None
        plan = navigator(self.ctx, r).from_robot()
        if plan is None:
            return None
        reach = payload.spec.range_m - job.point_radius_m
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


class ChooseScanPoints(InspectionStep):
    """Choose the scan points: the smallest set of the payload's joint-space candidates
    (a ``joint_grid_deg`` grid: 1170 at 3°) that covers the unseen part of its
    reachable workspace, around the robot or within the request's ``point_radius_m``
    of its point (``select_scan_points``), each zoomed for the distance to the surface
    along its axis (``distance_zoom``). What the body cameras see from here counts as
    seen first.

    When the unseen part exceeds ``full_scan_fraction`` of the workspace, a **full
    scan**: the robot is stopped (an ``inspection_pause``, unless it already left its
    path for the point). Otherwise a **point scan**: the robot walks on along the path
    it was on while the payload scans (the inspection takes over its motion).

    Logs ``inspection_scan_points``. Returns SUCCESS.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "full_scan_fraction": Param(float, 0.5, "full scan when the unseen part exceeds this fraction of the "
                                    "reachable workspace", minimum=0, maximum=1),
        "joint_grid_deg": Param(float, 3.0, "resolution of the candidate scan points in joint space",
                                exclusive_minimum=0, maximum=90),
        "distance_zoom": Param(bool, True, "zoom each scan for the distance to the surface along its axis"),
        "zoom_step": Param(float, 0.5, "zoom levels are multiples of this (rounded down)",
                           exclusive_minimum=0),
        "solver_node_limit": Param(int, NODE_LIMIT, "branch-and-bound nodes of the exact set cover (CBC): a "
                                   "work limit, so that the scans do not depend on the machine's speed", minimum=1),
    }

    def step(self, job: InspectionJob) -> Status:
        r = self.robot
        record = seen_record(self.ctx, r)
        record.look(r, self.state.cameras)               # what the body cameras see from here counts too
        plan = plan_inspection(r, record, point=job.point, point_radius_m=job.point_radius_m,
                               joint_grid_deg=self.p["joint_grid_deg"], distance_zoom=self.p["distance_zoom"],
                               zoom_step=self.p["zoom_step"], full_scan_fraction=self.p["full_scan_fraction"],
                               node_limit=self.p["solver_node_limit"])
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
                self.pause(job, "full scan")
            r.stop()
        elif len(job.resume_path):
            # Walk on along the same path while scanning. The robot's motion is taken
            # over, so that the block this one interrupted does not stop the robot as
            # it is halted.
            job.walking, job.walk_left, job.takeover_s = True, job.resume_path, self.ctx.clock.now_s
            self.follow(job.resume_path)
            if job.approached:
                self.log_resume(job)
        self.feedback_message = f"{job.mode or 'nothing to scan'}: {len(job.scans)} scan points"
        return Status.SUCCESS


class ScanWithPayload(InspectionStep):
    """Point the payload at each scan point and capture: what it sees counts as seen.

    In a full scan every point in turn, one sweep of the pan joint, each taking its
    slew time plus ``dwell_s`` of sim time. In a point scan the robot walks on and the
    payload tracks each scan's surface; the next scan is the one that would see most
    of what is still unseen from where the robot will be when it captures, and scans
    that would see nothing new are dropped.

    Logs ``inspection_scan`` per capture. Returns RUNNING while scanning; SUCCESS when
    every scan point is done.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "dwell_s": Param(float, 1.0, "time the camera holds still on each scan point", minimum=0),
    }

    def step(self, job: InspectionJob) -> Status:
        now = self.ctx.clock.now_s
        if not job.scanning:
            job.scanning = True
            self._aim(job, now)
        if job.walking:
            self._keep_walking(job)
        while job.current is not None and now + 1e-9 >= job.due_s:
            self._capture(job)
            self._aim(job, job.due_s)
        if job.current is not None:
            return Status.RUNNING
        job.info["covered_fraction"] = round(float(job.covered.mean()) if len(job.covered) else 1.0, 4)
        return Status.SUCCESS

    def _aim(self, job: InspectionJob, start_s: float) -> None:
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

    def _capture(self, job: InspectionJob) -> None:
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

    def _keep_walking(self, job: InspectionJob) -> None:
        """Keep the robot walking on the interrupted path while the payload scans."""
        r, now = self.robot, self.ctx.clock.now_s
        mine = self.state.command_id
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


class ResumeInterruptedPath(InspectionStep):
    """Resume the path the robot was on when the request came: after a full scan (or a
    walk to the point) the remembered waypoints are re-issued, after the way back to
    where it left them (``inspection_resume``). With ``resume_until_path_end`` the
    block keeps running until the robot has walked the rest of that path, so the block
    it interrupted re-plans where it would have; else it ends with the scans.

    Returns RUNNING while the robot walks the rest of the path; SUCCESS then, or at
    once when there is nothing to walk.
    """

    PARAMS: ClassVar[dict[str, Param]] = {
        "resume_until_path_end": Param(bool, True, "keep running until the robot has walked the rest of "
                                       "the interrupted path"),
    }

    def step(self, job: InspectionJob) -> Status:
        if not job.resuming:
            job.resuming = True
            if job.full_scan and len(job.resume_path):
                self.follow(job.resume_path)
                self.log_resume(job)
                if not self.p["resume_until_path_end"]:
                    return Status.SUCCESS
            elif not (job.walking and self.p["resume_until_path_end"]):
                return Status.SUCCESS
        if self.owns_motion() and self.robot.path_status == PathStatus.FOLLOWING:
            self.feedback_message = "walking the rest of the interrupted path"
            return Status.RUNNING
        return Status.SUCCESS


class _Report(InspectionStep):
    """Writes the result and clears the request the job answered."""

    ABSTRACT = True

    PARAMS: ClassVar[dict[str, Param]] = {
        "request_key": Param(str, "inspection_request", "blackboard key of the request (cleared)", key=True),
        "result_key": Param(str, "inspection_result", "blackboard key the result is written to", key=True),
    }
    INPUT_PORTS = {"inspection_request": REQUEST_IN}
    OUTPUT_PORTS = {
        "inspection_request": ParamNamedPort(dict | None, description="cleared (null) once answered, unless a newer "
                                             "request has replaced it", key_param="request_key"),
        "inspection_result": ParamNamedPort(dict, description="the result: ok, and what was done or why it failed",
                                            key_param="result_key"),
    }

    def finish(self, job: InspectionJob, result: dict[str, Any]) -> None:
        """Write ``result``; clear the request this job answered (a newer one stays for
        the next run); the job is over."""
        self.write("inspection_result", result)
        if self.read("inspection_request") == job.request:
            self.write("inspection_request", None)
        self.state.job = None


class ReportInspection(_Report):
    """Report the inspection done: ``result_key`` gets ``ok``, the scan points and
    zooms, scans taken and skipped, the covered fraction of the unseen part, full scan
    or not, mode, unseen fraction, workspace size and the paused and resumed paths;
    ``request_key`` is cleared (unless a newer request has replaced it).

    Logs ``inspection_done``. Returns SUCCESS.
    """

    def step(self, job: InspectionJob) -> Status:
        covered = job.info.get("covered_fraction", 1.0)
        now = self.ctx.clock.now_s
        self.finish(job, {
            "ok": True,
            "point": None if job.point is None else xyz(job.point),
            "requested_s": job.request.get("requested_s"),
            "done_s": round(now, 3),
            "mode": job.mode,
            "full_scan": job.full_scan,
            "scan_points": [[round(s.yaw_deg, 2), round(s.pitch_deg, 2)] for s in job.scans],
            "zooms": [s.zoom for s in job.scans],
            "scans_taken": job.captured,
            "scans_skipped": job.skipped,
            "paused_path": path_points(job.paused_path),
            "resumed_path": path_points(job.resume_path) if job.full_scan or job.approached else [],
            **job.info,
        })
        self.event("inspection_done", mode=job.mode, full_scan=job.full_scan, scan_points=len(job.scans),
                   scans_taken=job.captured, covered_fraction=covered,
                   unseen_fraction=job.info.get("unseen_fraction", 0.0), duration_s=round(now - job.started_s, 2))
        self.feedback_message = f"done: {job.captured} scans, covered {covered:.0%} of the unseen part"
        return Status.SUCCESS


class ReportInspectionFailure(_Report):
    """Report why the inspection failed, when a step has failed: the robot is stopped
    if it still follows the inspection's command, ``result_key`` gets ``ok: false``,
    ``reason`` and ``detail``, and ``request_key`` is cleared (unless a newer request
    has replaced it).

    Logs ``inspection_failed`` (reason: ``no_payload``, ``bad_point``,
    ``point_out_of_range``, ``no_path_to_point``, ``point_not_reached`` or
    ``error``). Returns FAILURE, also with nothing to report.
    """

    def step(self, job: InspectionJob) -> Status:
        if job.failure is None:
            return Status.FAILURE
        reason, detail = job.failure
        self.stop_own_motion()
        self.finish(job, {"ok": False, "reason": reason, "detail": detail, "point": job.request.get("point"),
                          "requested_s": job.request.get("requested_s")})
        self.event("inspection_failed", reason=reason, detail=detail)
        self.feedback_message = f"{reason}: {detail}"
        return Status.FAILURE


__all__ = ["STATE_SERVICE", "ApproachInspectionPoint", "ChooseScanPoints", "InspectionJob", "InspectionState",
           "InspectionStep", "LookWithBodyCameras", "NoticeUnseenWall", "ReportInspection", "ReportInspectionFailure",
           "ResumeInterruptedPath", "ScanWithPayload", "TakeInspectionRequest", "inspection_state"]
