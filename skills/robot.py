"""The robot interface: everything a skill may ask of a robot.

Skills own this protocol; the simulator implements it (``delve.sim.robot``), and a ROS
bridge could implement it later without touching a tree or a skill.

Onboard maps use these voxel values: ``UNKNOWN = -1``, ``FREE = 0``, ``OCCUPIED = 1``
(the same as ``delve.planners.occupancy``).
"""

from __future__ import annotations

import enum
from typing import Any, Protocol

import numpy as np


class PathStatus(str, enum.Enum):
    """Where the robot is with its last ``follow_path`` command."""

    IDLE = "idle"
    FOLLOWING = "following"
    ARRIVED = "arrived"
    BLOCKED = "blocked"


class Mobility(Protocol):
    """What a platform can do; planners read these limits."""

    aerial: bool
    speed_mps: float
    body_height_m: float
    radius_m: float
    max_inclination_deg: float
    max_step_m: float


class MapView(Protocol):
    """A robot's onboard occupancy voxel map, built only from its own scans."""

    @property
    def occupancy(self) -> np.ndarray:
        """int8 array (nx, ny, nz) of UNKNOWN / FREE / OCCUPIED."""

    @property
    def origin(self) -> np.ndarray:
        """World position (m) of the lower corner of voxel (0, 0, 0)."""

    @property
    def voxel_size_m(self) -> float: ...

    @property
    def version(self) -> int:
        """Increases each time the map changes, so planners can cache."""

    def free_voxels(self) -> np.ndarray:
        """Flat indices of the FREE voxels (kept by the map, so no grid scan is needed)."""

    def take_changes(self) -> tuple[np.ndarray, np.ndarray]:

        """Flat voxel indices and values changed since the last call (for map sharing)."""

    def change_log(self) -> ChangeLog:
        """A new log of the voxels that change from now on, for one consumer (a planner
        that updates its results incrementally), independent of ``take_changes``."""


class ChangeLog(Protocol):
    """One consumer's log of a map's changed voxels (:meth:`MapView.change_log`)."""

    def take(self) -> np.ndarray:
        """Flat indices (ascending) of the voxels changed since the last take."""


