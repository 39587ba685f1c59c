"""The SubT Final's Prize Round, replayed over several seeds (scenarios/subt_final.yaml).

Each seed generates its own course and places its own 40 artifacts; the team and the
supervisor's script are the scenario's. The runs are one sweep (docs/sweeps.md) on a
Dask LocalCluster of ``--jobs`` workers; ``--out DIR`` keeps it, and a second start
resumes it. Prints one row per run, then points (median, min, max), reports used,
each robot's distance, moving time and share of its time in the course, and the
share of the detected artifacts that scored, beside CERBERUS's Table 3 (23 points,
45 reports; the four ANYmals walked 240, 687, 311 and 500 m, operational 31-69 %).

    .venv/bin/python bench/subt_final.py [--seeds 1 2 3 4 5] [--jobs 1] [--duration-s 3600] [--out DIR]

A run takes about 15 minutes of wall time on a 2-core machine (six robots, one hour).
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import json
import shlex
import statistics
import sys
import tempfile
from pathlib import Path

import yaml

from delve import SCENARIOS_DIR

#: The shipped scenario (a sweep reads scenarios from the shipped ones or its own folder).
SCENARIO = SCENARIOS_DIR / "subt_final.yaml"
#: CERBERUS's Prize Round (paper, Table 3): ANYmal run time (min), distance (m),
#: points and operational share.
TABLE_3 = {"ANYmal 1": (57, 240, 8, 0.311), "ANYmal 2": (60, 687, 8, 0.69), "ANYmal 3": (47, 311, 1, 0.341),
           "ANYmal 4": (50, 500, 6, 0.575)}
PAPER_POINTS, PAPER_REPORTS = 23, 45


def sweep(seeds: list[int], duration_s: float, out: Path, jobs: int) -> list[dict]:
    """Run the scenario for each seed (resuming what ``out`` holds); the reports."""
    from delve.executive.sweep import run_sweep
    from delve.executive.sweep_spec import load_sweep

    out.mkdir(parents=True, exist_ok=True)
    spec = out / "subt_final_sweep.yaml"
    spec.write_text(yaml.safe_dump({"name": "subt_final", "scenarios": [str(SCENARIO)], "seeds": seeds,
                                    "grid": {"duration_s": [duration_s]}}))
    result = run_sweep(load_sweep(spec), out / "sweep", workers=jobs, plots=False)
    reports = []
    for row in result.table.to_dict("records"):
        if row["status"] != "ok":
            sys.exit(f"run {row['run_id']} failed: {row['error']}")
        reports.append(json.loads((out / "sweep" / "runs" / row["run_id"] / "report.json").read_text()))
    return sorted(reports, key=lambda r: r["seed"])


def robot_rows(report: dict, deploy: dict[str, float]) -> list[tuple[str, float, float, float, int]]:
    """Per robot: name, distance (m), moving time (min), moving share of its time in
    the course, points."""
    end = report["sim_time_s"]
    art = report["artifacts"]
    return [(r["name"], r["distance_m"], r["moving_s"] / 60.0, r["moving_s"] / max(end - deploy[r["name"]], 1e-9),
             art["robots"][r["name"]]["points"]) for r in report["robots"]]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    ap.add_argument("--jobs", type=int, default=1, help="sweep workers (each run needs about 3 GB)")
    ap.add_argument("--duration-s", type=float, default=3600.0)
    ap.add_argument("--out", type=Path, help="keep the sweep here (a second start resumes it)")
    args = ap.parse_args()
    print("$ " + " ".join(shlex.quote(a) for a in [".venv/bin/python", "bench/subt_final.py", *sys.argv[1:]]))
    deploy = {r["name"]: float(r.get("deploy_at_s", 0.0)) for r in yaml.safe_load(SCENARIO.read_text())["robots"]}
    with tempfile.TemporaryDirectory() as tmp:
        reports = sweep(args.seeds, args.duration_s, args.out or Path(tmp), args.jobs)
    print(f"\n{'seed':>4} {'points':>6} {'reports':>7} {'detected':>8} {'delivered':>9} {'undelivered':>11} "
          f"{'false':>5} {'coverage':>8} {'wall (s)':>8}")
    for r in reports:
        a = r["artifacts"]
        print(f"{r['seed']:>4} {a['scored']:>6} {a['submitted']:>7} {a['detected']:>8} {a['reported_to_base']:>9} "
              f"{a['undelivered']:>11} {a['false_reports']:>5} {r['coverage_fraction']:>8.1%} {r['wall_time_s']:>8.0f}")
    points = [r["artifacts"]["scored"] for r in reports]
    used = [r["artifacts"]["submitted"] for r in reports]
    share = [r["artifacts"]["scored"] / max(r["artifacts"]["detected"], 1) for r in reports]
    print(f"\npoints: median {statistics.median(points):g}, min {min(points)}, max {max(points)} "
          f"(CERBERUS: {PAPER_POINTS}); reports used: median {statistics.median(used):g} (CERBERUS: {PAPER_REPORTS}); "
          f"scored / detected: median {statistics.median(share):.0%}")
    print(f"\n{'robot':<10} {'distance (m)':>12} {'moving (min)':>12} {'moving share':>12} {'points':>6}   (median over seeds)")
    rows = [robot_rows(r, deploy) for r in reports]
    for i, (name, *_) in enumerate(rows[0]):
        col = [[row[i][k] for row in rows] for k in range(1, 5)]
        print(f"{name:<10} {statistics.median(col[0]):>12.0f} {statistics.median(col[1]):>12.1f} "
              f"{statistics.median(col[2]):>12.0%} {statistics.median(col[3]):>6g}")
    print(f"\n{'CERBERUS':<10} {'distance (m)':>12} {'run (min)':>12} {'operational':>12} {'points':>6}   (Table 3)")
    for name, (run, dist, pts, op) in TABLE_3.items():
        print(f"{name:<10} {dist:>12} {run:>12} {op:>12.0%} {pts:>6}")


if __name__ == "__main__":
    main()
