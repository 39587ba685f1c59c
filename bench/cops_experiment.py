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

    .venv/bin/python bench/cops_experiment.py                  # 1, 2, 4, 8, 14, 20 robots
    .venv/bin/python bench/cops_experiment.py --robots 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20
"""
from __future__ import annotations

import argparse
import shlex
import statistics
import sys
import time
from dataclasses import replace

from delve import SCENARIOS_DIR
from delve.executive.runner import Mission
from delve.executive.outputs import report
from delve.executive.scenario import load_scenario


def run(n_robots: int, seed: int, duration_s: float) -> tuple[dict, float]:
    sc = load_scenario(SCENARIOS_DIR / "cops_tunnel.yaml")
    template = sc.robots[0]
    robots = [replace(template, name=f"r{i + 1}", endurance_s=duration_s) for i in range(n_robots)]
    sc = replace(sc, robots=robots, seed=seed)
    t0 = time.perf_counter()
    mission = Mission(sc, duration_s=duration_s)
    mission.run()
    wall = time.perf_counter() - t0
    return report(mission, wall), wall


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", type=int, nargs="+", default=[1, 2, 4, 8, 14, 20])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration-s", type=float, default=100000.0, help="sim time limit of each mission")
    args = ap.parse_args(argv)
    print("command:", " ".join(shlex.quote(a) for a in [sys.executable] + sys.argv))
    head = (f"{'robots':>6} {'trans_mean':>10} {'trans_std':>9} {'all_at_base_s':>13} {'mission_s':>9} "
            f"{'cycles':>6} {'ExtCom/plan':>11} {'IntCom/plan':>11} {'solve_med_s':>11} {'solve_max_s':>11} "
            f"{'work_med':>8} {'safety':>6} {'valid':>7} {'wall_s':>7}  result")
    print(head)
    print("-" * len(head))
    for n in args.robots:
        rep, wall = run(n, args.seed, args.duration_s)
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
