"""Artifacts end to end on a small tunnel network (tests/scenarios/data/artifacts_small.yaml):
a robot detects artifacts at known places, most of them out of radio range; its
reports wait on board, reach the base station when it comes back, are submitted and
score. Slow (see conftest.py)."""
import json

import pytest

from delve.executive.cli import main

from .conftest import DATA, run_scenario


@pytest.fixture(scope="module")
def artifacts_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("artifacts")
    mission, report = run_scenario(DATA / "artifacts_small.yaml", out)
    return mission, report, out


def linked_at(mission, t: float) -> bool:
    """Whether the robot had a link to the base station at the coverage sample before ``t``."""
    return [s.linked["anymal"] for s in mission.state.samples if s.t <= t][-1]


def test_a_report_made_out_of_range_is_delivered_when_the_robot_is_back_and_scores(artifacts_run):
    mission, report, _ = artifacts_run
    made = {e["artifact_class"]: e for e in mission.state.events if e["event"] == "artifact_reported"}
    delivered = {e["artifact_class"]: e for e in mission.state.events if e["event"] == "artifact_delivered"}
    scored = {e["artifact"] for e in mission.state.events if e["event"] == "artifact_scored"}
    far = made["backpack"]
    assert not linked_at(mission, far["t"])  # 44 m out, the radio reaches 15 m
    assert delivered["backpack"]["t"] > far["t"] + 30 and delivered["backpack"]["made_s"] == pytest.approx(far["t"], abs=0.2)
    assert {"backpack_1", "helmet_1", "drill_1"} <= scored


def test_the_report_counts_what_happened(artifacts_run):
    mission, report, out = artifacts_run
    art = report["artifacts"]
    assert art["total"] == 4 and art["undelivered"] == 0
    assert art["scored"] >= 3 and art["scored"] == len(art["points"])
    assert art["submitted"] == art["scored"] + art["false_reports"]
    assert art["reports_left"] == 45 - art["submitted"]
    assert art["robots"]["anymal"]["reports_delivered"] == art["reported_to_base"] == art["robots"]["anymal"]["reports_made"]
    assert all(p["error_m"] < 5.0 and p["robots"] == ["anymal"] for p in art["points"])
    assert set(art["missed"]) == {"drill_1", "backpack_1", "helmet_1", "cube_1"} - {p["artifact"] for p in art["points"]}
    assert json.loads((out / "report.json").read_text())["artifacts"] == art
    assert (out / "scored.png").stat().st_size > 0 and (out / "map.png").stat().st_size > 0


def test_a_lost_robots_reports_count_as_undelivered(tmp_path):
    text = (DATA / "artifacts_small.yaml").read_text().replace("duration_s: 900", "duration_s: 400")
    path = tmp_path / "lost.yaml"
    path.write_text(text.replace("../../../trees", str(DATA.parent.parent.parent / "trees"))
                    + "faults:\n  - {at_s: 300, kind: lost, robot: anymal}\n")
    mission, report = run_scenario(path, tmp_path / "out")
    art = report["artifacts"]
    made = [e for e in mission.state.events if e["event"] == "artifact_reported"]
    assert art["undelivered"] >= 1 and art["undelivered"] + art["reported_to_base"] == len(made)
    assert art["robots"]["anymal"]["reports_undelivered"] == art["undelivered"]


def test_placing_more_artifacts_than_the_world_holds_is_one_line(tmp_path, capsys):
    path = tmp_path / "many.yaml"
    path.write_text((DATA / "artifacts_small.yaml").read_text()
                    .replace("../../../trees", str(DATA.parent.parent.parent / "trees"))
                    .replace("  items:\n", "  count: 400\n  items:\n"))
    assert main(["run", str(path), "--quiet", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(f"{path}:15: artifacts: ") and "400" in err, err
