"""A sweep of four tiny runs on a two-worker LocalCluster: its table and plots, a
resume after an interruption (on a cluster given by its address), a failing run
beside good ones, and reports equal to ``delve run``'s for the same scenario and seed."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from dask.distributed import LocalCluster

from delve import TREES_DIR
from delve.executive.cli import main
from delve.executive.outputs import strip_wall_clock
from delve.executive.sweep import run_sweep
from delve.executive.sweep_run import MARKER
from delve.executive.sweep_spec import load_sweep

from .conftest import DATA

#: small_tunnel, 20 s of sim time: about a second a run.
TINY_DURATION_S = 20
GRID = "scenarios: [tiny.yaml]\nseeds: [1, 2]\ngrid:\n  radio.range_m: [40, 60]\n"


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """The sweep run once: its folder, the sweep, what run_sweep returned and its
    progress calls (done, total, run id)."""
    folder = tmp_path_factory.mktemp("sweep")
    text = (DATA / "small_tunnel.yaml").read_text().replace("../../../trees", str(TREES_DIR))
    (folder / "tiny.yaml").write_text(text.replace("duration_s: 600", f"duration_s: {TINY_DURATION_S}"))
    (folder / "s.yaml").write_text(GRID)
    sweep = load_sweep(folder / "s.yaml")
    calls = []
    result = run_sweep(sweep, folder / "out", workers=2,
                       progress=lambda done, total, spec, _: calls.append((done, total, spec and spec.run_id)))
    return folder, sweep, result, calls


def test_the_table_has_a_row_per_run_and_a_plot_per_figure(swept):
    folder, sweep, result, calls = swept
    assert (result.ran, result.skipped, result.failed) == (4, 0, 0)
    # The progress bar learns the total before the first run, then counts each one.
    assert calls[0] == (0, 4, None) and [c[:2] for c in calls[1:]] == [(i, 4) for i in (1, 2, 3, 4)]
    assert sorted(c[2] for c in calls[1:]) == sorted(r.run_id for r in sweep.runs)
    table = pd.read_parquet(folder / "out" / "results.parquet")
    assert table["run_id"].tolist() == [r.run_id for r in sweep.runs]
    assert table["status"].tolist() == ["ok"] * 4 and table["seed"].tolist() == [1, 2, 1, 2]
    assert table["radio.range_m"].tolist() == [40, 40, 60, 60]
    assert (table["sim_time_s"] >= TINY_DURATION_S).all() and (table["coverage_fraction"] > 0).all()
    assert pd.read_csv(folder / "out" / "results.csv")["run_id"].tolist() == table["run_id"].tolist()
    assert (folder / "out" / "plots" / "coverage_fraction.png").is_file()
    for run in sweep.runs:
        written = {p.name for p in (folder / "out" / "runs" / run.run_id).iterdir()}
        assert {"report.json", "log.jsonl", "map.png", "coverage.png", "tree_anymal.svg", MARKER} <= written


def test_the_same_run_gives_the_same_report_as_delve_run(swept):
    """Each run, though a worker ran another before it, equals ``delve run`` of the
    same scenario and seed in a fresh process (the file's range is 40 m)."""
    folder, sweep, _, _ = swept
    for run in sweep.runs[:2]:
        out = folder / f"alone-{run.seed}"
        subprocess.run([sys.executable, "-m", "delve.executive.cli", "run", str(folder / "tiny.yaml"), "--seed",
                        str(run.seed), "--quiet", "--out", str(out)], check=False, capture_output=True,
                       env={**os.environ, "PYTHONWARNINGS": "ignore"})
        alone = json.loads((out / "report.json").read_text())
        swept_report = json.loads((folder / "out" / "runs" / run.run_id / "report.json").read_text())
        assert strip_wall_clock(swept_report) == strip_wall_clock(alone)
        assert (out / "log.jsonl").read_bytes() == (folder / "out" / "runs" / run.run_id / "log.jsonl").read_bytes()


def test_a_second_start_runs_only_what_is_unfinished_and_a_failure_stops_nothing(swept, capsys):
    folder, sweep, _, _ = swept
    runs = folder / "out" / "runs"
    (runs / sweep.runs[1].run_id / MARKER).unlink()  # as if the sweep stopped while it ran
    kept = {r.run_id: (runs / r.run_id / "report.json").stat().st_mtime_ns for r in sweep.runs}
    # A second entry whose world cannot be built (too short for a loop) fails at build, on every seed and range.
    (folder / "s.yaml").write_text(GRID + "runs:\n  - {}\n  - {label: broken, set: {world.total_length_m: 60}}\n")
    # This time on an existing cluster, given by its address.
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster:
        assert main(["sweep", str(folder / "s.yaml"), "--out", str(folder / "out"), "--scheduler",
                     cluster.scheduler_address, "--quiet"]) == 1
    printed = capsys.readouterr().out
    assert "8 runs, 5 run now, 3 finished before, 4 failed" in printed
    after = {r: (runs / r / "report.json").stat().st_mtime_ns for r in kept}
    assert [r for r in kept if after[r] != kept[r]] == [sweep.runs[1].run_id]
    table = pd.read_csv(folder / "out" / "results.csv")
    broken = table[table["label"] == "broken"]
    assert len(table) == 8 and (table[table["label"] != "broken"]["status"] == "ok").all()
    assert (broken["status"] == "failed").all() and broken["error"].str.contains("total_length_m").all()
    assert all("\n" not in e for e in broken["error"])
    assert broken["error"].str.contains("this run's overrides: ").all()
    assert broken["error"].str.contains("world.total_length_m=60 (sweep line ", regex=False).all()
    assert (runs / broken["run_id"].iloc[0] / "error.txt").read_text().startswith("Traceback")
