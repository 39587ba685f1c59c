"""CSIRO 3D frontiers in a small mine (tests/scenarios/data/csiro_small.yaml): explore-sync brings
the map and artifact reports back into radio range and the robot goes back to its region; the
same seed gives the same report."""
from __future__ import annotations

import json

import numpy as np
import pytest
from delve.executive.outputs import strip_wall_clock

from .conftest import DATA, run_scenario

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("csiro")
    return run_scenario(DATA / "csiro_small.yaml", out / "a")


def of(events, kind, agent="ugv"):
    return [e for e in events if e["event"] == kind and e.get("agent") == agent]


def test_explore_sync_uplinks_and_returns_to_the_region(small_run):
    mission, report = small_run
    events = mission.state.events
    due, back, sync, region = (of(events, k) for k in ("csiro_sync_due", "csiro_back_in_range", "csiro_sync",
                                                      "csiro_region_reached"))
    assert due and back and sync and region, [e["event"] for e in events if e["event"].startswith("csiro_s")]
    first = due[0]
    assert first["out_of_contact_s"] >= 30.0
    # driven back into range, then the uplink drained the outbox ...
    assert back[0]["t"] > first["t"] and sync[0]["t"] >= back[0]["t"] and sync[0]["pending"] == 0
    # ... and the base station heard the robot again then: its frontiers and map arrived
    uplinks = [e for e in events if e["event"] == "csiro_uplink" and back[0]["t"] <= e["t"] <= sync[0]["t"]]
    assert uplinks and uplinks[0]["robot"] == "ugv"
    # back where the sync began, not at the nearest frontier
    assert region[0]["t"] > sync[0]["t"]
    assert np.linalg.norm(np.subtract(region[0]["position"], first["region"])) <= 3.0
    robot = report["csiro"]["robots"]["ugv"]
    assert robot["syncs"] >= 1 and robot["regions_reached"] >= 1
    assert report["csiro"]["frontiers_at_base"] >= 0 and report["csiro"]["robots_heard_at_base"] == ["ugv"]


def test_the_sync_brings_map_and_artifact_reports_back(small_run):
    mission, _ = small_run
    events, samples = mission.state.events, mission.state.samples
    due, sync = of(events, "csiro_sync_due")[0], of(events, "csiro_sync")[0]
    # what the robot had mapped when it turned back is at the base station after the sync
    turned = max((s for s in samples if s.t <= due["t"]), key=lambda s: s.t)
    synced = min((s for s in samples if s.t >= sync["t"]), key=lambda s: s.t)
    assert turned.base < turned.robots["ugv"] <= synced.base + 1e-9
    # every artifact report made before it turned back reached the base station by the sync
    made = [e for e in of(events, "artifact_reported") if e["t"] <= due["t"]]
    delivered = [e for e in events if e["event"] == "artifact_delivered" and e["t"] <= sync["t"]]
    assert made and len(delivered) >= len(made)


def test_same_seed_same_report(small_run, tmp_path):
    _, a = small_run
    _, b = run_scenario(DATA / "csiro_small.yaml", tmp_path / "b")
    assert json.dumps(strip_wall_clock(a)) == json.dumps(strip_wall_clock(b))
