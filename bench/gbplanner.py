"""GBPlanner2 local-planning iteration time at 500 and 1000 vertices.

Builds a synthetic tunnel network (a few hundred metres of 4 m tunnels crossing on two
floor levels, joined by ramps) with numpy, hides everything farther than
``--mapped-radius`` from the robot (as if the robot had explored only that far), and
times ``LocalPlanner.plan`` from robot positions spread over the network: median and
90th percentile of the whole iteration and of its parts (graph building: the adaptive
bounding box, the local map and Algorithm 2; volumetric gain: Algorithm 3; Dijkstra's
shortest paths; the rest: path selection and improvement).

BLAS and OpenMP are limited to one thread: the goal is a median of at most 100 ms at
1000 vertices on one core. The paper reports 605 ms (1000 vertices, ANYmal C, 6-core
i7) and 279 ms (500 vertices, RMF-Obelix, ARM).

Run: ``.venv/bin/python bench/gbplanner.py [--iterations N] [--seed S] [--world synthetic|sim]``
(``--world sim`` uses ``delve.sim.worldgen.tunnel_network`` when it exists; it is not required.)

``--baseline DIR`` (a delve source tree, e.g. ``git worktree add /tmp/gb_base <commit>``)
also times that tree's local planner against this one, interleaved on the same inputs
(ANYmal C, 1000 vertices, ``--runs`` rounds of the iterations), and prints the medians
and the median ratio of the pairs (pairs share the machine's load) and whether both
planned the same paths and gains.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import importlib
import shlex
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from delve.planners.gbplanner2 import GBPlannerConfig, LocalPlanner
from delve.planners.gbplanner2.synthetic import Tunnel, tunnel_network
from delve.planners.occupancy import UNKNOWN, Grid


def robot_positions(tunnels: list[Tunnel], count: int, rng: np.random.Generator, height_m: float) -> np.ndarray:
    """Points on the tunnels' floor centre lines, ``height_m`` above the floor, spread
    over the network (long tunnels are picked more often)."""
    starts = np.array([t.start for t in tunnels])
    ends = np.array([t.end for t in tunnels])
    lengths = np.linalg.norm(ends - starts, axis=1)
    pick = rng.choice(len(tunnels), size=count, p=lengths / lengths.sum())
    s = rng.uniform(0.15, 0.85, size=count)[:, None]
    pts = starts[pick] + (ends[pick] - starts[pick]) * s
    pts[:, 2] += height_m
    return pts


def explored_view(full: Grid, position: np.ndarray, radius_m: float) -> Grid:
    """The network as mapped by a robot that has seen everything within ``radius_m``."""
    occ = full.occupancy.copy()
    vs = full.voxel_size_m
    x = full.origin[0] + (np.arange(occ.shape[0]) + 0.5) * vs - position[0]
    y = full.origin[1] + (np.arange(occ.shape[1]) + 0.5) * vs - position[1]
    far_xy = (x[:, None] ** 2 + y[None, :] ** 2) > radius_m**2
    occ[far_xy] = UNKNOWN
    return Grid(occ, full.origin.copy(), vs)


def sim_world(voxel_size_m: float, seed: int) -> tuple[Grid, list[Tunnel]]:
    """The simulator's generated mine (``delve.sim.worldgen.tunnel_network``), as a
    shell map (rock OCCUPIED where it borders air), with its centreline as tunnels."""
    from delve.sim.worldgen import tunnel_network as sim_tunnel_network  # optional
    from scipy import ndimage

    world = sim_tunnel_network(seed, voxel_size_m=voxel_size_m)
    free = world.free
    near = ndimage.binary_dilation(free, structure=np.ones((3, 3, 3), bool))
    occ = np.full(free.shape, UNKNOWN, np.int8)
    occ[near] = 1
    occ[free] = 0
    tunnels = [Tunnel(tuple(world.centreline.nodes[u]["pos"]), tuple(world.centreline.nodes[v]["pos"]))
               for u, v in world.centreline.edges]
    return Grid(occ, world.origin.copy(), world.voxel_size_m), tunnels


def run(config: GBPlannerConfig, world: Grid, tunnels: list[Tunnel], iterations: int, seed: int,
        mapped_radius_m: float, height_m: float) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    positions = robot_positions(tunnels, iterations + 1, rng, height_m)
    planner = LocalPlanner(config)
    rows: dict[str, list[float]] = {k: [] for k in ("total", "cpu", "graph", "gain", "dijkstra", "other", "vertices",
                                                    "gain_evals")}
    for i, p in enumerate(positions):
        grid = explored_view(world, p, mapped_radius_m)
        t = time.perf_counter()
        c = time.process_time()
        res = planner.plan(grid, p, np.random.default_rng(seed * 1000 + i), yaw_rad=0.0)
        cpu = time.process_time() - c
        total = time.perf_counter() - t
        if i == 0:
            continue  # warm-up (first-call costs of numpy/scipy)
        d = res.diagnostics
        graph = d.bound_s + d.map_s + d.graph_s
        rows["total"].append(total)
        rows["cpu"].append(cpu)
        rows["graph"].append(graph)
        rows["gain"].append(d.gain_s)
        rows["dijkstra"].append(d.shortest_paths_s)
        rows["other"].append(total - graph - d.gain_s - d.shortest_paths_s)
        rows["vertices"].append(d.num_vertices)
        rows["gain_evals"].append(d.num_gain_evaluations)
        if not res.ok:
            print(f"  note: iteration {i}: no path ({res.reason})")
    return {k: np.asarray(v) for k, v in rows.items()}


def baseline_package(tree: Path):
    """The ``planners`` package of another delve source tree, imported as
    ``delve_baseline.planners`` (planners import nothing else of delve)."""
    root = Path(tempfile.mkdtemp(prefix="delve_baseline_"))
    (root / "delve_baseline").mkdir()
    (root / "delve_baseline" / "__init__.py").write_text("")
    (root / "delve_baseline" / "planners").symlink_to(tree.resolve() / "planners")
    sys.path.insert(0, str(root))
    return importlib.import_module("delve_baseline.planners")


def paired(baseline_tree: Path, world: Grid, tunnels: list[Tunnel], iterations: int, runs: int, seed: int,
           mapped_radius_m: float) -> list[str]:
    """Wall and CPU time of one iteration of the baseline tree's local planner and of
    this one (ANYmal C, 1000 vertices), interleaved, and whether they planned the same."""
    old = baseline_package(baseline_tree)
    importlib.import_module("delve_baseline.planners.gbplanner2")
    old_planner = old.gbplanner2.LocalPlanner(old.gbplanner2.GBPlannerConfig.anymal_c())
    new_planner = LocalPlanner(GBPlannerConfig.anymal_c())
    positions = robot_positions(tunnels, iterations + 1, np.random.default_rng(seed), 0.5)
    times: dict[str, list[tuple[float, float]]] = {"old": [], "new": []}
    same = True
    for rep in range(runs):
        for i, p in enumerate(positions):
            grid = explored_view(world, p, mapped_radius_m)
            grids = {"new": grid, "old": old.occupancy.Grid(grid.occupancy, grid.origin, grid.voxel_size_m)}
            plans = {"new": new_planner, "old": old_planner}
            out = {}
            for who in (("old", "new") if (rep + i) % 2 == 0 else ("new", "old")):
                t, c = time.perf_counter(), time.process_time()
                out[who] = plans[who].plan(grids[who], p, np.random.default_rng(seed * 1000 + i), yaw_rad=0.0)
                if i > 0:  # the first position is a warm-up
                    times[who].append((time.perf_counter() - t, time.process_time() - c))
            same &= out["old"].gain == out["new"].gain and (
                (out["old"].path is None and out["new"].path is None)
                or np.array_equal(out["old"].path, out["new"].path))
    o, n = np.array(times["old"]), np.array(times["new"])
    return [
        f"baseline {baseline_tree}: ANYmal C, 1000 vertices, {len(o)} pairs (interleaved), median",
        f"{'':<10}{'wall ms':>9}{'cpu ms':>9}",
        f"{'baseline':<10}{np.median(o[:, 0]) * 1e3:>9.1f}{np.median(o[:, 1]) * 1e3:>9.1f}",
        f"{'this tree':<10}{np.median(n[:, 0]) * 1e3:>9.1f}{np.median(n[:, 1]) * 1e3:>9.1f}",
        f"{'ratio':<10}{np.median(n[:, 0] / o[:, 0]):>9.3f}{np.median(n[:, 1] / o[:, 1]):>9.3f}"
        "   (median of the pairs' ratios, this tree / baseline)",
        f"same paths and gains: {'yes' if same else 'NO'}",
    ]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=12, help="timed iterations per row (>= 10)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mapped-radius", type=float, default=40.0, help="m of tunnel mapped around the robot")
    ap.add_argument("--world", choices=("synthetic", "sim"), default="synthetic",
                    help="synthetic: this script's tunnel grid; sim: delve.sim.worldgen.tunnel_network (optional)")
    ap.add_argument("--baseline", type=Path, metavar="DIR",
                    help="a delve source tree whose local planner to time against this one (see the docstring)")
    ap.add_argument("--runs", type=int, default=3, help="rounds of the iterations with --baseline")
    args = ap.parse_args(argv)
    if args.iterations < 1:
        ap.error("--iterations must be >= 1")
    print("$ " + " ".join(shlex.quote(a) for a in [Path(sys.executable).name, *sys.argv]))
    print()
    worlds = {}
    t = time.perf_counter()
    for vs in (0.2, 0.3):
        worlds[vs] = sim_world(vs, args.seed) if args.world == "sim" else tunnel_network(voxel_size_m=vs)
    g02 = worlds[0.2][0]
    length = sum(np.linalg.norm(np.subtract(tn.end, tn.start)) for tn in worlds[0.2][1])
    kind = ("delve.sim.worldgen.tunnel_network" if args.world == "sim"
            else "crossing 4 m x 3.5 m tunnels on two levels joined by ramps")
    print(f"world: {kind}; {len(worlds[0.2][1])} segments, {length:.0f} m of tunnel in "
          f"{g02.shape[0] * 0.2:.0f} x {g02.shape[1] * 0.2:.0f} m; grids {g02.shape} at 0.2 m and "
          f"{worlds[0.3][0].shape} at 0.3 m (built in {time.perf_counter() - t:.1f} s); "
          f"mapped within {args.mapped_radius:.0f} m of the robot; {args.iterations} iterations per row; "
          f"1 BLAS thread; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print()
    cases = [
        ("ANYmal C (legged)", GBPlannerConfig.anymal_c(), 0.2, 0.5),
        ("ANYmal C (legged)", GBPlannerConfig.anymal_c(num_vertices_max=500), 0.2, 0.5),
        ("RMF-Obelix (aerial)", GBPlannerConfig.rmf_obelix(), 0.3, 1.5),
        ("RMF-Obelix (aerial)", GBPlannerConfig.rmf_obelix(num_vertices_max=1000, num_edges_max=12000), 0.3, 1.5),
    ]
    header = (f"{'preset':<20} {'voxel':>5} {'N_V,max':>7} {'vertices':>8} {'gain casts':>10} | "
              f"{'total ms':>15} | {'cpu ms':>15} | {'graph ms':>13} | {'gain ms':>13} | {'dijkstra ms':>11} | "
              f"{'other ms':>11}")
    print("median / p90 of each column (wall clock, except cpu = this process's CPU time for the whole iteration);")
    print("graph = bounding box + local map + Algorithm 2; gain = Algorithm 3; other = path selection + improvement")
    print(header)
    print("-" * len(header))
    for name, cfg, vs, h in cases:
        world, tunnels = worlds[vs]
        r = run(cfg, world, tunnels, args.iterations, args.seed, args.mapped_radius, h)

        def mp(x: np.ndarray) -> str:
            return f"{np.median(x) * 1e3:6.1f} / {np.percentile(x, 90) * 1e3:6.1f}"

        print(f"{name:<20} {vs:>5.1f} {cfg.num_vertices_max:>7d} {np.median(r['vertices']):>8.0f} "
              f"{np.median(r['gain_evals']):>10.0f} | {mp(r['total']):>15} | {mp(r['cpu']):>15} | {mp(r['graph']):>13} | "
              f"{mp(r['gain']):>13} | {mp(r['dijkstra']):>11} | {mp(r['other']):>11}")
    if args.baseline is not None:
        print()
        print("\n".join(paired(args.baseline, *worlds[0.2], args.iterations, args.runs, args.seed, args.mapped_radius)))
    print()
    print("paper (Table I): 605.53 ms at 1000 vertices (ANYmal C, i7-8850H, 6 cores); "
          "278.59 ms at 500 vertices (RMF-Obelix, ARM A311D)")
    print("goal: median <= 100 ms at 1000 vertices on one core")


if __name__ == "__main__":
    main()
