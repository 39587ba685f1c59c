"""Incremental maps (issue 17 item 1): time per update of the legged and of the aerial
navigation graph, of the frontier set and (COPS on voxel worlds) of the COPS network
extraction, updated from the changed voxels against recomputed over the whole map, at
every update of a real mission, with a check that the two agree.

    .venv/bin/python bench/incremental_maps.py [--scenario scenarios/demo.yaml] [--duration-s S]
    .venv/bin/python bench/incremental_maps.py --scenario scenarios/csiro_explore_sync.yaml --duration-s 600

The mission runs as usual (its navigators update their legged graphs from the maps'
change logs, COPS views their topologies); at each update this benchmark also builds
the graph with ``legged_graph`` and the frontier set with ``frontier_voxels`` and with
a ``FrontierUpdater`` on its own change log, and extracts the COPS topology with
``extract_topology`` (with the dense standable and passable masks it takes), times
each, and checks that the results are equal. Prints the medians and totals over the
mission, and the ratio of the medians (whole map / incremental).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario
from delve.planners.cops.extraction import extract_topology
from delve.planners.cops.extraction_incremental import ExtractionUpdater
from delve.planners.frontier import frontier_voxels
from delve.planners.frontier_incremental import FrontierUpdater
from delve.planners.navgraph import aerial_graph, legged_graph
from delve.planners.navgraph_incremental import AerialGraphUpdater
from delve.planners.occupancy import FREE
from delve.skills import navigation

TIMES: dict[str, list[float]] = defaultdict(list)
MISMATCHES: list[str] = []


def timed(key: str, fn, *args, **kwargs):
    t = time.perf_counter()
    out = fn(*args, **kwargs)
    TIMES[key].append(time.perf_counter() - t)
    return out


def instrument() -> None:
    """Wrap Navigator._legged_graph: time it, and compare with the full recomputations."""
    incremental = navigation.Navigator._legged_graph
    frontiers: dict[int, tuple[FrontierUpdater, object]] = {}

    def wrapper(self):
        m, mob = self.robot.onboard_map, self.robot.mobility
        graph = timed("legged graph, incremental", incremental, self)
        grid = self.grid()
        full = timed("legged graph, whole map", legged_graph, grid, body_height_m=mob.body_height_m,
                     radius_m=mob.radius_m, max_step_m=mob.max_step_m, max_inclination_deg=mob.max_inclination_deg)
        if not (np.array_equal(graph.positions, full.positions) and (graph.adjacency != full.adjacency).nnz == 0):
            MISMATCHES.append(f"legged graph at {self.ctx.clock.now_s:.1f} s")
        if id(m) not in frontiers:
            frontiers[id(m)] = (FrontierUpdater(), m.change_log())
            changed = None
        else:
            changed = frontiers[id(m)][1].take()
        got = timed("frontier set, incremental", frontiers[id(m)][0].update, grid, changed)
        want = timed("frontier set, whole map", frontier_voxels, grid)
        if not np.array_equal(got, want):
            MISMATCHES.append(f"frontier set at {self.ctx.clock.now_s:.1f} s")
        TIMES["free voxels"].append(len(grid.free_voxels()))
        return graph

    navigation.Navigator._legged_graph = wrapper


def instrument_cops() -> None:
    """Wrap ExtractionUpdater.update: time it, and compare with extract_topology."""
    incremental = ExtractionUpdater.update

    def wrapper(self, grid, changed=None, *, standable=None, visited=None, prior=None, keep=()):
        topo = timed("COPS extraction, incremental", incremental, self, grid, changed, standable=standable,
                     visited=visited, prior=prior, keep=keep)
        full = timed("COPS extraction, whole map", whole_map_extraction, self, grid, standable,
                     visited=visited, prior=prior, keep=keep)
        if topo != full:
            MISMATCHES.append(f"COPS extraction {len(TIMES['COPS extraction, incremental'])}")
        return topo

    ExtractionUpdater.update = wrapper


def instrument_aerial() -> None:
    """Wrap AerialGraphUpdater.update: time it, and compare with aerial_graph."""
    incremental = AerialGraphUpdater.update

    def wrapper(self, grid, changed=None):
        graph = timed("aerial graph, incremental", incremental, self, grid, changed)
        full = timed("aerial graph, whole map", aerial_graph, grid, radius_m=self.radius_m, stride=self.stride)
        if not (np.array_equal(graph.positions, full.positions) and (graph.adjacency != full.adjacency).nnz == 0):
            MISMATCHES.append(f"aerial graph {len(TIMES['aerial graph, incremental'])}")
        TIMES["free voxels"].append(len(grid.free_voxels()))
        return graph

    AerialGraphUpdater.update = wrapper


def whole_map_extraction(updater: ExtractionUpdater, grid, standable, **kwargs):
    """``extract_topology`` with the updater's parameters, as the COPS view called it
    before (dense masks of the standable and of the passable voxels)."""
    mask = np.zeros(grid.shape, dtype=bool)
    mask.reshape(-1)[standable] = True
    return extract_topology(grid.occupancy, grid.origin, grid.voxel_size_m, standable=mask,
                            passable=grid.occupancy == FREE, free=grid.free_voxels(), cell_m=updater.cell_m,
                            comm_range_m=updater.comm_range_m, min_free_voxels=updater.min_free_voxels,
                            sight_height_m=updater.sight_height_m, lattice_origin=updater.corner,
                            open_radius_m=updater.open_radius_m, max_region_m=updater.max_region_m, **kwargs)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", type=Path, default=Path(__file__).parent.parent / "scenarios" / "demo.yaml")
    ap.add_argument("--duration-s", type=float, help="override the scenario's duration (sim seconds)")
    args = ap.parse_args()
    scenario = load_scenario(args.scenario)
    instrument()
    instrument_cops()
    instrument_aerial()
    mission = Mission(scenario, world=scenario.build_world(), duration_s=args.duration_s)
    mission.run()
    print(f"$ {' '.join(sys.argv)}")
    n, cops = len(TIMES["free voxels"]), len(TIMES["COPS extraction, incremental"])
    extractions = f", {cops} COPS network extractions" if cops else ""
    print(f"scenario {scenario.name}: {n} navigation-graph updates{extractions}, "
          f"up to {max(TIMES['free voxels']):,} free voxels\n")
    print(f"{'per update':<30}{'median ms':>10}{'total s':>9}{'ratio':>8}")
    parts = [p for p in ("legged graph", "frontier set", "aerial graph", "COPS extraction") if TIMES[f"{p}, incremental"]]
    for part in parts:
        whole = statistics.median(TIMES[f"{part}, whole map"])
        for key in (f"{part}, whole map", f"{part}, incremental"):
            median = statistics.median(TIMES[key])
            ratio = f"{whole / median:>7.1f}x" if key.endswith("incremental") else ""
            print(f"{key:<30}{median * 1e3:>10.1f}{sum(TIMES[key]):>9.2f}{ratio}")
    print(f"\nincremental equal to whole-map results at every update: {'yes' if not MISMATCHES else MISMATCHES}")
    return 0 if not MISMATCHES else 1


if __name__ == "__main__":
    sys.exit(main())
