"""Memory and load time of a large mine: the world, its mesh, and missions on it.

    .venv/bin/python bench/memory.py [--region-m 300 500] [--length-m 4000] [--spacing-m 40]
                                     [--robots 1 5] [--sim-s 90] [--runs 3]

Builds a single-level ``tunnel_network`` spread over ``--region-m`` (x, y) at 0.2 m
voxels, writes its rock mesh to a PLY and loads that as a mesh world (a closed inner
surface), then runs a mission of ``--sim-s`` seconds with each number of legged
robots in ``--robots`` (the frontier explorer, independent robots). Each phase runs in
a fresh process, so that its peak resident memory (``ru_maxrss``) is its own; load
times are the median over ``--runs`` processes. Prints the bytes of each large array
at the end of each phase: the world's free space, its region labels and reachable
space, the ray-casting scene (resident memory it added), each robot's onboard map,
the base station's map, the coverage bookkeeping and the planners' caches.
"""
from __future__ import annotations

import argparse
import json
import pickle
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

MB = 1e6


def peak_rss_mb() -> float:
    """This process's peak resident memory so far (MB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / MB


def rss_mb() -> float:
    """This process's resident memory now (MB)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / MB


def array_bytes(obj: Any, seen: set[int], depth: int = 4) -> int:
    """Bytes of the numpy arrays reachable from ``obj`` through attributes, dicts,
    lists and tuples (``depth`` levels), each array counted once (``seen``)."""
    if id(obj) in seen or depth < 0:
        return 0
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        return obj.nbytes if obj.base is None or id(obj.base) not in seen else 0
    if isinstance(obj, dict):
        items = list(obj.values())
    elif isinstance(obj, (list, tuple)):
        items = list(obj)
    elif hasattr(obj, "__dict__") and not isinstance(obj, type):
        items = list(vars(obj).values())
    else:
        return 0
    return sum(array_bytes(v, seen, depth - 1) for v in items)


def world_arrays(world) -> dict[str, float]:
    """MB of the world's large arrays (free space, labels, reachable space, mesh)."""
    return {
        "world.free": world.free.nbytes / MB,
        "world labels": (world._labels.nbytes if world._labels is not None else 0) / MB,
        "world reachable": sum(np.asarray(r).nbytes for r in world._reachable.values()) / MB,
        "world mesh": (np.asarray(world.mesh.vertices).nbytes + np.asarray(world.mesh.triangles).nbytes) / MB,
    }


# ------------------------------------------------------------------------ phases
def phase_world(args) -> dict:
    """Generate the mine, build its scene and labels; pickle it to ``--cache``."""
    from delve.sim import worldgen
    t = time.perf_counter()
    world = worldgen.tunnel_network(args.seed, total_length_m=args.length_m, spacing_m=args.spacing_m,
                                    max_slope_deg=args.slope_deg, loops=args.loops,
                                    region_m=tuple(args.region_m), voxel_size_m=args.voxel_m)
    generate_s = time.perf_counter() - t
    before = rss_mb()
    t = time.perf_counter()
    _ = world.scene
    scene_s, scene_mb = time.perf_counter() - t, rss_mb() - before
    t = time.perf_counter()
    world.reachable_free(world.start)
    reach_s = time.perf_counter() - t
    out = {"generate_s": generate_s, "scene_s": scene_s, "reachable_s": reach_s,
           "load_s": generate_s + scene_s + reach_s, "peak_mb": peak_rss_mb(),
           "shape": world.shape, "voxels": int(np.prod(world.shape)),
           "free_voxels": int(np.count_nonzero(world.free)),
           "extent_m": (world.bounds_max - world.bounds_min).round(1).tolist(),
           "triangles": len(world.mesh.triangles), "arrays": {**world_arrays(world), "world scene": scene_mb}}
    if args.cache:
        with open(Path(args.cache) / "world.pkl", "wb") as f:
            pickle.dump(world, f, protocol=pickle.HIGHEST_PROTOCOL)
        world.save_mesh(Path(args.cache) / "mine.ply")
    return out


