"""The inspections block of the CERBERUS ANYmal tree (Figure 13) in its scenario: an
inspection request -> pause -> scan -> resume on the same path, and the mission
still ends well (the robot home)."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario

from delve import SCENARIOS_DIR


SCENARIO = SCENARIOS_DIR / "cerberus_inspection.yaml"


def events(mission, name, **match):
    return [e for e in mission.state.events
            if e["event"] == name and all(e.get(k) == v for k, v in match.items())]


@pytest.fixture(scope="module")
def mission():
    m = Mission(load_scenario(SCENARIO))

    m.run()
    return m


def test_a_point_request_pauses_scans_and_resumes_the_same_path(mission):
    (command,) = events(mission, "operator_command", command="scan", point=[8.5, 0.3, 3.0])
    (start,) = events(mission, "inspection_start", point=[8.5, 0.3, 3.0])
    assert start["t"] == command["t"]                  # requests put all others on hold at once
    plan = next(e for e in events(mission, "inspection_scan_points") if e["t"] >= start["t"])
    assert plan["full_scan"] and plan["unseen_fraction"] > 0.5 and plan["scan_points"] >= 1
    (pause,) = [e for e in events(mission, "inspection_pause") if e["t"] >= start["t"]]
    assert pause["path"], "the robot was following a path when the request came"
    resume = next(e for e in events(mission, "inspection_resume") if e["t"] >= pause["t"])
    done = next(e for e in events(mission, "inspection_done") if e["t"] >= start["t"])
    # Pause: the robot stands still while the payload scans every scan point.
    scans = [e for e in events(mission, "inspection_scan") if pause["t"] <= e["t"] <= resume["t"]]
    assert len(scans) == plan["scan_points"]
    assert all(not e["moving"] for e in scans)
    assert len({tuple(e["position"]) for e in scans}) == 1
    assert resume["t"] - scans[0]["t"] >= (len(scans) - 1) * 1.0      # the dwell, in sim time
    # Resume: the path re-issued is the path it was following (after a walk back, had
    # it walked to the point first).
    paused = np.asarray(pause["path"])
    resumed = np.asarray(resume["path"])
    assert np.allclose(resumed[len(resumed) - len(paused):], paused)
    if resume["way_back_waypoints"] == 0:
        assert np.allclose(resumed, paused)
    # ... and walked to its end before the block let the others go on.
    trail = mission.robots["anymal"].traversed_path
    assert np.min(np.linalg.norm(trail[:, :2] - paused[-1, :2], axis=1)) <= 0.6
    assert done["full_scan"] and done["covered_fraction"] >= 0.9
    assert done["t"] >= resume["t"]


def test_an_area_request_mostly_seen_is_scanned_without_a_pause(mission):
    """The body cameras saw most of the area on the way: the payload scans its points
    while the robot walks on (no pause), and the request is cleared."""
    (start,) = events(mission, "inspection_start", point=None)
    plan = next(e for e in events(mission, "inspection_scan_points") if e["t"] >= start["t"])
    done = next(e for e in events(mission, "inspection_done") if e["t"] >= start["t"])
    assert not plan["full_scan"] and plan["unseen_fraction"] <= 0.5
    assert not [e for e in events(mission, "inspection_pause") if start["t"] <= e["t"] <= done["t"]]
    assert not done["full_scan"] and 0.0 <= done["covered_fraction"] <= 1.0
    assert not events(mission, "inspection_failed")
    key = mission.agents["anymal"].ctx.namespace + "/inspection_request"
    assert py_trees.blackboard.Blackboard.storage.get(key) is None


def test_the_mission_still_ends_well(mission):
    assert mission.succeeded
    robot = mission.robots["anymal"]
    assert np.linalg.norm(robot.position - robot.home) <= 1.5
    assert robot.endurance_remaining_s > 0
    assert events(mission, "homing")
