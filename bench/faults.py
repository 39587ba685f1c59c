"""A fault campaign: seeded random faults over the shipped scenarios, checking that
nothing crashes and nothing is lost.

Each run takes one shipped scenario, shortened to a campaign duration, and injects
one to three faults drawn from a seeded generator: a kind the scenario's world and
robots accept (the scenario loader's own checks decide), a target, a time and, where
the kind can end, a duration; then runs it in-process and writes its outputs. Every
run is checked against these invariants:

* ``ran``: no exception, a report written, and it is strict JSON;
* ``delivered``: every robot that survived, finished its tree and can reach the base
  station has nothing left undelivered (messages, map voxels; COPS: locations and
  map chunks). A survivor that cannot reach the base at the end (stranded out of
  range, or still exploring when the run stops) holds its information: shown as
  ``held``, not a loss;
* ``counted``: what each lost robot held is counted as undelivered: the report's
  ``messages_undelivered`` is what waits in its outbox and ``map_voxels_undelivered``
  (COPS: ``locations_undelivered``) what it knows that the base station does not,
  recomputed here from the simulation; and no robot's message vanished: every one
  it sent was delivered, dropped by a datagram radio, or still waits;
* ``explained``: a run that did not succeed gives reasons, every FAILURE tree and
  every lost robot is named in them, and a timed-out run says so.

    .venv/bin/python bench/faults.py [--runs-per-scenario 4] [--seed 0] [--jobs 2]
                                     [--scenarios demo cerberus_wifi ...] [--out DIR]

Prints the command, one row per run as it finishes, then the invariants over all
runs and the runs per fault kind. Exit status 1 when an invariant failed.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import json
import multiprocessing
import random
import shlex
import sys
import tempfile
import time
import traceback
from collections import Counter, defaultdict
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"
#: Campaign duration of each shipped scenario (sim s): long enough for a robot to
#: explore, meet its faults and often come home, short enough for dozens of runs.
DURATION_S = {
    "aerial_cave": 400, "cerberus_budget": 500, "cerberus_goal_unreachable": 500, "cerberus_inspection": 500,
    "cerberus_map_reset": 500, "cerberus_modes": 500, "cerberus_slopes_shaft": 500, "cerberus_watchdog": 500,
    "cerberus_wifi": 450, "cops_mine": 600, "cops_tunnel": 8000, "demo": 500, "gbplanner_demo": 500,
    "scanned_mine": 500,
}
INVARIANTS = ("ran", "delivered", "counted", "explained")


@dataclass
class Run:
    """One campaign run and what its checks found."""

    index: int
    scenario: str
    faults: list[dict[str, Any]]
    wall_s: float = 0.0
    sim_s: float = 0.0
    succeeded: bool = False
    timed_out: bool = False
    lost: list[str] = field(default_factory=list)
    held: list[str] = field(default_factory=list)
    violations: dict[str, list[str]] = field(default_factory=dict)


# ---- drawing faults ---------------------------------------------------------------------
def draw_fault(rng: random.Random, kind: str, robots: list[str], duration_s: float) -> dict[str, Any]:
    """One fault entry of ``kind`` (as a scenario would write it), at a random time."""
    from delve.executive.faults import FAULT_KINDS
    from delve.executive.faults.base import BASE_STATION, LINK, NEVER, REQUIRED, ROBOT

    cls = FAULT_KINDS[kind]
    entry: dict[str, Any] = {"at_s": round(rng.uniform(0.05, 0.6) * duration_s, 1), "kind": kind}
    target = rng.choice(cls.TARGETS)
    if target == ROBOT:
        entry["robot"] = rng.choice(robots)
    elif target == LINK:
        entry["link"] = sorted(rng.sample(robots + ["base"], 2))
    elif target == BASE_STATION and cls.TARGETS != (BASE_STATION,):
        entry["base_station"] = True
    if cls.DURATION == REQUIRED or (cls.DURATION != NEVER and rng.random() < 0.7):
        entry["duration_s"] = round(rng.uniform(10.0, 0.3 * duration_s), 1)
    params = {"battery_drop": lambda: {"drop_fraction": round(rng.uniform(0.3, 1.0), 2)},
              "lidar_degraded": lambda: {"range_m": round(rng.uniform(2.0, 10.0), 1),
                                         "ray_fraction": round(rng.uniform(0.1, 1.0), 2)},
              "localisation_drift": lambda: {"rate_mps": round(rng.uniform(0.02, 0.2), 3),
                                             "heading_deg": round(rng.uniform(0.0, 360.0))},
              "planner_slow": lambda: {"delay_s": round(rng.uniform(5.0, 60.0), 1)},
              "map_artifact": lambda: {"radius_m": round(rng.uniform(0.5, 2.5), 1)}}
    entry.update(params.get(kind, dict)())
    return entry


def draw_faults(rng: random.Random, scenario: Any, duration_s: float) -> list[Any]:
    """One to three faults the scenario accepts, as :class:`Fault` objects."""
    from delve.executive.errors import DelveError
    from delve.executive.faults import FAULT_KINDS, FaultContext
    from delve.executive.faults.loader import load_fault
    from delve.executive.tree_loader import check_tree
    from delve.executive.yamlio import YamlDict, YamlList

    robots = [r.name for r in scenario.robots]
    ctx = FaultContext(scenario.path, {r.name: r for r in scenario.robots},
                       {r.name: check_tree(r.tree) for r in scenario.robots}, scenario.world_backend,
                       scenario.base_tree is not None)
    faults, wanted = [], rng.randint(1, 3)
    for _ in range(100):
        if len(faults) == wanted:
            break
        entry = draw_fault(rng, rng.choice(sorted(FAULT_KINDS)), robots, duration_s)
        item = YamlDict({k: YamlList(v) if isinstance(v, list) else v for k, v in entry.items()})
        try:
            faults.append(load_fault(item, None, ctx))
        except DelveError:
            continue  # a kind this scenario's world or robots do not take: draw again
    return sorted(faults, key=lambda f: f.at_s)


# ---- checking a run ---------------------------------------------------------------------
def _held(mission: Any, name: str) -> dict[str, int]:
    """What robot ``name`` holds that the base station does not, recomputed from the
    simulation (not from the report)."""
    from delve.executive.teams.cops import Cops, _cops_skill
    from delve.sim.voxel_map import UNKNOWN

    robot = mission.robots[name]
    out = {"messages": robot.radio.pending}
    base_map = getattr(mission.backend, "base_map", None)
    if base_map is not None:
        known = robot.onboard_map.occupancy != UNKNOWN
        out["map_voxels"] = int((known & (base_map.occupancy == UNKNOWN)).sum())
    if isinstance(mission.team, Cops):
        skill = _cops_skill(mission.agents[name].root)
        st = skill.stored_state() if skill is not None else None
        held = set(st.knowledge.topology.explored) if st is not None else set()
        out["locations"] = len(held - mission.team.explored_at_base())
    return out


UNDELIVERED = {"messages": "messages_undelivered", "map_voxels": "map_voxels_undelivered",
               "locations": "locations_undelivered", "map_chunks": "map_chunks_undelivered"}
#: How the table abbreviates what a robot holds undelivered.
SHORT = {"messages": "msg", "map_voxels": "vox", "locations": "loc", "map_chunks": "chk"}


def check(mission: Any, report: dict[str, Any], run: Run) -> None:
    """Fill ``run`` from a finished mission and its report, and its violations."""
    from delve.executive.worlds import BASE

    bad: dict[str, list[str]] = defaultdict(list)
    outcome = report["outcome"]
    run.sim_s, run.succeeded, run.timed_out = report["sim_time_s"], report["succeeded"], outcome["timed_out"]
    run.lost = sorted(outcome["lost"])
    reasons = " | ".join(outcome["reasons"])
    for r in report["robots"]:
        name = r["name"]
        ep = mission.radio.endpoints[name]
        dropped = getattr(ep, "dropped", 0)
        if ep.sent != ep.delivered + dropped + ep.pending:
            bad["counted"].append(f"{name}: sent {ep.sent} != delivered {ep.delivered} + dropped {dropped} "
                                  f"+ waiting {ep.pending}")
        left = {k: r.get(field, 0) for k, field in UNDELIVERED.items() if r.get(field)}
        if name in outcome["lost"]:
            held = _held(mission, name)
            for k, v in held.items():
                if r.get(UNDELIVERED[k]) != v:
                    bad["counted"].append(f"{name}: {UNDELIVERED[k]} {r.get(UNDELIVERED[k])}, holds {v}")
            if not outcome["lost"][name]:
                bad["explained"].append(f"{name}: lost without a reason")
            continue
        finished = r["final_status"] in ("SUCCESS", "FAILURE")
        reachable = mission.radio.linked(name, BASE)
        if left and finished and reachable:
            bad["delivered"].append(f"{name}: {left} undelivered though linked to the base")
        elif left:
            run.held.append(f"{name}:{'+'.join(f'{v}{SHORT[k]}' for k, v in left.items())}")
        if r["final_status"] == "FAILURE" and name not in reasons:
            bad["explained"].append(f"{name}: FAILURE without a reason")
    if not report["succeeded"] and not outcome["reasons"]:
        bad["explained"].append("failed without a reason")
    if outcome["timed_out"] and "had not finished" not in reasons and not report["succeeded"]:
        bad["explained"].append("timed out without saying so")
    run.violations = dict(bad)


def run_one(job: tuple[int, str, int, str]) -> Run:
    """Run campaign run ``index`` (scenario, campaign seed) into ``out``."""
    index, name, seed, out = job
    from delve.executive.outputs import write_outputs
    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario

    rng = random.Random(f"{seed}/{index}/{name}")
    duration = float(DURATION_S.get(name, 500))
    run = Run(index, name, [])
    started = time.perf_counter()
    try:
        scenario = load_scenario(SCENARIOS / f"{name}.yaml")
        faults = draw_faults(rng, scenario, duration)
        run.faults = [f.fields() | {"at_s": f.at_s} for f in faults]
        mission = Mission(replace(scenario, faults=list(scenario.faults) + faults), duration_s=duration)
        mission.run()
        folder = Path(out) / f"{index:03d}_{name}"
        report = write_outputs(mission, folder, time.perf_counter() - started)
        json.loads((folder / "report.json").read_text(), parse_constant=lambda c: 1 / 0)
        check(mission, report, run)
    except Exception:  # noqa: BLE001 - a crash is what the campaign looks for
        run.violations = {"ran": [traceback.format_exc(limit=6).strip().splitlines()[-1]]}
        (Path(out) / f"{index:03d}_{name}.traceback").write_text(traceback.format_exc())
    run.wall_s = time.perf_counter() - started
    return run


# ---- the table ---------------------------------------------------------------------------
def fault_text(f: dict[str, Any]) -> str:
    who = f.get("robot") or ("<->".join(f["link"]) if "link" in f else "base")
    end = f"+{f['duration_s']:g}" if "duration_s" in f else ""
    return f"{f['kind']}@{f['at_s']:g}{end}:{who}"


def row(r: Run) -> str:
    verdict = "ok" if not r.violations else "FAIL " + ",".join(r.violations)
    state = "succeeded" if r.succeeded else ("timed out" if r.timed_out else "failed")
    faults = " ".join(fault_text(f) for f in r.faults)
    lost, held = ",".join(r.lost) or "-", " ".join(r.held) or "-"
    return (f"{r.index:>3} {r.scenario:<26} {faults:<78} {r.sim_s:>6.0f} {r.wall_s:>6.1f} {state:<9} "
            f"{lost:<8} {held:<22} {verdict}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs-per-scenario", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0, help="the campaign's seed (faults drawn from it)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--scenarios", nargs="*", default=sorted(DURATION_S), help="shipped scenario names")
    ap.add_argument("--out", type=Path, help="where the runs' outputs go (default: a temporary folder)")
    args = ap.parse_args(argv)
    print("$ .venv/bin/python bench/faults.py " + shlex.join(argv if argv is not None else sys.argv[1:]))
    out = args.out or Path(tempfile.mkdtemp(prefix="delve-faults-"))
    jobs = [(i, name, args.seed, str(out)) for i, (k, name) in enumerate(
        (k, n) for k in range(args.runs_per_scenario) for n in args.scenarios)]
    print(f"{len(jobs)} runs over {len(args.scenarios)} shipped scenarios, campaign seed {args.seed}, "
          f"outputs in {out}\n")
    head = "faults (kind@at_s+duration_s:target)"
    print(f"{'#':>3} {'scenario':<26} {head:<78} {'sim s':>6} {'wall s':>6} {'outcome':<9} {'lost':<8} "
          f"{'held':<22} invariants")
    started = time.perf_counter()
    runs = []
    if args.jobs > 1:
        with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
            for r in pool.imap_unordered(run_one, jobs, chunksize=1):
                runs.append(r)
                print(row(r), flush=True)
    else:
        for job in jobs:
            runs.append(run_one(job))
            print(row(runs[-1]), flush=True)
    runs.sort(key=lambda r: r.index)
    print(f"\n{len(runs)} runs in {time.perf_counter() - started:.0f} s wall")
    print(f"\n{'invariant':<12} {'held':>5} {'violated':>9}")
    for name in INVARIANTS:
        failed = [r for r in runs if name in r.violations]
        print(f"{name:<12} {len(runs) - len(failed):>5} {len(failed):>9}")
        for r in failed:
            for v in r.violations[name]:
                print(f"    run {r.index} {r.scenario}: {v}")
    kinds: dict[str, Counter] = defaultdict(Counter)
    for r in runs:
        for kind in {f["kind"] for f in r.faults}:
            kinds[kind]["runs"] += 1
            kinds[kind]["violations"] += bool(r.violations)
            kinds[kind]["succeeded"] += r.succeeded
            kinds[kind]["lost"] += bool(r.lost)
    print(f"\n{'fault kind':<20} {'runs':>5} {'succeeded':>10} {'a robot lost':>13} {'violations':>11}")
    for kind in sorted(kinds):
        c = kinds[kind]
        print(f"{kind:<20} {c['runs']:>5} {c['succeeded']:>10} {c['lost']:>13} {c['violations']:>11}")
    return 1 if any(r.violations for r in runs) else 0


if __name__ == "__main__":
    sys.exit(main())
