"""The default mission: a legged robot explores the demo tunnel network and comes home."""
import json

import pytest

from delve import SCENARIOS_DIR
from delve.executive.outputs import WALL_CLOCK_FIELDS, strip_wall_clock

from .conftest import run_scenario


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    mission, report = run_scenario(SCENARIOS_DIR / "demo.yaml", out)
    return mission, report, out


def test_demo_explores_at_least_90_percent_and_comes_home_in_time(demo):
    mission, report, _ = demo
    assert report["succeeded"]
    assert report["coverage_fraction"] >= 0.90
    (robot,) = report["robots"]
    assert robot["returned_home"] and robot["final_status"] == "SUCCESS"
    assert robot["endurance_left_s"] > 0
    assert mission.robots["anymal"].alive


def test_demo_world_is_a_300_to_500_m_branching_tunnel(demo):
    mission, _, _ = demo
    g = mission.world.centreline
    length = sum(d["length_m"] for _, _, d in g.edges(data=True))
    assert 300 <= length <= 500
    assert any(deg >= 3 for _, deg in g.degree())  # branches
    assert any(deg == 1 for _, deg in g.degree())  # dead ends


def test_the_base_station_receives_the_whole_map(demo):
    _, report, _ = demo
    assert report["base_coverage_fraction"] == pytest.approx(report["coverage_fraction"], abs=1e-9)
    assert report["robots"][0]["messages_undelivered"] == 0


def test_demo_writes_every_output(demo):
    _, report, out = demo
    for name in ("report.json", "log.jsonl", "map.png", "coverage.png", "tree_anymal.txt", "tree_anymal.svg",
                 "tree_base.txt", "tree_base.svg"):
        assert (out / name).stat().st_size > 0, name
    saved = json.loads((out / "report.json").read_text())
    for key in ("scenario", "seed", "sim_time_s", "wall_time_s", "coverage_fraction", "base_coverage_fraction"):
        assert key in saved
    assert {"wall_time_s", "real_time_factor"} <= set(saved) and set(saved) - set(strip_wall_clock(saved)) <= set(WALL_CLOCK_FIELDS)
    events = [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines()]
    kinds = {e["event"] for e in events}
    assert {"mission_start", "status", "frontier_goal", "exploration_complete", "home_reached"} <= kinds or \
        {"mission_start", "status", "frontier_goal", "endurance_low", "home_reached"} <= kinds
    dump = (out / "tree_anymal.txt").read_text()
    assert "Explore nearest frontier" in dump and "Return home" in dump
    assert (out / "tree_anymal.svg").read_text().lstrip().startswith("<?xml")
