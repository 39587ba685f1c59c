"""The COPS paper's experiment: explore a 100-location tunnel-like network with the base
station and 1..20 robots, all starting at the base, through the Figure 4 trees, in
cycles of pre-exploration, exploration and post-exploration until nothing is left.

Each row is one full mission (``scenarios/cops_tunnel.yaml`` with the team size
changed). Printed per team size: transitions per robot (mean and standard
deviation), total exploration time (sim time until the base station knows every
location, and until the mission ended with everyone home), cycles, ExtCom and
IntCom per plan (pre- plus post-exploration), COPS solve time per cycle (median and
max, wall clock), the work per cycle (simplex iterations, median; it bounds the
plans, so they do not depend on the machine's load), the safety stops that fired
(wall clock; with one the run may not be reproducible) and whether every plan
passed the validator.

The missions are one sweep (``delve.executive.sweep``, docs/sweeps.md), a run per
team size, on a Dask LocalCluster of ``--workers`` workers (default 1: solve times
are wall clock, best measured alone) or the cluster at ``--scheduler``; the rows come
from the sweep's table and each run's ``report.json`` (its plans). ``--out DIR``
keeps the sweep and resumes it; by default it goes into a temporary folder.

    .venv/bin/python bench/cops_experiment.py                  # 1, 2, 4, 8, 14, 20 robots
    .venv/bin/python bench/cops_experiment.py --robots 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20
"""
from __future__ import annotations

import argparse
import json
import shlex
import statistics
import sys
import tempfile
from pathlib import Path

import yaml

from delve import SCENARIOS_DIR
from delve.executive.sweep import run_sweep
from delve.executive.sweep_spec import load_sweep
from delve.executive.yamlio import load_yaml, plain

SCENARIO = SCENARIOS_DIR / "cops_tunnel.yaml"


def sweep_doc(team_sizes: list[int], seed: int, duration_s: float) -> dict:
    """A run per team size: cops_tunnel's first robot copied ``n`` times (r1..rn),
    each with an endurance of ``duration_s``."""
    template = plain(load_yaml(SCENARIO)["robots"][0])
    return {"name": "cops_experiment", "scenarios": [str(SCENARIO)], "seeds": [seed],
            "runs": [{"label": f"{n}_robots",
                      "set": {"duration_s": duration_s,
                              "robots": [dict(template, name=f"r{i + 1}", endurance_s=duration_s) for i in range(n)]}}
                     for n in team_sizes]}


def _progress(done: int, total: int, spec, record: dict | None) -> None:
    """A line per finished run (none before the first: the sweep's first call gives the total)."""
    if spec is not None and record is not None:
        print(f"  [{done}/{total}] {spec.run_id} {record['status']}", file=sys.stderr, flush=True)


def reports(team_sizes: list[int], seed: int, duration_s: float, out: Path, workers: int,
            scheduler: str | None) -> list[tuple[int, dict | None, float, str]]:
    """Run the sweep into ``out``: per team size its report (None when the run
    failed), wall time and error."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep.yaml").write_text(yaml.safe_dump(sweep_doc(team_sizes, seed, duration_s), sort_keys=False))
    result = run_sweep(load_sweep(out / "sweep.yaml"), out / "results", workers=None if scheduler else workers,
                       scheduler=scheduler, plots=False, progress=_progress)
    rows = []
    for n, row in zip(team_sizes, result.table.itertuples()):
        report = out / "results" / "runs" / row.run_id / "report.json"
        rep = json.loads(report.read_text()) if row.status == "ok" else None
        rows.append((n, rep, float(row.wall_time_s or 0.0), row.error))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", type=int, nargs="+", default=[1, 2, 4, 8, 14, 20])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration-s", type=float, default=100000.0, help="sim time limit of each mission")
    ap.add_argument("--workers", type=int, default=1, help="workers of the local cluster")
    ap.add_argument("--scheduler", metavar="ADDRESS", help="run the sweep on the Dask cluster at ADDRESS")
    ap.add_argument("--out", type=Path, help="keep the sweep in DIR (and resume it there); default: a temporary folder")
    args = ap.parse_args(argv)
    print("command:", " ".join(shlex.quote(a) for a in [sys.executable] + sys.argv))
    head = (f"{'robots':>6} {'trans_mean':>10} {'trans_std':>9} {'all_at_base_s':>13} {'mission_s':>9} "
            f"{'cycles':>6} {'ExtCom/plan':>11} {'IntCom/plan':>11} {'solve_med_s':>11} {'solve_max_s':>11} "
            f"{'work_med':>8} {'safety':>6} {'valid':>7} {'wall_s':>7}  result")
    print(head)
    print("-" * len(head))
    with tempfile.TemporaryDirectory() as tmp:
        rows = reports(args.robots, args.seed, args.duration_s, args.out or Path(tmp), args.workers, args.scheduler)
    for n, rep, wall, error in rows:
        if rep is None:
            print(f"{n:>6} run failed: {error}")
            continue
        trans = [r["transitions"] for r in rep["robots"]]
        plans = rep["cops"]["plans"]
        ext = statistics.mean(p["ext_com"] for p in plans) if plans else 0.0
        intc = statistics.mean(p["int_com"] for p in plans) if plans else 0.0
        solve = rep.get("cops_solve_time_s", {})
        work = statistics.median(p["work"] or 0 for p in plans) if plans else 0
        done = rep["all_known_at_base_s"]
        result = "ok" if rep["succeeded"] else f"FAILED {rep['cops']['no_plan'][:1]}"
        print(f"{n:>6} {statistics.mean(trans):>10.1f} {statistics.pstdev(trans):>9.1f} "
              f"{done if done is not None else '-':>13} {rep['sim_time_s']:>9.0f} {rep['cops']['cycles']:>6} "
              f"{ext:>11.1f} {intc:>11.1f} {solve.get('median', 0):>11.2f} {solve.get('max', 0):>11.2f} "
              f"{work:>8.0f} {rep['cops']['safety_stops']:>6} "
              f"{rep['cops']['plans_valid']:>3}/{rep['cops']['cycles']:<3} {wall:>7.0f}  {result}")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
