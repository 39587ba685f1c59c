"""Unit tests for delve.sim.artifact_sensors on a small hand-carved world.

Two parallel tunnels along x (y = 0 and y = 8, 4 m wide, 3 m high, floors at z = 0)
with 4 m of rock between them, joined by a cross tunnel at x = 40.
"""

import math

import networkx as nx
import numpy as np
import pytest

from delve.sim.artifact_sensors import (ArtifactSensors, ArtifactSensorSpec, CameraDetection,
                                        SignalReading, SpecError)
from delve.sim.artifacts import listed_artifacts
from delve.sim.payload import PanTiltZoomCamera
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_tunnel, free_space_mesh

V = 0.25
DT = 0.1


@pytest.fixture(scope="module")
def world():
    canvas = VoxelCanvas(np.array([-2.0, -2.0, 0.0]), np.array([42.0, 10.0, 3.0]), V)
    for y in (0.0, 8.0):
        carve_tunnel(canvas, [0.0, y, 0.0], [42.0, y, 0.0], 4.0, 3.0)
    carve_tunnel(canvas, [40.0, -1.0, 0.0], [40.0, 9.0, 0.0], 4.0, 3.0)
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="twin", voxel_size_m=V, origin=canvas.origin, free=canvas.free, mesh=mesh,
                 centreline=nx.Graph(), start=[1.0, 0.0, 0.01])


def _pose(x, y, yaw=0.0, z=0.5):
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, z], [0, 0, 0, 1.0]])


def _sensors(world, items, seed=0, **spec):
    return ArtifactSensors(world, listed_artifacts(world, items), ArtifactSensorSpec(**spec),
                           np.random.default_rng(seed))


def _frames(sensors, pose, n, payload=None, period=1 / 3):
    """All readings of n frames, one call per camera period."""
    out = []
    for k in range(n):
        out += sensors.sense(k * period + 1e-6, pose, payload)
    return out


def _cams(readings, camera=None):
    return [r for r in readings if isinstance(r, CameraDetection) and camera in (None, r.camera)]


def test_seen_in_view_and_range_with_line_of_sight(world):
    s = _sensors(world, [{"class": "backpack", "position": [13.0, 0.0, 0.25]}],
                 false_positive_rate_per_frame=0.0)
    dets = _cams(_frames(s, _pose(10.0, 0.0), 60))
    assert dets and {d.camera for d in dets} == {"front"} and {d.artifact_class for d in dets} <= set(
        s.spec.visual_classes)
    assert all(d.rays.shape == (16, 3) and np.allclose(np.linalg.norm(d.rays, axis=1), 1) for d in dets)


@pytest.mark.parametrize("position, pose, spec", [
    ([11.0, 8.0, 0.25], _pose(10.0, 0.0), {"camera_range_m": 20.0}),    # behind 4 m of rock
    ([7.0, 0.0, 0.25], _pose(10.0, 0.0), {}),                            # behind the robot
    ([16.0, 0.0, 0.25], _pose(10.0, 0.0), {}),                           # 6 m away, range 5 m
])
def test_not_seen(world, position, pose, spec):
    s = _sensors(world, [{"class": "backpack", "position": position}],
                 false_positive_rate_per_frame=0.0, detection_probability=1.0, **spec)
    assert _cams(_frames(s, pose, 100)) == []


def test_probability_falls_with_distance(world):
    counts = []
    for x in (11.5, 13.0, 14.3):
        s = _sensors(world, [{"class": "backpack", "position": [x, 0.0, 0.25]}], seed=1,
                     false_positive_rate_per_frame=0.0)
        counts.append(len(_cams(_frames(s, _pose(10.0, 0.0), 400))))
    assert counts[0] > counts[1] > counts[2] > 0, counts


def test_camera_rate_is_3_hz(world):
    s = _sensors(world, [{"class": "backpack", "position": [10.8, 0.0, 0.1]}],
                 false_positive_rate_per_frame=0.0, detection_probability=1.0, grazing_factor=1.0)
    readings = []
    for k in range(100):                                  # 10 s at dt 0.1 s
        readings += s.sense(k * DT, _pose(10.0, 0.0))
    frames = {d.t_s for d in _cams(readings, "front")}
    assert 28 <= len(frames) <= 30


def test_false_positive_rate(world):
    s = _sensors(world, [], seed=2, false_positive_rate_per_frame=0.2, camera_range_m=60.0)
    dets = _cams(_frames(s, _pose(10.0, 0.0), 500))        # 4 cameras x 500 frames
    assert 340 <= len(dets) <= 460
    assert len({d.artifact_class for d in dets}) > 3


def test_ray_hits_median_near_artifact(world):
    items = [{"class": "backpack", "position": [12.5, 0.5, 0.25]},
             {"class": "vent", "position": [12.0, -1.6, 1.2], "surface": "wall"},
             {"class": "survivor", "position": [11.0, 1.2, 0.6]}]
    s = _sensors(world, items, seed=3, false_positive_rate_per_frame=0.0)
    arts = s.artifacts
    dets = _cams(_frames(s, _pose(9.5, 0.0), 60))
    for a in arts:
        near = []
        for d in dets:
            hit = world.cast_rays(np.broadcast_to(d.origin, d.rays.shape), d.rays, 30.0)
            ok = np.isfinite(hit)
            if ok.sum() < 8:
                continue
            med = np.median(d.origin + hit[ok, None] * d.rays[ok], axis=0)
            near.append(np.linalg.norm(med - a.position))
        assert min(near) <= 1.0, a.name


