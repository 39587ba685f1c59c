"""Scenario files: the shipped ones validate; each malformed one gives its one-line error."""
from pathlib import Path

import pytest

from delve import SCENARIOS_DIR
from delve.executive.cli import main
from delve.executive.errors import DelveError
from delve.executive.scenario import load_scenario

CORPUS = Path(__file__).parent.parent / "data" / "malformed_scenarios"
CASES = sorted(p for p in CORPUS.glob("*.yaml") if p.read_text().startswith("# expect:"))


def header(path: Path, key: str) -> str | None:
    for line in path.read_text().splitlines():
        if line.startswith(f"# {key}:"):
            return line.split(":", 1)[1].strip()
    return None


@pytest.mark.parametrize("case", CASES, ids=[c.stem for c in CASES])
def test_malformed_scenario_gives_one_line_with_file_and_line(case, capsys):
    assert main(["validate", str(case)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    where = CORPUS / (header(case, "file") or case.name)
    assert err.startswith(f"{where}:{header(case, 'line')}:") or err.startswith(
        f"{where.relative_to(Path.cwd()) if where.is_relative_to(Path.cwd()) else where}:{header(case, 'line')}:"
    ), err
    assert header(case, "expect") in err


def test_corpus_is_large_enough():
    assert len(CASES) >= 12


@pytest.mark.parametrize("path", sorted(SCENARIOS_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_scenarios_load(path):
    scenario = load_scenario(path)
    assert scenario.robots and scenario.duration_s > 0


def test_run_rejects_bad_overrides(capsys):
    assert main(["run", str(SCENARIOS_DIR / "demo.yaml"), "--duration-s", "-1", "--quiet"]) == 2
    assert "--duration-s must be a finite number of seconds > 0" in capsys.readouterr().err


@pytest.mark.parametrize("value, expect", [("inf", "must be a finite number of seconds > 0, got inf"),
                                           ("nan", "must be a finite number of seconds > 0, got nan"),
                                           ("1e9", "steps, more than the limit of 2,000,000")])
def test_run_refuses_an_endless_duration_before_building_the_world(value, expect, capsys):
    assert main(["run", str(SCENARIOS_DIR / "demo.yaml"), "--duration-s", value, "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err and expect in err, err


def test_load_errors_are_delve_errors(tmp_path):
    bad = tmp_path / "x.yaml"
    bad.write_text("- just\n- a list\n")
    with pytest.raises(DelveError, match="must be a mapping"):
        load_scenario(bad)


LATE = """name: late
duration_s: 100
world:
  generator: tunnel_network
  total_length_m: 120
  loops: 1
robots:
  - name: anymal
    platform: legged
    tree: {tree}
supervisor:
  - at_s: 50
    robot: anymal
    command: home
  - at_s: 500
    robot: anymal
    command: home
faults:
  - at_s: 200
    duration_s: 10
    kind: lidar_dropout
    robot: anymal
"""


def late_scenario(tmp_path):
    from delve import TREES_DIR

    path = tmp_path / "late.yaml"
    path.write_text(LATE.format(tree=TREES_DIR / "frontier_explorer.yaml"))
    return path


def test_commands_and_faults_after_the_end_warn_with_file_and_line(tmp_path):
    from delve.executive.errors import DelveWarning

    with pytest.warns(DelveWarning) as caught:
        load_scenario(late_scenario(tmp_path))
    messages = [str(w.message) for w in caught if w.category is DelveWarning]
    assert len(messages) == 2
    assert messages[0].endswith("late.yaml:15: supervisor command 'home' at_s 500 comes after the end of the run "
                                "(duration_s 100 s): it never happens")
    assert "late.yaml:19: fault 'lidar_dropout' at_s 200 comes after the end" in messages[1]


def test_cli_prints_late_events_as_one_line_warnings(tmp_path, monkeypatch, capsys):
    from delve.executive.scenario import Scenario

    def stop(*args, **kwargs):
        raise DelveError("stopped before the world")

    monkeypatch.setattr(Scenario, "build_world", stop)
    assert main(["run", str(late_scenario(tmp_path)), "--duration-s", "40", "--quiet", "--out",
                 str(tmp_path / "out")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert [line.split(": ", 1)[0] for line in lines[:3]] == ["warning"] * 3
    assert "at_s 50 comes after the end of the run (--duration-s 40 s)" in lines[2]
    assert lines[3] == "stopped before the world" and len(lines) == 4


def test_a_scenario_tree_resolves_only_in_its_folder_the_shipped_trees_or_include_path(tmp_path):
    (tmp_path / "mission").mkdir()
    (tmp_path / "mytrees").mkdir()
    (tmp_path / "mytrees" / "explorer.yaml").write_text("type: Sequence\nchildren:\n  - type: Success\n")
    path = tmp_path / "mission" / "s.yaml"
    path.write_text("name: s\nworld: {generator: tunnel_network, total_length_m: 120, loops: 1}\n"
                    "robots:\n  - name: anymal\n    platform: legged\n    tree: ../mytrees/explorer.yaml\n")
    with pytest.raises(DelveError, match=r"s.yaml:6: robot 'anymal': tree '../mytrees/explorer.yaml' is outside "
                                         r"the allowed folders .*add --include-path"):
        load_scenario(path)
    scenario = load_scenario(path, include_path=[tmp_path / "mytrees"])
    assert scenario.robots[0].tree == (tmp_path / "mytrees" / "explorer.yaml").resolve()
    (tmp_path / "mission" / "link.yaml").symlink_to(tmp_path / "mytrees" / "explorer.yaml")
    path.write_text(path.read_text().replace("../mytrees/explorer.yaml", "link.yaml"))
    with pytest.raises(DelveError, match="is outside the allowed folders"):
        load_scenario(path)


def test_a_robot_deployed_later_ticks_from_then(tmp_path):
    from delve import TREES_DIR
    from delve.executive.runner import Mission

    path = tmp_path / "deploy.yaml"
    path.write_text(f"""name: deploy
world: {{generator: tunnel_network, total_length_m: 60, loops: 0}}
robots:
  - {{name: first, platform: legged, tree: {TREES_DIR / 'frontier_explorer.yaml'}}}
  - {{name: later, platform: legged, tree: {TREES_DIR / 'frontier_explorer.yaml'}, deploy_at_s: 30}}
""")
    mission = Mission(load_scenario(path), duration_s=20.0)
    assert mission.agents["later"].next_tick_s == 30.0 and mission.agents["first"].next_tick_s == 0.0
    mission.run()
    assert mission.robots["later"].distance_m == 0.0 < mission.robots["first"].distance_m
