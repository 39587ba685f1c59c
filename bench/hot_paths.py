"""Wall-clock timings that unit tests used to assert: LiDAR ray casting and one COPS
planning cycle (tests assert behaviour only; the times live here).

Ray casting: ``World.cast_rays`` with 6000 rays (a LiDAR sweep) from the middle of a
30 m tunnel of two parallel closed tunnels (the world of ``tests/sim/test_world.py``),
against open3d's ``RaycastingScene.cast_rays`` on the same rays with the tensor ready
(the baseline: what delve adds on top). The old test's goal: under 50 ms a sweep.

COPS: ``plan_cycle`` on the networks of ``tests/planners/test_cops_cycle_growth.py``
with the default work limits (seconds only as safety stops; the old goal of 12 s a
cycle stays), against the smallest of them, one robot at the base of five known locations
(the baseline, to see how a cycle grows with the team and the network). The old
test's goal: a cycle under 4 x the cycle's limit (12 s).

Each row is measured ``--runs`` times, interleaved with its baseline; the table shows
the medians and the median of the per-pair ratios (pairs measured back to back share
the machine's load, so their ratio is steadier than the times).

    python bench/hot_paths.py [--runs N] [--only raycast|cops]
"""
from __future__ import annotations

import argparse
import random
import shlex
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import networkx as nx
import numpy as np
import open3d as o3d
from delve.planners.cops import (PlanningError, Robot, SolverOptions, plan_cycle, tunnel_network_graph,
                                 validate_plan)
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_chamber, carve_tunnel, free_space_mesh

RAYS = 6000
CASTS = 20  # sweeps per run (a run's time is their mean)
RAYCAST_GOAL_MS = 50.0
#: The default work limits (seconds are safety stops only); the goal is the former 12 s.
OPTS = SolverOptions()
CYCLE_GOAL_S = 12.0


def timed(fn: Callable[[], object]) -> tuple[float, object]:
    start = time.perf_counter()
    out = fn()
    return time.perf_counter() - start, out


def paired(row: Callable[[], float], base: Callable[[], float], runs: int) -> tuple[list[float], list[float]]:
    """``runs`` times of ``row`` and of ``base``, interleaved, the order alternating."""
    rows, bases = [], []
    for rep in range(runs):
        if rep % 2 == 0:
            rows.append(row())
            bases.append(base())
        else:
            bases.append(base())
            rows.append(row())
    return rows, bases


def ratio(rows: list[float], bases: list[float]) -> float:
    return statistics.median(r / b for r, b in zip(rows, bases))


# ---------------------------------------------------------------------- ray casting


def twin_tunnels() -> World:
    """Two parallel 30 m tunnels along x (y = 0 and 12 m), 4 m wide, 3 m high, with round
    chambers at their ends; 0.25 m voxels."""
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([33.0, 15.0, 3.0]), 0.25)
    for y in (0.0, 12.0):
        carve_tunnel(canvas, [0.0, y, 0.0], [30.0, y, 0.0], 4.0, 3.0)
        for x in (0.0, 30.0):
            carve_chamber(canvas, [x, y, 0.0], 2.4, 3.0)
    mesh = free_space_mesh(canvas.free, canvas.origin, canvas.voxel_size_m)
    return World(name="twin", voxel_size_m=canvas.voxel_size_m, origin=canvas.origin, free=canvas.free,
                 mesh=mesh, centreline=nx.Graph(), start=[1.0, 0.0, 0.01])


