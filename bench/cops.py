"""COPS planner benchmark: one full cycle (Problem 1 + Problem 2) against network size and
team size, with and without clustering.

Scenario per cell: a tunnel network from ``tunnel_network_graph(n, seed)``, the base
station at s0, half the robots at the base and the rest spread over the tunnels (as
after earlier cycles), frontiers at every dead end. The solves are bounded by work
(``SolverOptions``: nodes, checkpoint work ``--max-work``, probes ``--probe-max-work``,
the stall stop ``--stall-work``, the cycle ``--total-work`` simplex iterations), so
every run of a cell gives the same plans; the wall clock is only a safety stop
(``--safety-s`` per solve, 10 times that per cycle), and a cell whose cycle runs
longer than ``--cell-limit`` is skipped for larger teams. Printed per cell, for the
median of ``--repeats`` runs (the machine may be shared): wall time of the cycle
(with the fastest and slowest run), whether ``clustering="auto"`` would cluster, the
horizons, the work (simplex iterations) and solves of the cycle, the worst
optimality gap reported by the solver (None: unknown), and whether every plan of
every run passes the validator and every run gave the same plans (``differs``
otherwise, or ``safety stop`` when one fired).

    .venv/bin/python bench/cops.py            # the whole table, < 15 min on 2 cores
    .venv/bin/python bench/cops.py --sizes 100 --robots 10
"""
from __future__ import annotations

import argparse
import shlex
import sys
import time
from dataclasses import replace

from delve.planners.cops import (PlanningError, SolverOptions, available_solver, plan_cycle,
                                 validate_plan)
from delve.planners.cops.meter import Meter
from delve.planners.cops.clustering import should_cluster
from delve.planners.cops.network import spread_team_network


def run_cell(n: int, r: int, clustered: bool, opts: SolverOptions, seed: int):
    net = spread_team_network(n, r, seed)
    meter = Meter()
    t0 = time.perf_counter()
    try:
        cyc = plan_cycle(net, clustering=clustered, options=replace(opts, meter=meter))
    except PlanningError as err:
        return time.perf_counter() - t0, None, f"{err}" + (" (safety stop)" if meter.safety_stops else "")
    wall = time.perf_counter() - t0
    ok = not validate_plan(net, cyc.pre) and not validate_plan(net.with_positions(cyc.pre.final_positions()), cyc.post)
    return wall, cyc, ("valid" if ok else "INVALID") + (" safety stop" if meter.safety_stops else "")


def same_plans(cycles) -> bool:
    """Whether every run gave the same plans."""
    plans = {None if c is None else repr((c.pre.trajectories, c.pre.communications, c.post.trajectories,
                                           c.post.communications, c.meta.get("work"))) for c in cycles}
    return len(plans) == 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[25, 50, 100, 200])
    ap.add_argument("--robots", type=int, nargs="+", default=[2, 5, 10, 20])
    d = SolverOptions()
    ap.add_argument("--max-work", type=float, default=d.max_work, help="checkpoint work per integer program")
    ap.add_argument("--probe-max-work", type=float, default=d.probe_max_work,
                    help="checkpoint work per probe")
    ap.add_argument("--stall-work", type=float, default=d.stall_work, help="stall stop, in checkpoint work")
    ap.add_argument("--total-work", type=int, default=d.total_work,
                    help="simplex iterations for the whole cycle (ends the horizon searches)")
    ap.add_argument("--safety-s", type=float, default=30.0,
                    help="safety stop per integer program (seconds; 10 times that per cycle)")
    ap.add_argument("--cell-limit", type=float, default=40.0,
                    help="skip larger teams on a size once a cycle took this long")
    ap.add_argument("--repeats", type=int, default=3, help="runs per cell (the median run is shown)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    print("command:", " ".join(shlex.quote(a) for a in [sys.executable] + sys.argv))
    print(f"solver: {available_solver()}; per solve {args.max_work:g} checkpoint work (probes "
          f"{args.probe_max_work:g}, stall {args.stall_work:g}), cycle {args.total_work} simplex iterations; "
          f"safety stop {args.safety_s:g} s per solve; median of {args.repeats} runs per cell")
    opts = SolverOptions(max_work=args.max_work, probe_max_work=args.probe_max_work,
                         stall_work=args.stall_work, total_work=args.total_work, mip_gap=0.01,
                         time_limit_s=args.safety_s,
                         probe_time_limit_s=args.safety_s, total_time_limit_s=10 * args.safety_s)
    header = f"{'locations':>9} {'robots':>6} {'clustering':>10} {'auto':>4} {'cycle_s':>8} {'min_s':>6} " \
             f"{'max_s':>6} {'T_pre':>5} {'T_post':>6} {'clusters':>8} {'explorers':>9} {'work':>7} " \
             f"{'solves':>6} {'gap':>8}  result"
    print(header)
    print("-" * len(header))
    t_all = time.perf_counter()
    for n in args.sizes:
        for clustered in (False, True):
            skip = False
            for r in args.robots:
                label = "yes" if clustered else "no"
                net = spread_team_network(n, r, args.seed)
                auto = "yes" if should_cluster(net, net.positions(), {net.base_station}) else "no"
                if skip:
                    print(f"{n:>9} {r:>6} {label:>10} {auto:>4} {'-':>8} {'-':>6} {'-':>6} {'-':>5} {'-':>6} "
                          f"{'-':>8} {'-':>9} {'-':>7} {'-':>6} {'-':>8}  "
                          f"skipped (a smaller team already took > {args.cell_limit:g} s)")
                    continue
                runs = [run_cell(n, r, clustered, opts, args.seed) for _ in range(max(args.repeats, 1))]
                walls = sorted(w for w, _c, _res in runs)
                wall, cyc, result = sorted(runs, key=lambda run: run[0])[len(runs) // 2]
                if any(res.startswith("INVALID") for _w, _c, res in runs):
                    result = "INVALID"
                if any("safety stop" in res for _w, _c, res in runs):
                    result += "" if "safety stop" in result else " (a safety stop fired)"
                elif not same_plans([c for _w, c, _res in runs]):
                    result += " differs"
                if cyc is None:
                    print(f"{n:>9} {r:>6} {label:>10} {auto:>4} {wall:>8.2f} {walls[0]:>6.2f} "
                          f"{walls[-1]:>6.2f} {'-':>5} {'-':>6} {'-':>8} {'-':>9} {'-':>7} {'-':>6} "
                          f"{'-':>8}  no plan: {result}")
                else:
                    gap = cyc.meta.get("gap")
                    gap_s = "None" if gap is None else f"{gap:.3f}"
                    print(f"{n:>9} {r:>6} {label:>10} {auto:>4} {wall:>8.2f} {walls[0]:>6.2f} "
                          f"{walls[-1]:>6.2f} {cyc.pre.horizon:>5} {cyc.post.horizon:>6} {cyc.meta.get('clusters', 1):>8} "
                          f"{len(cyc.pre.explore):>9} {cyc.meta['work']:>7} {cyc.meta['solves']:>6} "
                          f"{gap_s:>8}  {result}")
                sys.stdout.flush()
                if wall > args.cell_limit:
                    skip = True
    print(f"total {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