class Message(Protocol):
    """A radio message: who sent it, to whom, what kind, its payload and when (sim s).

    A protocol, not a class: the radio that implements ``Radio`` makes them."""

    @property
    def sender(self) -> str: ...
    @property
    def recipient(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def data(self) -> Any: ...
    @property
    def sent_s(self) -> float: ...


class Radio(Protocol):
    """A robot's (or the base station's) radio. Messages wait in an outbox until a
    link carries them: nothing sent is lost while the link is down."""

    def send(self, recipient: str, kind: str, data: Any) -> None: ...

    def receive(self) -> list[Message]:
        """Messages delivered since the last call."""

    def linked_to(self, other: str) -> bool:
        """Whether a link to ``other`` exists right now (directly or through the mesh)."""

    @property
    def pending(self) -> int:
        """Messages still waiting in the outbox."""

    def ping(self, other: str) -> bool:
        """One echo request to ``other`` and its reply; False when either is lost or
        no route exists. Each call is one attempt (it may fail on a working link)."""


class CameraDetection(Protocol):
    """One object detection in one camera frame: when, which camera, the detector's
    label and confidence (0..1), the camera's optical centre (3,) and (K, 3) unit rays
    through the pixels of the detection's bounding box, in the world frame."""

    t_s: float
    camera: str
    artifact_class: str
    confidence: float
    origin: np.ndarray
    rays: np.ndarray


class LidarScan(Protocol):
    """One sweep of a range sensor: where the sensor was (3,) and the (N, 3) points its
    beams returned within range, in the world frame the robot believes in."""

    sensor: np.ndarray
    points: np.ndarray


class SignalReading(Protocol):
    """One reading of a signal sensor: ``kind`` ``bluetooth`` (``value`` in dBm, the
    beacon's SSID as ``identifier``) or ``co2`` (ppm, no identifier), taken at
    ``position`` (3,) at ``t_s``."""

    t_s: float
    kind: str
    identifier: str | None
    position: np.ndarray
    value: float


class BreadcrumbDrop(Protocol):
    """The result of a breadcrumb drop: ``ok`` and the new relay's ``name``, or an
    ``error`` saying why not (no breadcrumbs left, ...); ``remaining`` after it."""

    ok: bool
    name: str | None
    remaining: int
    error: str


class PayloadSpecView(Protocol):
    """The limits of a pan-tilt-zoom payload that skills read."""

    @property
    def yaw_limits_deg(self) -> tuple[float, float]: ...

    @property
    def pitch_limits_deg(self) -> tuple[float, float]: ...

    @property
    def range_m(self) -> float:
        """A point farther than this from the camera is not seen."""

    @property
    def joint_grid_deg(self) -> float:
        """Resolution of the candidate scan points in joint space (3° in the paper)."""

    @property
    def max_zoom(self) -> float: ...


class Payload(Protocol):
    """A pan-tilt-zoom inspection camera on the robot's body (the ANYmal's inspection
    payload). Angles are in degrees: yaw turns about the body's z axis (positive to the
    left), pitch raises the camera. A body pose is ``(x, y, z, yaw_rad)`` or a (4, 4)
    transform body -> world."""

    @property
    def spec(self) -> PayloadSpecView: ...

    @property
    def yaw_deg(self) -> float: ...

    @property
    def pitch_deg(self) -> float: ...

    @property
    def zoom(self) -> float: ...

    def view_directions(self, joint_grid_deg: float | None = None) -> np.ndarray:
        """The candidate scan points (K, 2) = (yaw, pitch) on the joint-space grid
        (1170 at 3°)."""

    def camera_position(self, body_pose: np.ndarray) -> np.ndarray:
        """World position (3,) of the camera's optical centre (it does not depend on the joints)."""

    def in_view(self, points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                zoom: float = 1.0) -> np.ndarray:
        """(N, K) bool: which points lie inside the field of view of each (yaw, pitch)
        candidate at ``zoom``, ignoring range and occlusion (pure geometry)."""

    def point_at(self, yaw_deg: float, pitch_deg: float, zoom: float | None = None) -> float:
        """Command the joints (and the zoom); returns the slew time in seconds.
        ValueError outside the joint limits or the zoom range."""

    def zoom_for_distance(self, distance_m: float) -> float:
        """The zoom that keeps an object at ``distance_m`` the size it has at the
        reference distance, within 1..max_zoom."""


class Robot(Protocol):
    """A robot as skills see it."""

    @property
    def name(self) -> str: ...

    @property
    def platform(self) -> str:
        """``legged`` or ``aerial``."""

    @property
    def mobility(self) -> Mobility: ...

    @property
    def position(self) -> np.ndarray:
        """(3,) position of the body centre in metres."""

    @property
    def yaw_rad(self) -> float: ...

    @property
    def view_up_deg(self) -> float:
        """How far above the horizontal the main range sensor sees (half a LiDAR's
        vertical field of view), so planners pick viewpoints it can see from."""

    @property
    def home(self) -> np.ndarray:

        """(3,) position the robot started from (the base station's side)."""

    @property
    def onboard_map(self) -> MapView: ...

    @property
    def endurance_remaining_s(self) -> float: ...

    @property
    def distance_m(self) -> float:
        """Distance travelled so far."""

    @property
    def traversed_path(self) -> np.ndarray:
        """(N, 3) positions the robot has passed, oldest first."""

    @property
    def radio(self) -> Radio: ...

    def follow_path(self, path: np.ndarray) -> None:
        """Start following ``path`` ((N, 3) waypoints); returns at once."""

    def stop(self) -> None: ...

    @property
    def command_id(self) -> int:
        """Counts motion commands (``follow_path`` and ``stop``), so a behaviour can
        tell whether the robot still follows its command."""


    def reset_local_map(self, radius_m: float) -> None:
        """Forget the onboard map within ``radius_m`` of the robot; the next scans map
        it again (the paper's reset of the elevation map after odometry artifacts)."""


    @property
    def path_status(self) -> PathStatus: ...

    @property
    def blocked_reason(self) -> str:
        """Why the last path is BLOCKED (rock in the way, a step too high, ...); "" while
        it is not."""

    @property
    def breadcrumbs(self) -> int:
        """Breadcrumbs (mesh relay nodes) the robot still carries."""

    def deploy_breadcrumb(self) -> BreadcrumbDrop:
        """Drop a breadcrumb where the robot stands; a refusal is a result, not an exception."""

    @property
    def remaining_path(self) -> np.ndarray:
        """(M, 3) waypoints of the path being followed that the robot has not reached
        yet, the next one first; (0, 3) when it follows none. A behaviour that pauses
        another's motion re-issues them to resume it on the same path."""

    @property
    def payload(self) -> Payload | None:
        """The pan-tilt-zoom inspection camera; None when the robot carries none."""

    def take_camera_detections(self) -> list[CameraDetection]:
        """The artifact detector's detections since the last call, oldest first."""

    def take_signal_readings(self) -> list[SignalReading]:
        """The Bluetooth and CO2 readings since the last call, oldest first."""

    def take_lidar_scans(self) -> list[LidarScan]:
        """The range sensors' sweeps since the last call, oldest first (the first call
        starts keeping them; a robot may keep only the latest few)."""


class NetworkView(Protocol):
    """A robot's view of the COPS mobility-communication network.

    ``topology()`` is the plain-dict form of
    :class:`delve.planners.cops.topology.Topology`: every location the robot's own
    sensing has revealed so far, the explored ones, and the edges it observed.
    Location names must be the same for every robot that sees a location (the graph
    world names them; a voxel world names lattice cells by their indices)."""

    def topology(self) -> dict[str, Any]: ...

    def location(self) -> str | None:
        """The location the robot stands at, or None between locations."""

    def arrived(self, location: str) -> bool:
        """Whether the robot stands at ``location``'s position (where the plan has it
        communicate), not only in its region."""

    def route(self, location: str) -> np.ndarray | None:
        """Waypoints (N x 3) from the robot to a known ``location``, None if no route."""