def bench_raycast(runs: int) -> list[str]:
    world = twin_tunnels()
    rng = np.random.default_rng(0)
    d = rng.normal(size=(RAYS, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    o = np.repeat(np.array([[15.0, 0.0, 1.0]]), RAYS, 0)
    rays = o3d.core.Tensor(np.concatenate([o, d], axis=1).astype(np.float32))
    hits = world.cast_rays(o, d, 30.0)  # warm up (and check: a closed tunnel, every ray hits)
    world.scene.cast_rays(rays)
    if not np.isfinite(hits).all():
        raise SystemExit("a ray left the closed tunnel: the world is not what this benchmark expects")

    def delve() -> float:
        return timed(lambda: [world.cast_rays(o, d, 30.0) for _ in range(CASTS)])[0] / CASTS

    def raw() -> float:
        return timed(lambda: [world.scene.cast_rays(rays) for _ in range(CASTS)])[0] / CASTS

    rows, bases = paired(delve, raw, runs)
    ms, base_ms = statistics.median(rows) * 1e3, statistics.median(bases) * 1e3
    verdict = "ok" if ms < RAYCAST_GOAL_MS else "ABOVE GOAL"
    return [
        f"ray casting, {RAYS} rays from the middle of a closed 30 m tunnel; {runs} runs of {CASTS} sweeps "
        f"(interleaved), median",
        "",
        f"{'':<42}{'ms':>8}{'ratio':>8}",
        f"{'World.cast_rays':<42}{ms:>8.2f}{ratio(rows, bases):>8.2f}"
        f"   (goal < {RAYCAST_GOAL_MS:g} ms: {verdict})",
        f"{'baseline: open3d RaycastingScene.cast_rays':<42}{base_ms:>8.2f}{1.0:>8.2f}",
    ]


# ------------------------------------------------------------------- COPS planning

FULL = tunnel_network_graph(100, seed=4)


def known_network(known: set[str], robots: dict[str, str]):
    """The explored part of FULL: frontiers are known locations with an unknown neighbour."""
    net = FULL.subnetwork(known)
    net.robots = {"base": FULL.robots["base"]}
    net.base_station = "base"
    for r, s in robots.items():
        net.add_robot(Robot(r, s))
    und = FULL.mobility.to_undirected(as_view=True)
    net.frontiers = {v for v in known if any(w not in known for w in und.neighbors(v))}
    return net


def grow(n_known: int, seed: int = 0) -> set[str]:
    rng = random.Random(seed)
    und = FULL.mobility.to_undirected(as_view=True)
    known = {"s0"}
    while len(known) < n_known:
        known.add(rng.choice(sorted({w for v in known for w in und.neighbors(v)} - known)))
    return known


class Cycles:
    """Times ``plan_cycle`` (until its plan, or until it gives up) and counts the plans
    that fail the validator and the cycles that found none."""

    def __init__(self) -> None:
        self.invalid = 0
        self.failed = 0

    def cycle(self, net) -> tuple[float, object | None]:
        start = time.perf_counter()
        try:
            cyc = plan_cycle(net, masters={"base"}, explorers=set(net.robots) - {"base"}, static={"base"},
                             clustering="auto", options=OPTS)
        except PlanningError:
            self.failed += 1
            return time.perf_counter() - start, None
        wall = time.perf_counter() - start
        after = net.with_positions(cyc.pre.final_positions())
        if validate_plan(net, cyc.pre) or validate_plan(after, cyc.post):
            self.invalid += 1
        return wall, cyc

    def one(self, known: set[str], robots: dict[str, str]) -> Callable[[], float]:
        net = known_network(known, robots)
        return lambda: self.cycle(net)[0]

    def growing(self, team: int) -> Callable[[], float]:
        """The slowest of four cycles on a network that grows from the base (the
        executive's loop: robots start where the last post-exploration left them)."""
        und = FULL.mobility.to_undirected(as_view=True)

        def run() -> float:
            positions = {f"r{i}": "s0" for i in range(1, team + 1)}
            known, slowest = {"s0"}, 0.0
            for _ in range(4):
                wall, cyc = self.cycle(known_network(known, positions))
                slowest = max(slowest, wall)
                if cyc is None:
                    break
                positions = {r: s for r, s in cyc.post.final_positions().items() if r != "base"}
                for s in set(cyc.pre.explore.values()):
                    new = {w for w in und.neighbors(s) if w not in known}
                    known |= new | {x for w in new for x in und.neighbors(w)}
            return slowest

        return run


def bench_cops(runs: int) -> list[str]:
    cycles = Cycles()
    small = grow(5, seed=1)
    larger = sorted(grow(60, seed=2))
    rng = random.Random(2)
    spread = {f"r{i}": ("s0" if i <= 3 else rng.choice(larger)) for i in range(1, 11)}
    base = cycles.one(small, {"r1": "s0"})
    rows = [
        ("20 robots at the base, 5 known locations",
         cycles.one(small, {f"r{i}": "s0" for i in range(1, 21)})),
        ("10 robots spread, 60 known locations", cycles.one(set(larger), spread)),
        ("growing network, 1 robot (slowest of 4)", cycles.growing(1)),
        ("growing network, 20 robots (slowest of 4)", cycles.growing(20)),
    ]
    base()  # warm up (imports, solver start-up)
    lines = [
        f"COPS plan_cycle, default work limits ({OPTS.total_work} simplex iterations a cycle; "
        f"safety stops {OPTS.time_limit_s:g} s a program, {OPTS.total_time_limit_s:g} s a cycle); "
        f"{runs} runs (interleaved with the baseline), median",
        "",
        f"{'':<44}{'s':>8}{'ratio':>8}",
    ]
    base_times: list[float] = []
    for label, row in rows:
        failed = cycles.failed
        times, bases = paired(row, base, runs)
        base_times += bases
        s = statistics.median(times)
        verdict = "ok" if s < CYCLE_GOAL_S else "ABOVE GOAL"
        if cycles.failed > failed:  # the time until plan_cycle gave up
            verdict = f"NO PLAN in {cycles.failed - failed} of {runs} runs"
        lines.append(f"{label:<44}{s:>8.2f}{ratio(times, bases):>8.1f}"
                     f"   (goal < {CYCLE_GOAL_S:g} s: {verdict})")
    base_s = statistics.median(base_times)
    lines.append(f"{'baseline: 1 robot at the base, 5 known':<44}{base_s:>8.3f}{1.0:>8.1f}")
    lines.append("")
    lines.append(f"plans failing the validator: {cycles.invalid}; "
                 f"cycles that found no plan within the limits: {cycles.failed}")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="runs per row, at least 3 (default 5)")
    parser.add_argument("--only", choices=("raycast", "cops"), help="one of the two tables")
    args = parser.parse_args(argv)
    runs = max(3, args.runs)
    command = shlex.join(["bench/hot_paths.py", *(sys.argv[1:] if argv is None else argv)])
    print(f"$ {Path(sys.executable).name} {command}")
    if args.only in (None, "raycast"):
        print()
        print("\n".join(bench_raycast(runs)))
    if args.only in (None, "cops"):
        print()
        print("\n".join(bench_cops(runs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
