"""What a robot's artifact sensors produce each step: camera detections and signal readings.

The CERBERUS paper's ANYmal C (Section 2, "Hardware modifications"; Section 3.5,
"Artifacts scoring" and "Inspection payload") is the default:

- four colour cameras of the Alphasense Core (front, left, right, up), 0.4 MP
  FLIR Blackfly S sensors behind lenses of 126° x 92.4° (horizontal x vertical),
  each running the object detector at 3 Hz. An artifact of a visual class is seen
  inside a camera's field of view, within ``camera_range_m`` (the paper's 5 m, the
  range at which the autonomous scanning counts a body camera's view as seen), with
  line of sight through the true world. A frame detects it with a probability that
  falls with the distance (``1 - (d / range)^2``) and with the viewing angle from
  the surface normal, may give it a wrong label, and now and then reports a false
  positive (a random class on a random wall point in view).
- the Explorer's inspection payload (:mod:`delve.sim.payload`): its zoom camera,
  pointed where the payload points, runs the same detector; its range follows from
  the zoom (an object has the same size in pixels at ``zoom`` times the distance),
  so 50 m at the paper's 10x. Its thermal camera sees only survivor and vent. Both
  work only when ``sense`` is given the payload.
- a Bluetooth receiver reading the cell phone's and the cube's signal strength
  (log-distance path loss, extra loss per metre of rock on the straight line,
  Gaussian noise, nothing below the receiver's sensitivity; one SSID per artifact,
  its name, e.g. "cube_2"), and a Sensirion SCD30 CO2 sensor: the gas room holds
  ``co2_room_ppm`` within ``co2_room_radius_m`` (geodesic) of its centre, decaying
  exponentially with the geodesic distance through free space beyond, over an
  ambient level; rock stops it.

A detection's rays go through the pixels of its bounding box. The simulated world
holds no artifact geometry (nor does a robot's map), so the box is modelled as the
patch of surface the artifact stands on, slightly enlarged: rays aim at points of
that patch around the artifact's foot, and their hits in a map (where fusion takes
the median) land on and beside the artifact.

Not modelled: obscurants (dust, fog, smoke), darkness and lighting, motion blur,
detector latency, partial occlusion (line of sight is tested to the centre only),
multipath of radio signals and airflow of gas.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .artifacts import Artifact, GeodesicGrid
from .payload import PanTiltZoomCamera, body_transform, camera_axes
from .world import World

#: Classes the object detector was trained on (paper, Table 1) and used (not the phone).
VISUAL_CLASSES = ("survivor", "fire_extinguisher", "drill", "backpack", "vent", "helmet", "rope")


@dataclass(frozen=True, eq=False)
class CameraDetection:
    """One detection by a camera's detector.

    Fields:
        t_s: sim time of the frame.
        camera: "front", "left", "right", "up", "zoom" or "thermal".
        artifact_class: the detector's label (may be wrong, and is for a false positive).
        confidence: the detector's probability of a correct detection, 0..1.
        origin: (3,) optical centre, world frame.
        rays: (K, 3) unit directions through the pixels of the bounding box.
    """

    t_s: float
    camera: str
    artifact_class: str
    confidence: float
    origin: np.ndarray
    rays: np.ndarray


@dataclass(frozen=True, eq=False)
class SignalReading:
    """One reading of the Bluetooth receiver or the CO2 sensor.

    Fields:
        t_s: sim time.
        kind: "bluetooth" or "co2".
        identifier: the Bluetooth SSID (the artifact's name, e.g. "cell_phone_1"); None for co2.
        position: (3,) where the robot's sensor was (its body centre).
        value: dBm for Bluetooth, ppm for CO2.
    """

    t_s: float
    kind: str
    identifier: str | None
    position: np.ndarray
    value: float


class SpecError(ValueError):
    """A bad sensor parameter; ``field`` names it (the executive finds its line)."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f"{field}: {message}")
        self.field = field


@dataclass(frozen=True)
class ArtifactSensorSpec:
    """Artifact sensor parameters; the paper's values by default, documented choices otherwise.

    Body cameras (paper: Alphasense Core, four colour cameras, 0.4 MP, 126° x 92.4°, 3 Hz):
        camera_names, camera_yaw_deg, camera_pitch_deg: each camera's name and its
            direction in the body frame (yaw left of forward, pitch up). The side
            cameras' tilt (20° up) is not in the paper.
        camera_horizontal_fov_deg, camera_vertical_fov_deg: field of view (pinhole model).
        camera_mount_m: optical centre in the body frame (not in the paper).
        camera_range_m: nothing farther is detected (the paper's 5 m "seen" range).
        inference_rate_hz: detector frames per second per camera.
    Detector (model choices, not in the paper):
        detection_probability: per frame, at close range, facing the surface.
        grazing_factor: the probability's factor when seen edge-on (90° from the normal);
            cos-weighted in between, nothing from behind the surface.
        misclassification_probability: a true detection carries a wrong label.
        false_positive_rate_per_frame: expected false positives per camera frame.
        true_confidence, false_confidence: (low, high) of the uniform confidence drawn
            for true and for false detections.
        rays_per_detection: K rays per detection.
        box_enlargement: the box's patch is the artifact's size times this.
        box_noise_fraction: the box centre's standard deviation, in artifact sizes.
        false_positive_size_m: the size of the object a false positive seems to be.
        visual_classes: classes the detector reports (the phone, cube and gas are left
            to Bluetooth and CO2, as the paper did).
    Inspection payload (its pointing, field of view and zoom: :mod:`delve.sim.payload`):
        zoom_pixel_scale: the zoom camera's angular pixel size at zoom 1 over a body
            camera's (not in the paper); its range is camera_range_m x zoom x this.
        thermal_classes, thermal_range_m, thermal_horizontal_fov_deg,
            thermal_vertical_fov_deg: the thermal camera (classes from the paper; a
            640 px Boson-like camera of 50° x 40° resolving about twice as finely as a
            body camera, hence 10 m, is assumed); thermal_rate_hz: the paper's 3 Hz.
    Bluetooth (typical BLE figures, not in the paper):
        bluetooth_classes: the artifacts that advertise; bluetooth_rate_hz: readings per second.
        bluetooth_power_at_1m_dbm: received power 1 m away in air.
        path_loss_exponent: n in ``P(d) = P(1 m) - 10 n log10(d)``.
        rock_loss_db_per_m: extra loss per metre of rock on the straight line.
        bluetooth_noise_db: standard deviation of the reading.
        bluetooth_sensitivity_dbm: nothing weaker is read.
    CO2 (Sensirion SCD30, 2 s interval; DARPA's 3000 ppm in the gas room, paper Section 4.2):
        co2_rate_hz, co2_ambient_ppm, co2_room_ppm, co2_room_radius_m,
        co2_decay_m (e-folding length beyond the room), co2_noise_ppm,
        co2_cell_m (cell of the geodesic grid; rock thinner than it leaks).
    """

    camera_names: tuple[str, ...] = ("front", "left", "right", "up")
    camera_yaw_deg: tuple[float, ...] = (0.0, 90.0, -90.0, 0.0)
    camera_pitch_deg: tuple[float, ...] = (0.0, 20.0, 20.0, 90.0)
    camera_horizontal_fov_deg: float = 126.0
    camera_vertical_fov_deg: float = 92.4
    camera_mount_m: tuple[float, float, float] = (0.3, 0.0, 0.1)
    camera_range_m: float = 5.0
    inference_rate_hz: float = 3.0
    detection_probability: float = 0.6
    grazing_factor: float = 0.5
    misclassification_probability: float = 0.05
    false_positive_rate_per_frame: float = 0.01
    true_confidence: tuple[float, float] = (0.5, 0.95)
    false_confidence: tuple[float, float] = (0.3, 0.7)
    rays_per_detection: int = 16
    box_enlargement: float = 1.3
    box_noise_fraction: float = 0.1
    false_positive_size_m: float = 0.5
    visual_classes: tuple[str, ...] = VISUAL_CLASSES
    zoom_pixel_scale: float = 1.0
    thermal_classes: tuple[str, ...] = ("survivor", "vent")
    thermal_range_m: float = 10.0
    thermal_horizontal_fov_deg: float = 50.0
    thermal_vertical_fov_deg: float = 40.0
    thermal_rate_hz: float = 3.0
    bluetooth_classes: tuple[str, ...] = ("cell_phone", "cube")
    bluetooth_rate_hz: float = 1.0
    bluetooth_power_at_1m_dbm: float = -59.0
    path_loss_exponent: float = 2.0
    rock_loss_db_per_m: float = 15.0
    bluetooth_noise_db: float = 4.0
    bluetooth_sensitivity_dbm: float = -90.0
    co2_rate_hz: float = 0.5
    co2_ambient_ppm: float = 400.0
    co2_room_ppm: float = 3000.0
    co2_room_radius_m: float = 3.0
    co2_decay_m: float = 5.0
    co2_noise_ppm: float = 30.0
    co2_cell_m: float = 1.0

    def __post_init__(self) -> None:
        problem = self.problem()
        if problem is not None:
            raise SpecError(*problem)

    def problem(self) -> tuple[str, str] | None:
        """The first bad field as (name, message), or None."""
        n = len(self.camera_names)
        for name in ("camera_yaw_deg", "camera_pitch_deg"):
            if len(getattr(self, name)) != n:
                return name, f"needs one value per camera ({n}), got {len(getattr(self, name))}"
        for name in _UNIT_FIELDS:
            if not 0.0 <= getattr(self, name) <= 1.0:
                return name, f"must lie in [0, 1], got {getattr(self, name)}"
        for name in _POSITIVE_FIELDS:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                return name, f"must be > 0, got {value}"
        for name in _NON_NEGATIVE_FIELDS:
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                return name, f"must be >= 0, got {value}"
        for name in _FOV_FIELDS:
            if getattr(self, name) >= 180.0:
                return name, f"must be < 180 for a camera, got {getattr(self, name)}"
        for name in ("true_confidence", "false_confidence"):
            lo, hi = getattr(self, name)
            if not 0.0 <= lo <= hi <= 1.0:
                return name, f"must be (low, high) with 0 <= low <= high <= 1, got {(lo, hi)}"
        if self.rays_per_detection != int(self.rays_per_detection):
            return "rays_per_detection", f"must be an integer, got {self.rays_per_detection}"
        if self.co2_room_ppm < self.co2_ambient_ppm:
            return "co2_room_ppm", (f"must be at least co2_ambient_ppm ({self.co2_ambient_ppm}), "
                                    f"got {self.co2_room_ppm}")
        return None


_UNIT_FIELDS = ("detection_probability", "grazing_factor", "misclassification_probability",
                "false_positive_rate_per_frame")
_FOV_FIELDS = ("camera_horizontal_fov_deg", "camera_vertical_fov_deg", "thermal_horizontal_fov_deg",
               "thermal_vertical_fov_deg")
_POSITIVE_FIELDS = _FOV_FIELDS + (
    "camera_range_m", "inference_rate_hz", "rays_per_detection", "box_enlargement",
    "false_positive_size_m", "zoom_pixel_scale", "thermal_range_m", "thermal_rate_hz",
    "bluetooth_rate_hz", "path_loss_exponent", "co2_rate_hz", "co2_room_radius_m", "co2_decay_m",
    "co2_cell_m")
_NON_NEGATIVE_FIELDS = ("box_noise_fraction", "rock_loss_db_per_m", "bluetooth_noise_db",
                        "co2_ambient_ppm", "co2_noise_ppm")


@dataclass
class _Camera:
    """A camera's frame geometry, for one frame: where it is, where it looks, what it sees."""

    name: str
    origin: np.ndarray
    axes: np.ndarray               # (3, 3) rows: forward, left, up in the world frame
    tan_half: tuple[float, float]  # tan of half the horizontal and vertical field of view
    range_m: float
    classes: tuple[str, ...]

    def in_view(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: points inside the field of view and range (no occlusion test)."""
        rel = points - self.origin
        x, y, z = (rel @ self.axes.T).T
        d = np.linalg.norm(rel, axis=1)
        return (x > 1e-9) & (np.abs(y) <= x * self.tan_half[0]) & (np.abs(z) <= x * self.tan_half[1]) \
            & (d <= self.range_m)


def _tan_half(h_deg: float, v_deg: float, zoom: float = 1.0) -> tuple[float, float]:
    return (math.tan(math.radians(h_deg) / 2) / zoom, math.tan(math.radians(v_deg) / 2) / zoom)


def _plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning the plane perpendicular to ``normal``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


class ArtifactSensors:
    """A robot's artifact sensors over the true world: ``sense`` once per step.

    Each sensor keeps its own rate (cameras 3 Hz, Bluetooth and CO2 theirs): a call
    before a sensor's next frame is due returns nothing for it, and missed frames are
    skipped, not caught up. Random draws come from ``rng`` only, so a seeded rng and
    the same calls give the same readings.
    """

    def __init__(self, world: World, artifacts: list[Artifact], spec: ArtifactSensorSpec | None = None,
                 rng: np.random.Generator | None = None) -> None:
        self.world = world
        self.artifacts = list(artifacts)
        self.spec = spec if spec is not None else ArtifactSensorSpec()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        s = self.spec
        self._pos = np.array([a.position for a in self.artifacts]).reshape(-1, 3)
        self._normal = np.array([a.normal for a in self.artifacts]).reshape(-1, 3)
        self._cls = np.array([a.artifact_class for a in self.artifacts], dtype=object)
        self._tolerance_m = world.voxel_size_m
        #: each body camera's axes (3, 3) in the body frame (rows: forward, left, up)
        self._body_axes = [np.vstack(camera_axes(yaw, pitch))
                           for yaw, pitch in zip(s.camera_yaw_deg, s.camera_pitch_deg)]
        self._of_class = {cs: np.isin(self._cls, cs) for cs in (s.visual_classes, s.thermal_classes)}
        self._due: dict[str, float] = {}
        #: Ground truth for the report, never for the robot: each artifact's name ->
        #: the sim time a sensor first picked it up (a true camera detection, a
        #: Bluetooth reading, or a CO2 reading inside its gas room).
        self.detected: dict[str, float] = {}
        self._bluetooth = np.flatnonzero(np.isin(self._cls, s.bluetooth_classes))
        # the farthest a Bluetooth signal can be read (through air, three sigma of noise)
        self._bluetooth_reach_m = 10 ** ((s.bluetooth_power_at_1m_dbm - s.bluetooth_sensitivity_dbm
                                          + 3 * s.bluetooth_noise_db) / (10 * s.path_loss_exponent))
        self._gas = np.flatnonzero(self._cls == "gas")
        self._co2_grid: GeodesicGrid | None = None
        self._co2_field: np.ndarray | None = None
        if len(self._gas):
            self._co2_grid = GeodesicGrid(world, world.free, s.co2_cell_m)
            limit = s.co2_room_radius_m + s.co2_decay_m * math.log(
                max(s.co2_room_ppm - s.co2_ambient_ppm, 1.0) / max(0.1 * s.co2_noise_ppm, 1e-3))
            self._co2_field = np.min([self._co2_grid.distances(self._pos[i][None], limit)
                                      for i in self._gas], axis=0)

    # ------------------------------------------------------------------ rates
    def _frame_due(self, sensor: str, t_s: float, rate_hz: float) -> bool:
        """True when ``sensor`` takes a frame at ``t_s``; advances its next frame time."""
        due = self._due.get(sensor, -math.inf)
        if t_s < due - 1e-9:
            return False
        period = 1.0 / rate_hz
        nxt = due + period if math.isfinite(due) else t_s + period
        self._due[sensor] = nxt if nxt > t_s + 1e-9 else t_s + period
        return True

    # ------------------------------------------------------------------ sense
    def sense(self, t_s: float, pose: np.ndarray, payload: PanTiltZoomCamera | None = None
              ) -> list[CameraDetection | SignalReading]:
        """Readings at sim time ``t_s`` from body pose ``pose`` (4x4 body -> world, or
        (x, y, z, yaw)). With ``payload`` the zoom and thermal cameras take frames too,
        pointed where it points. Returns camera detections then signal readings."""
        s = self.spec
        rot, trans = body_transform(pose)
        out: list[CameraDetection | SignalReading] = []
        for cam in self._cameras_due(t_s, rot, trans, payload):
            out.extend(self._camera_frame(t_s, cam))
        if len(self._bluetooth) and self._frame_due("bluetooth", t_s, s.bluetooth_rate_hz):
            out.extend(self._bluetooth_readings(t_s, trans))
        if len(self._gas) and self._frame_due("co2", t_s, s.co2_rate_hz):
            out.append(SignalReading(float(t_s), "co2", None, trans.copy(), self.co2_ppm(trans)))
            self._note_gas_room(t_s, trans)
        return out

    def _note_gas_room(self, t_s: float, sensor: np.ndarray) -> None:
        """Record the gas artifact whose room the sensor stands in (the nearest one)."""
        g = float(self._co2_grid.at(self._co2_field, sensor[None])[0])
        if g <= self.spec.co2_room_radius_m:
            i = self._gas[int(np.argmin(np.linalg.norm(self._pos[self._gas] - sensor, axis=1)))]
            self.detected.setdefault(self.artifacts[int(i)].name, float(t_s))

    def _cameras_due(self, t_s: float, rot: np.ndarray, trans: np.ndarray,
                     payload: PanTiltZoomCamera | None) -> list[_Camera]:
        s = self.spec
        cams = []
        # Where the cameras are is worked out only when one of them takes a frame
        # (most calls take none: the cameras run slower than the loop).
        due = [(name, body_axes) for name, body_axes in zip(s.camera_names, self._body_axes)
               if self._frame_due(name, t_s, s.inference_rate_hz)]
        if due:
            mount = trans + rot @ np.asarray(s.camera_mount_m, float)
            cams = [_Camera(name, mount, body_axes @ rot.T, _tan_half(
                s.camera_horizontal_fov_deg, s.camera_vertical_fov_deg), s.camera_range_m, s.visual_classes)
                for name, body_axes in due]
        if payload is None:
            return cams
        zoom = self._frame_due("zoom", t_s, s.inference_rate_hz)
        thermal = self._frame_due("thermal", t_s, s.thermal_rate_hz)
        if not (zoom or thermal):
            return cams
        origin = payload.camera_position(np.vstack([np.c_[rot, trans], [0, 0, 0, 1]]))
        axes = (rot @ np.vstack(camera_axes(payload.yaw_deg, payload.pitch_deg)).T).T
        if zoom:
            h, v = payload.spec.horizontal_fov_deg, payload.spec.vertical_fov_deg
            cams.append(_Camera("zoom", origin, axes, _tan_half(h, v, payload.zoom),
                                self.zoom_range_m(payload.zoom), s.visual_classes))
        if thermal:
            cams.append(_Camera("thermal", origin, axes, _tan_half(s.thermal_horizontal_fov_deg,
                                                                   s.thermal_vertical_fov_deg),
                                s.thermal_range_m, s.thermal_classes))
        return cams

    def zoom_range_m(self, zoom: float) -> float:
        """The zoom camera's range at ``zoom``: where an object is as many pixels tall
        as it is at a body camera's range (50 m at the paper's 10x)."""
        return self.spec.camera_range_m * float(zoom) * self.spec.zoom_pixel_scale

    # ---------------------------------------------------------------- cameras
    def visible(self, cam: _Camera) -> np.ndarray:
        """Indices of the artifacts of the camera's classes in its view and range, with
        line of sight from its optical centre to their centres through the true world."""
        if len(self._pos) == 0:
            return np.zeros(0, dtype=int)
        near = np.flatnonzero(self._of_class[cam.classes]
                              & (np.abs(self._pos - cam.origin).max(axis=1) <= cam.range_m))
        if len(near):
            near = near[cam.in_view(self._pos[near])]
        if len(near) == 0:
            return near
        rel = self._pos[near] - cam.origin
        d = np.linalg.norm(rel, axis=1)
        hit = self.world.cast_rays(np.broadcast_to(cam.origin, rel.shape), rel / d[:, None],
                                   cam.range_m + self._tolerance_m)
        return near[hit.astype(float) >= d - self._tolerance_m]

    def detection_probability(self, cam: _Camera, i: int) -> float:
        """Per-frame probability that ``cam`` detects artifact ``i`` (assumed visible)."""
        s = self.spec
        rel = cam.origin - self._pos[i]
        d = float(np.linalg.norm(rel))
        cos = float(self._normal[i] @ rel) / d if d > 0 else 1.0
        if cos < 0.0:
            return 0.0
        angle = s.grazing_factor + (1.0 - s.grazing_factor) * cos
        return s.detection_probability * max(1.0 - (d / cam.range_m) ** 2, 0.0) * angle

    def _camera_frame(self, t_s: float, cam: _Camera) -> list[CameraDetection]:
        s, rng = self.spec, self.rng
        out = []
        for i in self.visible(cam):
            if rng.random() >= self.detection_probability(cam, int(i)):
                continue
            a = self.artifacts[int(i)]
            self.detected.setdefault(a.name, float(t_s))
            label = a.artifact_class
            others = [c for c in cam.classes if c != label]
            if others and rng.random() < s.misclassification_probability:
                label = str(rng.choice(others))
            foot = a.position - a.normal * (0.5 * a.size_m)
            rays = self._box_rays(cam.origin, foot, a.normal, a.size_m)
            out.append(CameraDetection(float(t_s), cam.name, label,
                                       float(rng.uniform(*s.true_confidence)), cam.origin.copy(), rays))
        if rng.random() < s.false_positive_rate_per_frame:
            fp = self._false_positive(t_s, cam)
            if fp is not None:
                out.append(fp)
        return out

    def _box_rays(self, origin: np.ndarray, centre: np.ndarray, normal: np.ndarray,
                  size_m: float) -> np.ndarray:
        """K unit rays from ``origin`` through a square patch (the box) around ``centre``
        in the plane perpendicular to ``normal``, its side size_m x box_enlargement,
        its centre jittered by box_noise_fraction sizes."""
        s, rng = self.spec, self.rng
        e1, e2 = _plane_basis(normal)
        half = 0.5 * size_m * s.box_enlargement
        shift = rng.normal(0.0, s.box_noise_fraction * size_m, 2)
        ab = rng.uniform(-half, half, (int(s.rays_per_detection), 2)) + shift
        points = centre + ab[:, :1] * e1 + ab[:, 1:] * e2
        rays = points - origin
        return rays / np.linalg.norm(rays, axis=1, keepdims=True)

    def _false_positive(self, t_s: float, cam: _Camera) -> CameraDetection | None:
        """A random class on the rock surface along a random direction in view, if the
        ray meets rock within range."""
        s, rng = self.spec, self.rng
        u, v = rng.uniform(-1.0, 1.0, 2) * np.asarray(cam.tan_half)
        direction = cam.axes[0] + u * cam.axes[1] + v * cam.axes[2]
        direction /= np.linalg.norm(direction)
        label = str(rng.choice(cam.classes))
        confidence = float(rng.uniform(*s.false_confidence))
        hit = float(self.world.cast_rays(cam.origin[None], direction[None], cam.range_m)[0])
        if not math.isfinite(hit):
            return None
        rays = self._box_rays(cam.origin, cam.origin + hit * direction, -direction, s.false_positive_size_m)
        return CameraDetection(float(t_s), cam.name, label, confidence, cam.origin.copy(), rays)

    # ---------------------------------------------------------------- signals
    def rock_length_m(self, sensor: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Metres of rock (M,) on the straight segments from ``sensor`` to each target
        (M, 3) in the true world, sampled every voxel (one ``is_free`` call for all)."""
        targets = np.asarray(targets, float).reshape(-1, 3)
        length = np.linalg.norm(targets - sensor, axis=1)
        n = np.maximum(np.ceil(length / self.world.voxel_size_m).astype(int), 1)
        seg = np.repeat(np.arange(len(targets)), n)
        t = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n) + 0.5) / np.repeat(n, n)
        pts = sensor + t[:, None] * (targets[seg] - sensor)
        rock = np.bincount(seg, weights=~self.world.is_free(pts), minlength=len(targets))
        return length * rock / n

    def bluetooth_dbm(self, sensor: np.ndarray, indices) -> np.ndarray:
        """Noise-free signal strength (dBm) of the artifacts ``indices`` at ``sensor``."""
        s = self.spec
        i = np.asarray(indices, dtype=int).reshape(-1)
        d = np.maximum(np.linalg.norm(self._pos[i] - sensor, axis=1), 1.0)   # the model holds from 1 m
        return (s.bluetooth_power_at_1m_dbm - 10.0 * s.path_loss_exponent * np.log10(d)
                - s.rock_loss_db_per_m * self.rock_length_m(sensor, self._pos[i]))

    def _bluetooth_readings(self, t_s: float, sensor: np.ndarray) -> list[SignalReading]:
        s = self.spec
        near = self._bluetooth[np.linalg.norm(self._pos[self._bluetooth] - sensor, axis=1)
                               <= self._bluetooth_reach_m]
        if len(near) == 0:
            return []
        values = self.bluetooth_dbm(sensor, near) + self.rng.normal(0.0, s.bluetooth_noise_db, len(near))
        out = [SignalReading(float(t_s), "bluetooth", self.artifacts[int(i)].name, sensor.copy(), float(v))
               for i, v in zip(near, values) if v >= s.bluetooth_sensitivity_dbm]
        for r in out:
            self.detected.setdefault(r.identifier, float(t_s))
        return out

    def co2_ppm(self, sensor: np.ndarray, noise: bool = True) -> float:
        """CO2 concentration (ppm) at ``sensor``: the room's level within its radius of a
        gas artifact, decaying with the geodesic distance beyond, over ambient."""
        s = self.spec
        if self._co2_grid is None:
            return s.co2_ambient_ppm
        g = float(self._co2_grid.at(self._co2_field, sensor[None])[0])
        excess = (s.co2_room_ppm - s.co2_ambient_ppm) * math.exp(-max(g - s.co2_room_radius_m, 0.0)
                                                                 / s.co2_decay_m)
        value = s.co2_ambient_ppm + excess
        if noise:
            value += float(self.rng.normal(0.0, s.co2_noise_ppm))
        return max(value, 0.0)
