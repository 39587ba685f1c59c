"""Real-time factor of a mission, with the share of ray casting, map integration,
planning and ticking.

    .venv/bin/python bench/sim_speed.py [--scenario scenarios/demo.yaml] [--runs 3] [--duration-s S]
    .venv/bin/python bench/sim_speed.py --runs 3 --baseline /tmp/vb/bin/python
    .venv/bin/python bench/sim_speed.py --scenario subt_final --duration-s 1200 --runs 2 --baseline /tmp/vb/bin/python

Prints the median over the runs and the process's peak resident memory. The shares
come from timing the functions that do each kind of work (wrapped here, in the
benchmark only); "planning" is the time in the navigation-graph and frontier planners
and the COPS network extraction (voxel worlds), "ticking" is tree ticks minus planning.

``--baseline PYTHON`` compares with another checkout: PYTHON is the interpreter of a
virtual environment with that checkout installed (``git worktree add /tmp/base REV &&
python3 -m venv /tmp/vb && /tmp/vb/bin/pip install -e /tmp/base``). Each round runs
the mission once with this checkout and once with the baseline, each in a fresh
process, in alternating order (load on a shared machine hits both alike), and the
ratio of the medians is printed with the load average.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

from delve.executive import agent as agent_mod
from delve.executive.cli import shipped_or_given
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario
from delve.planners import frontier, navgraph
from delve.planners.frontier_incremental import FrontierUpdater
from delve.planners import navgraph_incremental
from delve.sim import robot as robot_mod
from delve.sim.voxel_map import VoxelMap
from delve.sim.world import World
from delve.skills import exploration

try:
    from delve.planners.cops.extraction_incremental import ExtractionUpdater
except ImportError:  # a baseline checkout from before it (--baseline)
    ExtractionUpdater = None

SPENT: dict[str, float] = defaultdict(float)
#: Timed calls under way per bucket: a call within another of its bucket (the COPS
#: extractor's frontier update) is not counted twice.
_OPEN: dict[str, int] = defaultdict(int)


BUCKETS = ("ray casting", "map integration", "planning", "ticking", "kinematics")


def timed(owner, attr: str, bucket: str) -> None:
    fn = getattr(owner, attr, None)
    if fn is None:  # a baseline checkout without it (--baseline)
        return

    def wrapper(*a, **k):
        if _OPEN[bucket]:
            return fn(*a, **k)
        t = time.perf_counter()
        _OPEN[bucket] += 1
        try:
            return fn(*a, **k)
        finally:
            _OPEN[bucket] -= 1
            SPENT[bucket] += time.perf_counter() - t

    setattr(owner, attr, wrapper)


def instrument() -> None:
    timed(World, "cast_rays", "ray casting")
    timed(VoxelMap, "integrate_scan", "map integration")
    timed(navgraph, "aerial_graph", "planning")
    timed(navgraph, "legged_graph", "planning")
    for updater in ("LeggedGraphUpdater", "AerialGraphUpdater"):   # AerialGraphUpdater: not in a baseline before it
        timed(getattr(navgraph_incremental, updater, None), "update", "planning")
    timed(FrontierUpdater, "update", "planning")
    timed(navgraph.NavGraph, "shortest_paths", "planning")
    for mod in (exploration, frontier):
        timed(mod, "frontier_voxels", "planning")
        timed(mod, "frontier_clusters", "planning")
        timed(mod, "nearest_frontier", "planning")
    timed(ExtractionUpdater, "update", "planning")
    timed(agent_mod.Agent, "tick_if_due", "ticking (incl. planning)")
    timed(robot_mod.SimRobot, "step", "kinematics")


def run_once(scenario, world, duration_s: float | None = None) -> dict:
    """One mission: sim time, wall and CPU time of its loop, seconds per bucket."""
    SPENT.clear()
    mission = Mission(scenario, world=world, duration_s=duration_s)
    t, cpu = time.perf_counter(), time.process_time()
    mission.run()
    wall, cpu = time.perf_counter() - t, time.process_time() - cpu
    shares = dict(SPENT)
    shares["ticking"] = shares.pop("ticking (incl. planning)", 0.0) - shares.get("planning", 0.0)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024   # KiB on Linux
    return {"sim_s": mission.clock.now_s, "wall_s": wall, "cpu_s": cpu, "shares": shares, "peak_mb": peak_mb}


def print_table(name: str, rows: list[dict]) -> None:
    sim = statistics.median(r["sim_s"] for r in rows)
    wall = statistics.median(r["wall_s"] for r in rows)
    print(f"{name}\n{'sim time (s)':<28}{sim:>10.0f}")
    runs = " ".join(f"{r['wall_s']:.1f}" for r in rows)
    print(f"{'wall time (s), median':<28}{wall:>10.2f}   runs: {runs}")
    print(f"{'CPU time (s), median':<28}{statistics.median(r['cpu_s'] for r in rows):>10.2f}")
    print(f"{'real-time factor, median':<28}{sim / wall:>10.0f}x   (goal: >= 100x for one robot, >= 30x for five)")
    print(f"{'peak memory (MB), max':<28}{max(r.get('peak_mb', 0.0) for r in rows):>10.0f}\n")
    print(f"{'share of wall time':<28}{'median s':>10}{'share':>9}")
    spent = {b: statistics.median(r["shares"].get(b, 0.0) for r in rows) for b in BUCKETS}
    for bucket, s in spent.items():
        print(f"{bucket:<28}{s:>10.2f}{s / wall:>9.0%}")
    other = wall - sum(spent.values())
    print(f"{'other (radio, coverage, loop)':<28}{other:>10.2f}{other / wall:>9.0%}\n")


def compare(args: argparse.Namespace) -> int:
    """Alternate child runs of this checkout and the baseline; print both and the ratio."""
    child = [__file__, "--runs", "1", "--json"] + (["--scenario", str(args.scenario)] if args.scenario else []) + (
        ["--duration-s", str(args.duration_s)] if args.duration_s else [])
    pythons = {"this checkout": sys.executable, "baseline": args.baseline}
    rows: dict[str, list[dict]] = {name: [] for name in pythons}
    load = [os.getloadavg()[0]]
    for i in range(args.runs):
        order = list(pythons) if i % 2 == 0 else list(pythons)[::-1]
        for name in order:
            out = subprocess.run([pythons[name], *child], check=True, capture_output=True, text=True).stdout
            rows[name].append(json.loads(out.strip().splitlines()[-1]))
        load.append(os.getloadavg()[0])
    print(f"$ {' '.join(sys.argv)}")
    print(f"scenario {args.scenario.stem if args.scenario else 'demo'} (each checkout's own), {args.runs} rounds, "
          "one run of each per round in alternating order\n")
    for name, r in rows.items():
        print_table(name, r)
    ratio = [b["wall_s"] / a["wall_s"] for a, b in zip(rows["this checkout"], rows["baseline"])]
    med = {n: statistics.median(r["wall_s"] for r in rows[n]) for n in rows}
    print(f"baseline / this checkout, wall time: {med['baseline'] / med['this checkout']:.2f} (medians), "
          f"per round {' '.join(f'{x:.2f}' for x in ratio)}")
    cpu = {n: statistics.median(r["cpu_s"] for r in rows[n]) for n in rows}
    print(f"baseline / this checkout, CPU time:  {cpu['baseline'] / cpu['this checkout']:.2f} (medians)")
    print(f"load average (1 min) before and after each round: {' '.join(f'{x:.1f}' for x in load)}")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", type=Path, help="a scenario file, or the name of a shipped one (each checkout's "
                    "own with --baseline); default: demo")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--duration-s", type=float, help="override the scenario's duration (sim seconds)")
    ap.add_argument("--baseline", help="python of a virtual environment with the baseline checkout installed")
    ap.add_argument("--json", action="store_true", help="print one run's figures as JSON (used by --baseline)")
    args = ap.parse_args()
    if args.baseline:
        return compare(args)
    scenario = load_scenario(shipped_or_given(args.scenario or Path("demo")))
    world = scenario.build_world()
    instrument()
    rows = [run_once(scenario, world, args.duration_s) for _ in range(args.runs)]
    if args.json:
        print(json.dumps(rows[-1]))
        return 0
    print(f"$ {' '.join(sys.argv)}")
    print(f"scenario {scenario.name}, {args.runs} runs, world built once, load average {os.getloadavg()[0]:.1f}\n")
    print_table("", rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
