"""delve.planners.artifacts.signal_fusion: Bluetooth clustered by SSID, CO2 by
distance, centres from the strongest readings, one report per cluster."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.artifacts.params import SignalFusionParams, SignalParams
from delve.planners.artifacts.signal_fusion import SignalClusterer, ssid_class

PHONE = np.array([20.0, 3.0, 1.0])


def _rssi(at: np.ndarray, source: np.ndarray) -> float:
    """Log-distance path loss: -59 dBm at 1 m, exponent 2.5."""
    return -59.0 - 25.0 * np.log10(max(np.linalg.norm(at - source), 1.0))


def _walk(x0: float, x1: float, n: int) -> np.ndarray:
    """Sensor positions along a corridor at y = 0, z = 1."""
    return np.stack([np.linspace(x0, x1, n), np.zeros(n), np.ones(n)], axis=1)


def test_ssid_names_give_the_class():
    classes = ("cell_phone", "cube")
    assert ssid_class("cell_phone_2", classes) == "cell_phone"
    assert ssid_class("cube_12", classes) == "cube"
    assert ssid_class("cube", classes) == "cube"
    assert ssid_class("anymal_1_wifi", classes) is None
    assert ssid_class("backpack_1", classes) is None


def test_bluetooth_clusters_per_ssid_and_reports_near_the_strongest_readings():
    s = SignalClusterer(robot="anymal_4")
    reports = []
    for i, p in enumerate(_walk(0.0, 40.0, 81)):                  # passes 3 m from the phone
        reports += s.add(i * 0.5, "bluetooth", "cell_phone_1", p, _rssi(p, PHONE))
        reports += s.add(i * 0.5, "bluetooth", "cube_1", p, _rssi(p, PHONE + [6.0, 0.0, 0.0]))
    assert [(r.artifact_class, r.source, r.robot) for r in reports] == \
        [("cell_phone", "bluetooth", "anymal_4"), ("cube", "bluetooth", "anymal_4")]
    assert len(s.clusters) == 2
    phone = s.clusters[0]
    centre = phone.centre(SignalFusionParams().bluetooth.top_k)
    assert np.linalg.norm(centre[:2] - [PHONE[0], 0.0]) < 1.0      # beside the phone, on the robot's path
    assert 0.0 < reports[0].probability <= 1.0


def test_no_report_before_enough_readings_above_threshold():
    bluetooth = SignalParams(raw_min=-100.0, raw_max=-40.0, threshold=-72.0, min_readings=5, after_peak_readings=0)
    s = SignalClusterer(SignalFusionParams(bluetooth=bluetooth))
    near = PHONE + [1.0, 0.0, 0.0]
    for i in range(20):                                            # below -72 dBm: no cluster
        assert s.add(float(i), "bluetooth", "cell_phone_3", near, -85.0) == []
    assert s.clusters == []
    n = bluetooth.min_readings
    for i in range(n - 1):
        assert s.add(float(i), "bluetooth", "cell_phone_3", near, -60.0) == []
    r = s.add(99.0, "bluetooth", "cell_phone_3", near, -60.0)
    assert len(r) == 1 and r[0].detections == n and r[0].t_s == 99.0
    assert s.add(100.0, "bluetooth", "cell_phone_3", near, -50.0) == []        # one report per cluster


def test_a_rising_signal_is_reported_only_after_its_peak():
    s = SignalClusterer()
    after = SignalFusionParams().bluetooth.after_peak_readings
    cube = np.array([20.0, 1.5, 1.0])
    approach = _walk(0.0, 20.0, 21)                                   # up to beside the cube, 1.5 m away
    assert all(s.add(float(i), "bluetooth", "cube_1", p, _rssi(p, cube)) == [] for i, p in enumerate(approach))
    leave = _walk(21.0, 30.0, 10)                                     # weaker readings, soon below threshold
    reports = [(i, r) for i, p in enumerate(leave)
               for r in s.add(30.0 + i, "bluetooth", "cube_1", p, _rssi(p, cube))]
    assert [i for i, _ in reports] == [after - 1]                     # the eighth reading past the peak
    assert np.linalg.norm(reports[0][1].position - [20.0, 0.0, 1.0]) < 1.0


def test_unknown_ssids_are_ignored_and_a_mapping_can_name_them():
    assert all(SignalClusterer().add(float(i), "bluetooth", "robot_wifi", PHONE, -50.0) == [] for i in range(10))
    s = SignalClusterer(classify=lambda ssid: "cube" if ssid.startswith("SubTCube") else None)
    reports = [r for i in range(10) for r in s.add(float(i), "bluetooth", "SubTCube-A1", PHONE, -50.0)]
    assert [r.artifact_class for r in reports] == ["cube"]


def test_co2_clusters_by_distance():
    s = SignalClusterer()
    reports = []
    rooms = [np.array([0.0, 0.0, 1.0]), np.array([30.0, 0.0, 1.0])]
    for i in range(12):
        for room in rooms:
            reports += s.add(float(i), "co2", None, room + [0.2 * i, 0.0, 0.0], 3000.0 - 10.0 * abs(i - 5))
    assert len(s.clusters) == 2
    assert [r.artifact_class for r in reports] == ["gas", "gas"]
    for room, r in zip(rooms, reports):
        assert np.linalg.norm(r.position - room) < 2.5 and r.source == "co2"
    assert s.add(0.0, "co2", None, np.array([15.0, 0.0, 1.0]), 1500.0) == [] and len(s.clusters) == 2


def test_the_centre_leans_to_the_strongest_readings():
    s = SignalClusterer()
    for x, ppm in [(0.0, 2100.0), (2.0, 2100.0), (4.0, 2100.0), (6.0, 4800.0), (8.0, 4900.0), (9.0, 5000.0),
                   (7.0, 4950.0), (5.0, 2100.0)]:
        s.add(0.0, "co2", None, np.array([x, 0.0, 0.0]), ppm)
    assert len(s.clusters) == 1
    assert s.clusters[0].centre(3)[0] == pytest.approx(np.average([9.0, 7.0, 8.0], weights=[1.0, 0.989, 0.978]),
                                                         abs=0.01)


def test_bad_readings_are_errors():
    with pytest.raises(ValueError, match="unknown signal kind"):
        SignalClusterer().add(0.0, "wifi", "x", PHONE, -50.0)
    with pytest.raises(ValueError, match="identifier"):
        SignalClusterer().add(0.0, "bluetooth", None, PHONE, -50.0)