def phase_mesh(args) -> dict:
    """Load the mine's mesh file as a world (a closed inner surface)."""
    from delve.sim.worldfile import from_file
    t = time.perf_counter()
    world = from_file(Path(args.cache) / "mine.ply", voxel_size_m=args.voxel_m)
    file_s = time.perf_counter() - t
    t = time.perf_counter()
    _ = world.scene
    world.reachable_free(world.start)
    return {"load_s": file_s + time.perf_counter() - t, "file_s": file_s, "peak_mb": peak_rss_mb(),
            "shape": world.shape, "voxels": int(np.prod(world.shape)),
            "free_voxels": int(np.count_nonzero(world.free)), "arrays": world_arrays(world)}


SCENARIO = """name: memory_{robots}
seed: {seed}
duration_s: {sim_s}
dt_s: 0.1
world: {{generator: tunnel_network, total_length_m: {length_m}}}
base_station: {{tree: {trees}/base_station.yaml}}
radio: {{range_m: 80, loss: 0.05}}
robots:
"""
ROBOT = "  - {{name: r{i}, platform: legged, tree: {trees}/frontier_explorer.yaml, endurance_s: 1800}}\n"


def phase_mission(args) -> dict:
    """Run ``--sim-s`` seconds of a mission with ``--robots`` legged robots on the
    pickled mine."""
    from delve import TREES_DIR
    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario
    from delve.planners.navgraph import Voxels
    n = args.robots[0]
    t = time.perf_counter()
    with open(Path(args.cache) / "world.pkl", "rb") as f:
        world = pickle.load(f)
    unpickle_s = time.perf_counter() - t
    text = SCENARIO.format(robots=n, seed=args.seed, sim_s=args.sim_s, length_m=args.length_m, trees=TREES_DIR)
    text += "".join(ROBOT.format(i=i + 1, trees=TREES_DIR) for i in range(n))
    path = Path(args.cache) / f"memory_{n}.yaml"
    path.write_text(text)
    peaks = {"unpickled": peak_rss_mb()}
    t = time.perf_counter()
    mission = Mission(load_scenario(path), world=world)
    setup_s = time.perf_counter() - t
    peaks["set up"] = peak_rss_mb()
    t = time.perf_counter()
    mission.run()
    run_s = time.perf_counter() - t
    peaks["run"] = peak_rss_mb()
    backend = mission.backend
    arrays = world_arrays(world)
    arrays["world scene"] = float("nan")
    seen = {id(world.free)}
    maps = [r.onboard_map for r in backend.robots.values()]
    arrays["onboard map, each"] = statistics.mean(array_bytes(m, seen) for m in maps) / MB
    arrays["base station map"] = array_bytes(backend.base_map, seen) / MB
    arrays["coverage truth"] = backend.truth.nbytes / MB
    last = Voxels._last_free
    arrays["navgraph free-voxel cache"] = (array_bytes(last, seen) if last else 0) / MB
    skip = seen | {id(m) for m in maps} | {id(backend.base_map), id(world)}
    services = sum(array_bytes(agent.ctx.services, skip) for agent in mission.agents.values())
    arrays["other services (all agents)"] = services / MB
    samples = mission.state.samples
    return {"robots": n, "unpickle_s": unpickle_s, "setup_s": setup_s, "run_s": run_s,
            "sim_s": mission.clock.now_s, "peak_mb": peak_rss_mb(), "peaks": peaks, "arrays": arrays,
            "coverage": samples[-1].team if samples else None}


PHASES = {"world": phase_world, "mesh": phase_mesh, "mission": phase_mission}


# ------------------------------------------------------------------------ driver
def run_phase(name: str, args, extra: list[str]) -> dict:
    """Run one phase in a fresh Python process and return what it printed (JSON)."""
    cmd = [sys.executable, __file__, "--phase", name, "--cache", args.cache, "--seed", str(args.seed),
           "--region-m", *map(str, args.region_m), "--length-m", str(args.length_m),
           "--spacing-m", str(args.spacing_m), "--slope-deg", str(args.slope_deg), "--loops", str(args.loops),
           "--voxel-m", str(args.voxel_m), "--sim-s", str(args.sim_s), "--max-voxels", str(args.max_voxels), *extra]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stderr)
        raise SystemExit(f"phase {name} failed (exit {done.returncode})")
    return json.loads(done.stdout.strip().splitlines()[-1])


