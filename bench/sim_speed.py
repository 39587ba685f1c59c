"""Real-time factor of a mission, with the share of ray casting, map integration,
planning and ticking.

    .venv/bin/python bench/sim_speed.py [--scenario scenarios/demo.yaml] [--runs 3]

Prints the median over the runs. The shares come from timing the functions that do
each kind of work (wrapped here, in the benchmark only); "planning" is the time in
the navigation-graph and frontier planners and the COPS network extraction (voxel
worlds), "ticking" is tree ticks minus planning.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

from delve.executive import agent as agent_mod
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario
from delve.planners import frontier, navgraph
from delve.planners.cops.extraction_incremental import ExtractionUpdater
from delve.planners.frontier_incremental import FrontierUpdater
from delve.planners.navgraph_incremental import LeggedGraphUpdater
from delve.sim import robot as robot_mod
from delve.sim.voxel_map import VoxelMap
from delve.sim.world import World
from delve.skills import exploration, navigation

SPENT: dict[str, float] = defaultdict(float)
#: Timed calls under way per bucket: a call within another of its bucket (the COPS
#: extractor's frontier update) is not counted twice.
_OPEN: dict[str, int] = defaultdict(int)


def timed(owner, attr: str, bucket: str) -> None:
    fn = getattr(owner, attr)

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
    for mod in (navigation, navgraph):
        timed(mod, "aerial_graph", "planning")
    timed(navgraph, "legged_graph", "planning")
    timed(LeggedGraphUpdater, "update", "planning")
    timed(FrontierUpdater, "update", "planning")
    timed(navgraph.NavGraph, "shortest_paths", "planning")
    for mod in (exploration, frontier):
        timed(mod, "frontier_voxels", "planning")
        timed(mod, "frontier_clusters", "planning")
        timed(mod, "nearest_frontier", "planning")
    timed(ExtractionUpdater, "update", "planning")
    timed(agent_mod.Agent, "tick_if_due", "ticking (incl. planning)")
    timed(robot_mod.SimRobot, "step", "kinematics")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", type=Path, default=Path(__file__).parent.parent / "scenarios" / "demo.yaml")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    scenario = load_scenario(args.scenario)
    world = scenario.build_world()
    instrument()
    rows = []
    for _ in range(args.runs):
        SPENT.clear()
        mission = Mission(scenario, world=world)
        t = time.perf_counter()
        mission.run()
        wall = time.perf_counter() - t
        shares = dict(SPENT)
        shares["ticking"] = shares.pop("ticking (incl. planning)", 0.0) - shares.get("planning", 0.0)
        rows.append((mission.clock.now_s, wall, shares))
    print(f"$ {' '.join(sys.argv)}")
    print(f"scenario {scenario.name}, {args.runs} runs, world built once\n")
    sim = statistics.median(r[0] for r in rows)
    wall = statistics.median(r[1] for r in rows)
    print(f"{'sim time (s)':<28}{sim:>10.0f}")
    print(f"{'wall time (s), median':<28}{wall:>10.2f}")
    print(f"{'real-time factor, median':<28}{sim / wall:>10.0f}x   (goal >= 100x)\n")
    print(f"{'share of wall time':<28}{'median s':>10}{'share':>9}")
    for bucket in ("ray casting", "map integration", "planning", "ticking", "kinematics"):
        s = statistics.median(r[2].get(bucket, 0.0) for r in rows)
        print(f"{bucket:<28}{s:>10.2f}{s / wall:>9.0%}")
    other = wall - sum(statistics.median(r[2].get(b, 0.0) for r in rows)
                       for b in ("ray casting", "map integration", "planning", "ticking", "kinematics"))
    print(f"{'other (radio, coverage, loop)':<28}{other:>10.2f}{other / wall:>9.0%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
