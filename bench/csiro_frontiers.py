"""Time per CSIRO frontier update (issue 14 items 1-2) against the number of points in range,
beside delve's voxel-grid frontier search (planners/frontier.py) on the same drive.

    flock /tmp/delve-heavy.lock .venv/bin/python bench/csiro_frontiers.py [--runs 3] [--steps 80]
        [--ranges 6 9 12] [--worlds tunnel cave] [--platform legged]

A robot drives along the longest route of a generated world's centreline (tunnel_network and
cave, seed 1), one update every d_min = 1 m. At each step its LiDAR (sim ray casting, the
platform's own sensor) is cast into the world; the hits within d_max go into the CSIRO point cache
and the whole scan into a voxel map like the robot's onboard map. Timed per step:

- ``csiro``: one CSIRO update = the cloud of equation 2 (``PointCache.cloud``) plus
  ``SequentialFrontiers.update`` (visible mesh, segmentation, NotVis, clustering, assignment);
- ``insert``: adding the scan to the point cache (and forgetting voxels beyond d_max);
- ``voxel``: ``frontier_voxels`` + ``frontier_clusters`` over the whole onboard voxel map (the
  nearest-frontier explorer's search, with its default parameters);
- ``integrate``: ``VoxelMap.integrate_scan`` of the same scan (the dense map the voxel search needs).

Each drive runs ``--runs`` times; a step's figure is its median over the runs, and the table gives
the median over the steps whose cloud size (points handed to qhull, sphere points not counted)
falls in each bin, with the voxel search's time divided by the CSIRO update's.
"""
from __future__ import annotations

import argparse
import dataclasses
import statistics
import time

import networkx as nx
import numpy as np

from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.point_cache import PointCache
from delve.planners.csiro.sequential import SequentialFrontiers
from delve.planners.frontier import frontier_clusters, frontier_voxels
from delve.planners.occupancy import Grid
from delve.sim.platforms import PLATFORMS
from delve.sim.voxel_map import VoxelMap
from delve.sim.world import World
from delve.sim.worldgen import cave, tunnel_network

SEED = 1
#: The nearest-frontier explorer's defaults (skills/exploration.py).
CLUSTER_RADIUS_M, MIN_CLUSTER_VOXELS, MAX_EXTENT_M = 0.8, 10, 4.0
BINS = (0, 2000, 4000, 6000, 8000, 12000, 20000, 10**9)


def make_world(name: str) -> World:
    if name == "tunnel":
        return tunnel_network(SEED, total_length_m=200.0)
    return cave(SEED, total_length_m=150.0, shaft=False)


def route(world: World, step_m: float, steps: int) -> np.ndarray:
    """Floor points every ``step_m`` along the longest shortest route from the start node."""
    g = world.centreline
    pos = {n: np.asarray(d["pos"], float) for n, d in g.nodes(data=True)}
    start = min(g.nodes, key=lambda n: float(np.linalg.norm(pos[n] - world.start)))
    dist, paths = nx.single_source_dijkstra(g, start, weight="length_m")
    far = max(sorted(dist), key=lambda n: dist[n])
    pts = np.array([pos[n] for n in paths[far]])
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.arange(0.0, cum[-1], step_m)[:steps]
    return np.stack([np.interp(s, cum, pts[:, a]) for a in range(3)], axis=1)


def drive(world: World, platform: str, params: CsiroFrontierParams, steps: int) -> list[dict]:
    """One drive; per step the cloud size and the four timings (s)."""
    plat = PLATFORMS[platform]
    spec = plat.lidar
    dirs = spec.beam_directions(0.0)
    cache = PointCache(params.d_vox_m)
    seq = SequentialFrontiers(params)
    vmap = VoxelMap(world.shape, world.origin, world.voxel_size_m)
    rows = []
    for k, floor in enumerate(route(world, params.d_min_m, steps)):
        sensor = floor + np.array([0.0, 0.0, plat.body_height_m + spec.mount_height_m])
        ranges = world.cast_rays(np.broadcast_to(sensor, dirs.shape), dirs, spec.range_m).astype(float)
        hit = ranges <= params.d_max_m
        points = sensor + dirs[hit] * ranges[hit, None]

        t0 = time.perf_counter()
        cache.insert(points, sensor)
        cache.prune(sensor, params.d_max_m)
        t1 = time.perf_counter()
        cloud = cache.cloud(sensor, params)
        seq.update(float(k), sensor, cloud)
        t2 = time.perf_counter()
        vmap.integrate_scan(sensor, dirs, ranges, spec.range_m)
        t3 = time.perf_counter()
        grid = Grid(vmap.occupancy, vmap.origin, vmap.voxel_size_m, vmap.free_voxels())
        voxels = frontier_voxels(grid)
        frontier_clusters(grid, voxels, cluster_radius_m=CLUSTER_RADIUS_M, min_cluster_voxels=MIN_CLUSTER_VOXELS,
                          max_extent_m=MAX_EXTENT_M)
        t4 = time.perf_counter()
        rows.append({"points": len(cloud), "frontiers": len(seq.frontiers), "insert": t1 - t0, "csiro": t2 - t1,
                     "integrate": t3 - t2, "voxel": t4 - t3})
    return rows