def median_of(runs: list[dict], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def print_table(world: list[dict], mesh: list[dict], missions: list[dict]) -> None:
    w = world[0]
    print(f"mine: {w['extent_m'][0]:.0f} x {w['extent_m'][1]:.0f} x {w['extent_m'][2]:.0f} m box, "
          f"{w['shape'][0]} x {w['shape'][1]} x {w['shape'][2]} = {w['voxels'] / 1e6:.0f} M voxels, "
          f"{w['free_voxels'] / 1e6:.1f} M free, {w['triangles']:,} triangles")
    print()
    print(f"{'load (median of ' + str(len(world)) + ')':34s} {'seconds':>9s} {'peak MB':>9s}")
    print(f"{'generate the mine':34s} {median_of(world, 'generate_s'):9.1f}")
    print(f"{'  + scene + reachable space':34s} {median_of(world, 'load_s'):9.1f} {median_of(world, 'peak_mb'):9.0f}")
    if mesh:
        print(f"{'load its mesh file (closed)':34s} {median_of(mesh, 'load_s'):9.1f} {median_of(mesh, 'peak_mb'):9.0f}")
    print()
    head = f"{'arrays (MB)':34s} {'world':>9s}" + "".join(f" {str(m['robots']) + ' robot(s)':>11s}" for m in missions)
    print(head)
    keys = list(world[0]["arrays"]) + [k for k in missions[0]["arrays"] if k not in world[0]["arrays"]] if missions \
        else list(world[0]["arrays"])
    for k in keys:
        cells = [world[0]["arrays"].get(k)] + [m["arrays"].get(k) for m in missions]
        print(f"{k:34s}" + "".join(f" {c:9.1f}  " if isinstance(c, float) and c == c else f" {'':9s}  "
                                   for c in cells))
    print()
    for m in missions:
        rt = m["sim_s"] / m["run_s"] if m["run_s"] else float("nan")
        print(f"mission, {m['robots']} robot(s), {m['sim_s']:.0f} s sim: set-up {m['setup_s']:.1f} s, "
              f"run {m['run_s']:.1f} s ({rt:.0f}x real time), peak {m['peak_mb']:.0f} MB "
              f"(after " + ", ".join(f"{k} {v:.0f}" for k, v in m["peaks"].items()) + ")")
    if len(missions) >= 2:
        a, b = missions[0], missions[-1]
        per = (b["peak_mb"] - a["peak_mb"]) / (b["robots"] - a["robots"])
        print(f"peak memory per added robot: {per:.0f} MB")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--region-m", type=float, nargs=2, default=[300.0, 500.0])
    ap.add_argument("--length-m", type=float, default=4000.0)
    ap.add_argument("--spacing-m", type=float, default=40.0)
    ap.add_argument("--slope-deg", type=float, default=15.0)
    ap.add_argument("--loops", type=int, default=8)
    ap.add_argument("--voxel-m", type=float, default=0.2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--robots", type=int, nargs="+", default=[1, 5])
    ap.add_argument("--sim-s", type=float, default=90.0)
    ap.add_argument("--runs", type=int, default=3, help="processes per load phase (median)")
    ap.add_argument("--no-mesh", action="store_true", help="skip loading the mine's mesh file")
    ap.add_argument("--max-voxels", type=float, default=0,
                    help="raise the world size limit (sim/limits.py) for this run, to measure beyond it")
    ap.add_argument("--phase", choices=sorted(PHASES), help=argparse.SUPPRESS)
    ap.add_argument("--cache", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.max_voxels:
        from delve.sim import limits
        limits.MAX_WORLD_VOXELS = int(args.max_voxels)
    if args.phase:
        print(json.dumps(PHASES[args.phase](args)))
        return 0
    print(f"$ {' '.join(sys.argv)}")
    with open("/proc/loadavg") as f:
        print(f"load average at start: {' '.join(f.read().split()[:3])}")
    with tempfile.TemporaryDirectory() as tmp:
        args.cache = tmp
        world = [run_phase("world", args, []) for _ in range(args.runs)]
        mesh = [] if args.no_mesh else [run_phase("mesh", args, []) for _ in range(args.runs)]
        missions = [run_phase("mission", args, ["--robots", str(n)]) for n in args.robots]
    print_table(world, mesh, missions)
    with open("/proc/loadavg") as f:
        print(f"load average at end: {' '.join(f.read().split()[:3])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