def test_zoom_sees_farther_than_body_cameras(world):
    item = [{"class": "helmet", "position": [40.0, 0.0, 0.15]}]
    payload = PanTiltZoomCamera(world)
    payload.point_at(0.0, 0.0, zoom=10.0)
    body = _sensors(world, item, false_positive_rate_per_frame=0.0)
    zoom = _sensors(world, item, false_positive_rate_per_frame=0.0)
    assert _cams(_frames(body, _pose(10.0, 0.0), 100)) == []
    dets = _cams(_frames(zoom, _pose(10.0, 0.0), 100, payload))
    assert dets and {d.camera for d in dets} == {"zoom"}
    assert zoom.zoom_range_m(10.0) == pytest.approx(50.0)


def test_thermal_sees_survivor_and_vent_only(world):
    items = [{"class": "survivor", "position": [17.0, 0.5, 0.6]},
             {"class": "backpack", "position": [17.0, -0.5, 0.25]}]
    payload = PanTiltZoomCamera(world)                    # zoom 1: the zoom camera sees 5 m
    s = _sensors(world, items, false_positive_rate_per_frame=0.0, misclassification_probability=0.0)
    dets = _cams(_frames(s, _pose(10.0, 0.0), 100, payload))
    assert dets and {(d.camera, d.artifact_class) for d in dets} == {("thermal", "survivor")}


def test_payload_cameras_only_when_asked(world):
    s = _sensors(world, [{"class": "survivor", "position": [17.0, 0.0, 0.6]}])
    assert not [d for d in _cams(_frames(s, _pose(10.0, 0.0), 50)) if d.camera in ("zoom", "thermal")]


def test_bluetooth_weaker_through_rock(world):
    s = _sensors(world, [{"class": "cell_phone", "position": [20.0, 8.0, 0.1]}])
    air = s.bluetooth_dbm(np.array([12.0, 8.0, 0.5]), [0])[0]
    rock = s.bluetooth_dbm(np.array([20.0, 0.0, 0.5]), [0])[0]
    assert s.rock_length_m(np.array([20.0, 0.0, 0.5]), s.artifacts[0].position)[0] == pytest.approx(4.0, abs=0.6)
    assert rock < air - 40.0
    readings = [r for r in _frames(s, _pose(12.0, 8.0), 30, period=1.0) if isinstance(r, SignalReading)]
    assert len(readings) == 30 and {r.identifier for r in readings} == {"cell_phone_1"}
    assert np.mean([r.value for r in readings]) == pytest.approx(air, abs=2.0)
    through = _frames(s, _pose(20.0, 0.0), 30, period=1.0)
    assert through == []                                  # below the receiver's sensitivity


def test_co2_high_in_room_and_ambient_far_or_through_rock(world):
    s = _sensors(world, [{"class": "gas", "position": [5.0, 8.0, 1.0]}])
    amb, room = s.spec.co2_ambient_ppm, s.spec.co2_room_ppm
    assert s.co2_ppm(np.array([5.5, 8.0, 0.5]), noise=False) == pytest.approx(room)
    assert amb < s.co2_ppm(np.array([14.0, 8.0, 0.5]), noise=False) < s.co2_ppm(
        np.array([10.0, 8.0, 0.5]), noise=False) < room
    assert s.co2_ppm(np.array([35.0, 8.0, 0.5]), noise=False) == pytest.approx(amb, abs=20.0)
    assert s.co2_ppm(np.array([5.0, 0.0, 0.5]), noise=False) == pytest.approx(amb, abs=1.0)
    readings = [r for r in _frames(s, _pose(5.0, 8.0), 10, period=2.0) if isinstance(r, SignalReading)]
    assert [r.kind for r in readings] == ["co2"] * 10
    assert np.mean([r.value for r in readings]) == pytest.approx(room, abs=50.0)


def test_deterministic_for_a_seed(world):
    items = [{"class": "backpack", "position": [13.0, 0.0, 0.25]},
             {"class": "cube", "position": [20.0, 0.0, 0.1]}]
    runs = []
    for _ in range(2):
        s = _sensors(world, items, seed=7, false_positive_rate_per_frame=0.1)
        out = []
        for k in range(50):
            out += s.sense(k * DT, _pose(10.0 + 0.05 * k, 0.0))
        runs.append(out)
    assert len(runs[0]) == len(runs[1]) > 0
    for a, b in zip(*runs):
        assert type(a) is type(b) and a.t_s == b.t_s
        if isinstance(a, CameraDetection):
            np.testing.assert_array_equal(a.rays, b.rays)
        else:
            assert a.value == b.value


@pytest.mark.parametrize("kw, field", [({"camera_range_m": -1.0}, "camera_range_m"),
                                       ({"detection_probability": 1.5}, "detection_probability"),
                                       ({"false_positive_rate_per_frame": -0.1},
                                        "false_positive_rate_per_frame"),
                                       ({"thermal_range_m": 0.0}, "thermal_range_m"),
                                       ({"camera_pitch_deg": (0.0,)}, "camera_pitch_deg")])
def test_bad_spec_names_the_field(kw, field):
    with pytest.raises(SpecError, match=f"^{field}: ") as err:
        ArtifactSensorSpec(**kw)
    assert err.value.field == field