def per_step_medians(runs: list[list[dict]]) -> list[dict]:
    keys = ("insert", "csiro", "integrate", "voxel")
    out = []
    for step in zip(*runs):
        row = {"points": step[0]["points"], "frontiers": step[0]["frontiers"]}
        row.update({k: statistics.median(r[k] for r in step) for k in keys})
        out.append(row)
    return out


def table(world: str, d_max: float, rows: list[dict]) -> list[str]:
    lines = []
    for lo, hi in zip(BINS[:-1], BINS[1:]):
        sel = [r for r in rows if lo <= r["points"] < hi]
        if not sel:
            continue
        med = {k: 1e3 * statistics.median(r[k] for r in sel) for k in ("insert", "csiro", "integrate", "voxel")}
        pts = statistics.median(r["points"] for r in sel)
        lines.append(f"| {world} | {d_max:g} | {lo}-{hi if hi < 10**9 else ''} | {len(sel)} | {pts:.0f} | "
                     f"{statistics.median(r['frontiers'] for r in sel):.0f} | "
                     f"{med['csiro']:.1f} | {med['insert']:.1f} | {med['voxel']:.1f} | {med['integrate']:.1f} | "
                     f"{med['voxel'] / med['csiro']:.2f} |")
    allm = {k: 1e3 * statistics.median(r[k] for r in rows) for k in ("csiro", "voxel")}
    p90 = 1e3 * float(np.percentile([r["csiro"] for r in rows], 90))
    lines.append(f"| {world} | {d_max:g} | all | {len(rows)} | {statistics.median(r['points'] for r in rows):.0f} | "
                 f"{statistics.median(r['frontiers'] for r in rows):.0f} | "
                 f"{allm['csiro']:.1f} (p90 {p90:.1f}) | | {allm['voxel']:.1f} | | "
                 f"{allm['voxel'] / allm['csiro']:.2f} |")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--steps", type=int, default=80)
    ap.add_argument("--ranges", type=float, nargs="+", default=[6.0, 9.0, 12.0], help="d_max values (m)")
    ap.add_argument("--worlds", nargs="+", default=["tunnel", "cave"], choices=["tunnel", "cave"])
    ap.add_argument("--platform", default="legged", choices=sorted(PLATFORMS))
    args = ap.parse_args()
    spec = PLATFORMS[args.platform].lidar
    half = spec.vertical_fov_deg / 2
    print(f"platform {args.platform}: LiDAR {spec.vertical_fov_deg:g} deg vertical, sphere elevations "
          f"{spec.pitch_deg - half:g}..{spec.pitch_deg + half:g} deg; {args.runs} runs, up to {args.steps} "
          f"updates 1 m apart; times in ms (medians)")
    print("| world | d_max m | points in range | updates | points (median) | frontiers | CSIRO update | "
          "cache insert | voxel frontier search | voxel map integration | voxel / CSIRO |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.worlds:
        world = make_world(name)
        for d_max in args.ranges:
            params = dataclasses.replace(CsiroFrontierParams(), d_max_m=d_max,
                                         elevation_min_deg=spec.pitch_deg - half,
                                         elevation_max_deg=spec.pitch_deg + half)
            rows = per_step_medians([drive(world, args.platform, params, args.steps) for _ in range(args.runs)])
            print("\n".join(table(name, d_max, rows)), flush=True)


if __name__ == "__main__":
    main()
