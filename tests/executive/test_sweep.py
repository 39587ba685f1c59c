"""Sweep files (executive/sweep_spec.py), a run's marker (sweep_run.py) and the results
table and plots (sweep_table.py), without running a mission; the sweeps that run
missions on a LocalCluster are in tests/scenarios/test_sweep.py."""
import json
from pathlib import Path

import matplotlib.figure
import pandas as pd
import pytest

from delve import TREES_DIR
from delve.executive.cli import main
from delve.executive.errors import DelveError
from delve.executive.sweep_run import MARKER, finished_record, one_line
from delve.executive.sweep_spec import Override, apply_overrides, load_sweep
from delve.executive.sweep_table import figure_columns, flatten, plot_figures, results_table, write_table
from delve.executive.yamlio import loads_yaml

SMALL = Path(__file__).parent.parent / "scenarios" / "data" / "small_tunnel.yaml"


def sweep_file(tmp_path: Path, text: str) -> Path:
    """A sweep file in ``tmp_path`` where SMALL names a copy of small_tunnel.yaml beside it
    (a sweep's scenarios lie in its folder or the shipped scenarios)."""
    small = tmp_path / SMALL.name
    small.write_text(SMALL.read_text().replace("../../../trees", str(TREES_DIR)))
    path = tmp_path / "s.yaml"
    path.write_text(text.replace("SMALL", str(small)).replace("../../../trees", str(TREES_DIR)))
    return path


