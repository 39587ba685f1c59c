"""Coverage over sim time: GBPlanner2 against the nearest-frontier baseline.

The same legged robot (ANYmal-like, 1800 s endurance) explores each generated world
twice, once with ``trees/gbplanner_explorer.yaml`` (GBPlanner2's Explore and Home) and
once with ``trees/frontier_explorer.yaml`` (nearest frontier, Home along the navigation
graph), on the same world and seed. T90 is the sim time at which the robot has
observed 90 % of the world's reachable free volume (linearly interpolated between
coverage samples, every 5 s); "not reached" when it never does, with the final
coverage.

Worlds: a tunnel network, a two-level tunnel network joined by a ramp, and a cave
(no shaft: the legged robot must be able to reach all of it), each with several
seeds. Missions run in-process (``delve.executive.runner.Mission``), one world and
seed per worker process.

    .venv/bin/python bench/exploration.py [--quick] [--seeds 1 2 3] [--jobs 2]

Prints the command, one row per run, then the median T90 per planner and world and
the ratio GBPlanner2 / baseline (goal: at most 0.8), and the same for T80 (80 %
coverage), since parts of some generated worlds are out of a legged robot's reach.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import multiprocessing
import shlex
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent

TREES = {
    "GBPlanner2": ROOT / "trees" / "gbplanner_explorer.yaml",
    "frontier": ROOT / "trees" / "frontier_explorer.yaml",
}
#: name -> world section of a scenario (generator parameters).
WORLDS = {
    "tunnel_network": {"generator": "tunnel_network", "total_length_m": 300, "loops": 2, "max_slope_deg": 30},
    "two_level_ramp": {"generator": "tunnel_network", "total_length_m": 300, "levels": 2, "ramp": True, "loops": 1,
                       "max_slope_deg": 20},
    "cave": {"generator": "cave", "total_length_m": 250, "shaft": False, "width_m": [2.0, 6.0], "height_m": [2.0, 4.0]},
}
QUICK_LENGTH_M = {"tunnel_network": 150, "two_level_ramp": 200, "cave": 130}
ENDURANCE_S = 1800.0
DURATION_S = 2400.0
TARGET = 0.90
#: A second, lower target, reported too: where parts of a world are out of a legged
#: robot's reach, neither planner may reach 90 %.
TARGET_LOW = 0.80


@dataclass
class Run:
    world: str
    seed: int
    planner: str
    t90_s: float | None
    t80_s: float | None
    final_coverage: float
    sim_time_s: float
    distance_m: float
    returned_home: bool
    succeeded: bool
    wall_s: float


def scenario_doc(world: dict, tree: Path, seed: int) -> dict:
    return {
        "name": "exploration_bench",
        "seed": seed,
        "duration_s": DURATION_S,
        "world": world,
        "base_station": {"tree": str(ROOT / "trees" / "base_station.yaml")},
        "robots": [{"name": "anymal", "platform": "legged", "tree": str(tree), "endurance_s": ENDURANCE_S}],
    }


def t_reach(samples: list, fraction: float) -> float | None:
    """Sim time at which team coverage first reaches ``fraction`` (interpolated)."""
    prev = None
    for s in samples:
        if s.team >= fraction:
            if prev is None or s.team == prev.team:
                return float(s.t)
            return float(prev.t + (fraction - prev.team) / (s.team - prev.team) * (s.t - prev.t))
        prev = s
    return None


def run_world(job: tuple[str, dict, int]) -> list[Run]:
    """Both planners on one world and seed (the world is generated once)."""
    import numpy as np
    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario

    name, world_spec, seed = job
    out: list[Run] = []
    world = None
    with tempfile.TemporaryDirectory() as tmp:
        for planner, tree in TREES.items():
            path = Path(tmp) / f"{planner}.yaml"
            path.write_text(yaml.safe_dump(scenario_doc(world_spec, tree, seed)))
            scenario = load_scenario(path)
            if world is None:
                world = scenario.build_world(seed=seed)
            t = time.perf_counter()
            mission = Mission(scenario, seed=seed, world=world)
            mission.run()
            wall = time.perf_counter() - t
            robot = mission.robots["anymal"]
            out.append(Run(name, seed, planner, t_reach(mission.state.samples, TARGET),
                           t_reach(mission.state.samples, TARGET_LOW), mission.state.samples[-1].team, mission.clock.now_s, robot.distance_m,
                           bool(np.linalg.norm(robot.position - robot.home) <= 1.5), mission.succeeded, wall))
    return out


def fmt_t(t: float | None) -> str:
    return "not reached" if t is None else f"{t:.0f}"


def median_t(times: list[float | None]) -> float | None:
    """Median time, counting "not reached" as later than any time (None when the median
    itself is not reached)."""
    values = sorted((t if t is not None else float("inf")) for t in times)
    m = statistics.median(values)
    return None if m == float("inf") else m


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller worlds and one seed (a minute or two)")
    ap.add_argument("--seeds", type=int, nargs="+", default=None, help="world/mission seeds (default 1 to 5)")
    ap.add_argument("--worlds", nargs="+", choices=sorted(WORLDS), default=list(WORLDS))
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1), help="worker processes")
    args = ap.parse_args(argv)
    seeds = args.seeds or ([1] if args.quick else [1, 2, 3, 4, 5])
    print("$ " + " ".join(shlex.quote(a) for a in [Path(sys.executable).name, *sys.argv]))
    print()
    worlds = {}
    for name in args.worlds:
        spec = dict(WORLDS[name])
        if args.quick:
            spec["total_length_m"] = QUICK_LENGTH_M[name]
        worlds[name] = spec
    for name, spec in worlds.items():
        params = ", ".join(f"{k}={v}" for k, v in spec.items() if k != "generator")
        print(f"world {name}: {spec['generator']}({params})")
    print(f"robot: legged (ANYmal-like), endurance {ENDURANCE_S:.0f} s, mission limit {DURATION_S:.0f} s; "
          f"seeds {seeds}; {args.jobs} worker(s); load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"trees: GBPlanner2 = {TREES['GBPlanner2'].relative_to(ROOT)}, "
          f"frontier = {TREES['frontier'].relative_to(ROOT)}")
    print()
    jobs = [(name, spec, seed) for name, spec in worlds.items() for seed in seeds]
    t0 = time.perf_counter()
    runs: list[Run] = []

    def done(rs: list[Run]) -> None:
        runs.extend(rs)
        print(f"  [{len(runs) // len(TREES)}/{len(jobs)}] {rs[0].world} seed {rs[0].seed} done "
              f"({time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)

    if args.jobs > 1:
        with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
            for rs in pool.imap_unordered(run_world, jobs, chunksize=1):
                done(rs)
    else:
        for job in jobs:
            done(run_world(job))
    header = (f"{'world':<16}{'seed':>5}  {'planner':<11}{'T90 (s)':>12}{'T80 (s)':>12}{'final cov':>11}"
              f"{'end (s)':>9}{'dist (m)':>10}{'home':>6}{'wall (s)':>10}")
    print(header)
    print("-" * len(header))
    for r in sorted(runs, key=lambda r: (list(worlds).index(r.world), r.seed, r.planner)):
        print(f"{r.world:<16}{r.seed:>5}  {r.planner:<11}{fmt_t(r.t90_s):>12}{fmt_t(r.t80_s):>12}"
              f"{r.final_coverage:>10.1%}"
              f"{r.sim_time_s:>9.0f}{r.distance_m:>10.0f}{'yes' if r.returned_home else 'no':>6}{r.wall_s:>10.1f}")
    print()
    for label, attr in (("T90", "t90_s"), ("T80", "t80_s")):
        header = f"{'world':<16}{'median ' + label + ' GBPlanner2':>23}{'median ' + label + ' frontier':>21}{'ratio':>8}"
        print(header)
        print("-" * len(header))
        ratios = []
        for name in worlds:
            gb = median_t([getattr(r, attr) for r in runs if r.world == name and r.planner == "GBPlanner2"])
            fr = median_t([getattr(r, attr) for r in runs if r.world == name and r.planner == "frontier"])
            ratio = gb / fr if gb is not None and fr is not None else None
            if ratio is not None:
                ratios.append(ratio)
            print(f"{name:<16}{fmt_t(gb):>23}{fmt_t(fr):>21}{'—' if ratio is None else f'{ratio:.2f}':>8}")
        if ratios:
            print(f"{'all worlds':<16}{'':>23}{'':>21}{statistics.median(ratios):>8.2f}  (median of the ratios)")
        print()
    print(f"goal: T90 ratio GBPlanner2 / baseline <= 0.8; total wall time {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