def cli_error(path: Path, capsys) -> str:
    """Run ``delve sweep`` on a wrong file: exit 2, one line, no traceback; the line."""
    assert main(["sweep", str(path), "--out", str(path.parent / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    assert not (path.parent / "out").exists(), "nothing runs before the sweep is checked"
    return err


def test_grid_times_runs_times_seeds_in_file_order(tmp_path):
    path = sweep_file(tmp_path, """
scenarios: [SMALL]
seeds: {count: 2, first: 5}
grid:
  radio.range_m: [30, 60]
runs:
  - {}
  - {label: short, set: {duration_s: 100, world.loops: 0}}
""")
    sweep = load_sweep(path)
    assert [r.run_id for r in sweep.runs] == [
        "small_tunnel-radio.range_m=30-s5", "small_tunnel-radio.range_m=30-s6",
        "small_tunnel-radio.range_m=60-s5", "small_tunnel-radio.range_m=60-s6",
        "small_tunnel-short-radio.range_m=30-s5", "small_tunnel-short-radio.range_m=30-s6",
        "small_tunnel-short-radio.range_m=60-s5", "small_tunnel-short-radio.range_m=60-s6"]
    assert sweep.override_paths == ("radio.range_m", "duration_s", "world.loops")
    assert sweep.name == "s"
    assert load_sweep(path).runs == sweep.runs, "ids and digests are stable"
    assert len({r.digest for r in sweep.runs}) == 8


def test_without_seeds_each_scenario_keeps_its_own(tmp_path):
    sweep = load_sweep(sweep_file(tmp_path, "scenarios: [SMALL]\ngrid: {world.total_length_m: [100, 140]}\n"))
    assert [(r.run_id, r.seed) for r in sweep.runs] == [("small_tunnel-world.total_length_m=100-s4", 4),
                                                         ("small_tunnel-world.total_length_m=140-s4", 4)]


def test_a_path_value_shows_its_file_name_and_a_list_a_digest(tmp_path):
    sweep = load_sweep(sweep_file(tmp_path, """
scenarios: [SMALL]
grid:
  robots.0.tree: [../../../trees/gbplanner_explorer.yaml]
  robots.0.start: [[0, 0, 0]]
"""))
    (run,) = sweep.runs
    assert run.run_id.startswith("small_tunnel-robots.0.tree=gbplanner_explorer.yaml-robots.0.start=h")


def test_a_shipped_scenario_by_its_name(tmp_path):
    sweep = load_sweep(sweep_file(tmp_path, "scenarios: [demo]\nruns:\n  - {}\n  - {scenario: cops_mine, set: {}}\n"))
    assert [run.scenario_file.name for run in sweep.runs] == ["demo.yaml", "cops_mine.yaml"]


def test_overrides_make_missing_mappings_and_index_lists():
    doc = loads_yaml("name: x\nrobots:\n  - {name: a}\n")
    out = apply_overrides(doc, (Override("radio.range_m", 40, 3), Override("robots.0.name", "b", 4)))
    assert out["radio"] == {"range_m": 40} and out["robots"][0]["name"] == "b"
    assert "radio" not in doc, "the scenario's own document is left alone"
    with pytest.raises(DelveError, match="is a list of 1") as err:
        apply_overrides(doc, (Override("robots.3.name", "b", 7),))
    assert err.value.line == 7


@pytest.mark.parametrize("text, line, expect", [
    ("scenarios: [SMALL]\ngird: {}\n", 2, "sweep: unknown key 'gird' (did you mean 'grid'?)"),
    ("scenarios: [nope.yaml]\n", 1, "scenarios: scenario file not found: nope.yaml"),
    ("scenarios: [SMALL, sub]\n", 1, "scenarios: scenario file is a directory: sub"),
    ("scenarios: [/etc]\n", 1, "scenario '/etc' is outside the allowed folders"),
    ("scenarios: [SMALL]\nruns:\n  - set: {world: {mesh: ../elsewhere.yaml}}\n", 1,
     "world.mesh '../elsewhere.yaml' is outside the allowed folders (the sweep's folder "),
    ("scenarios: [../elsewhere.yaml]\n", 1, "scenario '../elsewhere.yaml' is outside the allowed folders"),
    ("runs:\n  - {scenario: ../elsewhere.yaml, set: {}}\n", 2, "scenario '../elsewhere.yaml' is outside the "),
    ("scenarios: [SMALL]\nseeds: [1, -2]\n", 2, "seeds/1: a seed is an integer from 0 to 9223372036854775807, not -2"),
    ("scenarios: [SMALL]\nseeds: [99999999999999999999]\n", 2, "seeds/0: a seed is an integer from 0 to "),
    ("scenarios: [SMALL]\nseeds: {count: 0}\n", 2, "seeds: count must be an integer from 1 to 10000, not 0"),
    ("scenarios: [SMALL]\nseeds: {count: 9000}\ngrid: {duration_s: [1, 2]}\n", 1,
     "sweep: 18,000 runs, more than the limit of 10,000"),
    ("scenarios: [SMALL]\ngrid:\n  duration_s: 100\n", 3, "grid: 'duration_s': a non-empty list of values"),
    ("scenarios: [SMALL]\ngrid:\n  wrold.total_length_m: [100]\n", 3,
     "wrold.total_length_m: 100 does not fit scenario 'small_tunnel.yaml': "),
    ("scenarios: [SMALL]\ngrid:\n  duration_s: [100, -5]\n", 3, "duration_s: -5 does not fit scenario"),
    ("scenarios: [SMALL]\nruns:\n  - set: {robots.2.tree: x.yaml}\n", 3, "robots.2.tree: robots is a list of 1"),
    ("scenarios: [SMALL]\nseeds: [1]\ngrid:\n  seed: [3]\n", 4, "seed: give the seeds with 'seeds:'"),
    ("scenarios: [SMALL]\nruns:\n  - {set: {}}\n  - {set: {}}\n", 1, "two runs get the same id"),
    ("runs:\n  - {label: x}\n", 2, "runs/0: no scenario"),
    ("- a\n", 1, "a sweep file must be a mapping"),
])
def test_a_mistake_is_one_line_at_its_key(tmp_path, capsys, text, line, expect):
    (tmp_path / "elsewhere.yaml").write_text("secret: 1\n")   # readable, but not the sweep's to read
    (tmp_path / "sweep" / "sub").mkdir(parents=True)
    path = sweep_file(tmp_path / "sweep", text)
    err = cli_error(path, capsys)
    assert err.startswith(f"{path}:{line}: ") or err.startswith(f"{path.name}:{line}: "), err
    assert expect in err, err


def test_an_override_the_scenario_refuses_names_both_files(tmp_path, capsys):
    path = sweep_file(tmp_path, "scenarios: [SMALL]\ngrid:\n  world.total_lenght_m: [100]\n")
    err = cli_error(path, capsys)
    assert ":3: world.total_lenght_m: 100 does not fit scenario 'small_tunnel.yaml': " in err
    assert "small_tunnel.yaml:" in err and "did you mean 'total_length_m'" in err, err


def test_workers_and_scheduler_are_checked(tmp_path, capsys):
    path = sweep_file(tmp_path, "scenarios: [SMALL]\n")
    assert main(["sweep", str(path), "--workers", "0"]) == 2
    assert "--workers must be >= 1" in capsys.readouterr().err
    assert main(["sweep", str(path), "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "leave it out with --scheduler" in capsys.readouterr().err


def test_a_marker_counts_only_for_the_same_run_with_its_outputs(tmp_path):
    sweep = load_sweep(sweep_file(tmp_path, "scenarios: [SMALL]\nseeds: [1, 2]\n"))
    a, b = sweep.runs
    folder = tmp_path / "run"
    folder.mkdir()
    record = {"run_id": a.run_id, "digest": a.digest, "status": "ok", "error": "", "wall_time_s": 1.0}
    (folder / MARKER).write_text(json.dumps(record))
    assert finished_record(a, folder) is None, "an ok run without its report is not finished"
    (folder / "report.json").write_text("{}")
    assert finished_record(a, folder) == record
    assert finished_record(b, folder) is None, "another run's marker (another seed) does not count"
    (folder / MARKER).write_text("{not json")
    assert finished_record(a, folder) is None


def test_an_error_is_one_line_with_where_it_was_raised():
    try:
        {}["missing"]
    except KeyError as err:
        text = one_line(err)
    assert text.startswith("KeyError: 'missing' (at test_sweep.py:") and "\n" not in text
    assert one_line(DelveError("bad\nvalue", "x.yaml", 3)) == "x.yaml:3: bad value"
    long = "/home/someone/experiments/2026/scenarios/gbplanner_demo.yaml"    # a run's error names it whole
    assert one_line(DelveError("world: cannot lay out", long, 12)).startswith(f"{long}:12: world")


REPORT = {"scenario": "small_tunnel", "seed": 1, "succeeded": True, "wall_time_s": 2.0,
          "outcome": {"timed_out": False, "reasons": [], "lost": {}}, "coverage_fraction": 0.5,
          "coverage_reached_s": {"80%": None, "90%": None},
          "robots": [{"name": "anymal", "distance_m": 10.0, "start": [0, 0, 0], "safety_triggers": {"stuck": 1}}]}


def test_flatten_keeps_numbers_words_truths_and_robots_by_name():
    assert flatten(REPORT) == {"succeeded": True, "outcome.timed_out": False, "coverage_fraction": 0.5,
                               "coverage_reached_s.80%": None, "coverage_reached_s.90%": None,
                               "robots.anymal.distance_m": 10.0, "robots.anymal.safety_triggers.stuck": 1}


def fake_sweep(tmp_path: Path):
    """A sweep of four runs (two ranges x two seeds) with reports made up: coverage
    grows with the range, the first run failed."""
    sweep = load_sweep(sweep_file(tmp_path, "scenarios: [SMALL]\nseeds: [1, 2]\ngrid: {radio.range_m: [30, 60]}\n"))
    runs_dir = tmp_path / "out" / "runs"
    records = {}
    for i, run in enumerate(sweep.runs):
        ok = i > 0
        records[run.run_id] = {"status": "ok" if ok else "failed", "error": "" if ok else "boom", "wall_time_s": 1.0}
        (runs_dir / run.run_id).mkdir(parents=True)
        rep = dict(REPORT, seed=run.seed, coverage_fraction=0.1 * i, succeeded=i % 2 == 0)
        (runs_dir / run.run_id / "report.json").write_text(json.dumps(rep))
    return sweep, records, runs_dir


def test_the_table_has_a_row_per_run_and_reads_back_from_parquet(tmp_path):
    sweep, records, runs_dir = fake_sweep(tmp_path)
    table = results_table(sweep, records, runs_dir)
    assert list(table.columns[:8]) == ["run_id", "scenario", "seed", "label", "status", "error", "wall_time_s",
                                       "radio.range_m"]
    assert list(table["status"]) == ["failed", "ok", "ok", "ok"]
    assert table["coverage_fraction"].isna().tolist() == [True, False, False, False], "a failed run has no figures"
    assert list(table["radio.range_m"]) == [30, 30, 60, 60]
    write_table(table, tmp_path / "out")
    back = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert back["run_id"].tolist() == table["run_id"].tolist()
    assert back["coverage_fraction"].tolist()[1:] == pytest.approx([0.1, 0.2, 0.3])
    assert pd.read_csv(tmp_path / "out" / "results.csv")["status"].tolist() == ["failed", "ok", "ok", "ok"]


def test_one_plot_per_figure_that_varies(tmp_path):
    sweep, records, runs_dir = fake_sweep(tmp_path)
    table = results_table(sweep, records, runs_dir)
    assert figure_columns(table, sweep) == ["succeeded", "coverage_fraction"]
    written = plot_figures(table, sweep, tmp_path / "plots")
    assert [p.name for p in written] == ["succeeded.png", "coverage_fraction.png"]
    assert all(p.stat().st_size > 1000 for p in written)


def test_runs_without_a_value_are_counted_under_their_group_and_leave_no_median(tmp_path, monkeypatch):
    """A coverage never reached has no time: the plot says how many, not a median of the rest."""
    sweep, records, runs_dir = fake_sweep(tmp_path)
    last = runs_dir / sweep.runs[3].run_id / "report.json"
    last.write_text(json.dumps(dict(json.loads(last.read_text()), coverage_reached_s={"80%": 120.0, "90%": None})))
    drawn = {}
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, path, **kw: drawn.setdefault(
        Path(path).name, ([t.get_text() for t in fig.axes[0].texts], len(fig.axes[0].collections))))
    plot_figures(results_table(sweep, records, runs_dir), sweep, tmp_path / "plots")
    texts, _ = drawn["coverage_reached_s.80_.png"]
    assert texts == ["1 of 1:\nno value", "1 of 2:\nno value"]     # range 30 (one failed run), range 60
    _, with_value = drawn["coverage_fraction.png"]
    assert with_value > 0


def test_a_whole_list_can_be_overridden(tmp_path):
    """A team of two in place of the scenario's one robot (paths resolve from the scenario)."""
    sweep = load_sweep(sweep_file(tmp_path, """
scenarios: [SMALL]
runs:
  - label: two
    set:
      robots:
        - {name: a, platform: legged, tree: ../../../trees/frontier_explorer.yaml}
        - {name: b, platform: legged, tree: ../../../trees/frontier_explorer.yaml}
"""))
    (run,) = sweep.runs
    assert run.run_id == "small_tunnel-two-s4" and [r["name"] for r in run.overrides[0].value] == ["a", "b"]
