"""Team exploration: one robot, three robots on their own, and three robots of a team
method (COHORT, CSIRO), on the same worlds and seeds (issues 13 and 14).

Every run is the same team of aerial robots (RMF-Obelix-like, ``--endurance-s``) on
one generated world with artifacts placed by seed, and the base station's radio
reaching only part of it. The methods:

- ``single``: one robot, ``trees/gbplanner_explorer.yaml`` (GBPlanner2, then home);
- ``independent``: three robots with that tree, each on its own (the SubT Final's
  practice; they share maps with the base station, not with each other);
- ``cohort``: three ``trees/cohort_robot.yaml`` robots and the hub
  ``trees/cohort_hub.yaml`` (``team: {strategy: cohort}``, the paper's parameters);
- ``csiro``, ``csiro1``: three (one) ``trees/csiro_uav.yaml`` robots and
  ``trees/csiro_base.yaml`` (``team: {strategy: csiro}``).

The runs are one sweep (``delve.executive.sweep``, docs/sweeps.md) on a Dask
LocalCluster of ``--jobs`` workers (or the cluster at ``--scheduler``); ``--out DIR``
keeps it, and a second start resumes it.

    .venv/bin/python bench/team_exploration.py [--quick] [--seeds 1 2 3 4 5] [--methods ...] [--radio-range-m 60]
        [--jobs 1] [--out DIR]

``--radio-range-m`` sets the base station's radio range (default 60 m: with the link
budget of ``sim/radio.py``, rock and corners cut it to the first tunnels).
``--radio-clear`` lets links reach that range through rock (no obstruction loss and a
20 dB margin at the range): with a range larger than the world (``--radio-clear
--radio-range-m 1000``) every robot has a link everywhere, which shows what COHORT's
coordination gains without its lost-link rule.

Prints one row per run, then per world and method the median of: T90 (sim time to
90 % of the world's free volume observed by the team; "not reached" counts as later
than any time), T90 at base (the same of what the base station knows), final
coverage, coverage known at the base station, the robots' total distance, the overlap
(the share of the team's observed volume that more than one robot observed) and the
artifacts scored; then the ratios of the issue's goals:
COHORT(3)/single T90 (goal <= 0.5) and COHORT(3)/independent(3) T90 (goal <= 0.8), and
the same ratios of T90 at base.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import math
import shlex
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path


ROOT = Path(__file__).resolve().parent.parent
TREES = ROOT / "trees"

#: name -> world section of a scenario (generator parameters, the default 0.2 m voxels).
WORLDS = {
    "tunnel_network": {"generator": "tunnel_network", "total_length_m": 800, "loops": 1},
    "two_level": {"generator": "tunnel_network", "total_length_m": 700, "levels": 2, "ramp": True, "loops": 1},
    "cave": {"generator": "cave", "total_length_m": 500},
}
QUICK_LENGTH_M = {"tunnel_network": 400, "two_level": 400, "cave": 250}
#: name -> (robot tree, base station tree, team section, number of robots).
METHODS = {
    "single": ("gbplanner_explorer.yaml", "base_station.yaml", None, 1),
    "independent": ("gbplanner_explorer.yaml", "base_station.yaml", None, 3),
    "cohort": ("cohort_robot.yaml", "cohort_hub.yaml", {"strategy": "cohort"}, 3),
    "csiro1": ("csiro_uav.yaml", "csiro_base.yaml", {"strategy": "csiro"}, 1),
    "csiro": ("csiro_uav.yaml", "csiro_base.yaml", {"strategy": "csiro"}, 3),
}
ENDURANCE_S = 1500.0
DURATION_S = 1800.0
ARTIFACTS = 20
#: The quick worlds hold fewer artifacts 10 m apart.
QUICK_ARTIFACTS = 10
#: The base station's radio reaches only part of the world (as in the COHORT paper);
#: ``--radio-range-m`` changes it.
RADIO_RANGE_M = 60.0
TARGET = "90%"
#: ``--radio-clear``: the link margin at the range (dB).
CLEAR_MARGIN_DB = 20.0


@dataclass
class Run:
    world: str
    method: str
    seed: int
    t90_s: float | None
    base_t90_s: float | None
    coverage: float
    base_coverage: float
    distance_m: float
    overlap: float | None
    scored: int | None
    succeeded: bool
    wall_s: float


def robots_section(method: str) -> list[dict]:
    tree, _, _, count = METHODS[method]
    return [{"name": f"uav{i + 1}", "platform": "aerial", "tree": str(TREES / tree), "endurance_s": ENDURANCE_S}
            for i in range(count)]


def radio_doc(range_m: float, clear: bool) -> dict:
    """The scenario's radio section: the range alone (the link budget of ``sim/radio.py``
    still applies), or with ``clear`` no obstruction loss and the transmit power that
    leaves :data:`CLEAR_MARGIN_DB` at the range (log-distance path loss of RadioSpec)."""
    if not clear:
        return {"range_m": range_m}
    from delve.sim.radio import RadioSpec

    spec = RadioSpec()
    path_loss = spec.path_loss_d0_db + 10.0 * spec.path_loss_exponent * math.log10(
        max(range_m, spec.reference_distance_m) / spec.reference_distance_m)
    return {"range_m": range_m, "corner_loss_db": 0.0, "rock_loss_db_per_m": 0.0,
            "tx_power_dbm": round(spec.sensitivity_dbm + CLEAR_MARGIN_DB + path_loss, 1)}


def scenario_doc(world: dict, seed: int, duration_s: float, artifacts: int,
                 radio: dict | None = None) -> dict:
    """The scenario every run starts from (the sweep sets world, robots, base and team)."""
    return {"name": "team_exploration", "seed": seed, "duration_s": duration_s, "world": world,
            "radio": radio or {"range_m": RADIO_RANGE_M}, "artifacts": {"count": artifacts},
            "base_station": {"tree": str(TREES / "base_station.yaml")}, "robots": robots_section("single")}


def run_set(world: dict, method: str, team_params: dict | None = None) -> dict:
    """The overrides of one run: its world and its method's robots, base tree and team
    (with ``team_params``, the ``--team-param`` keys given for this method)."""
    _, base, team, _ = METHODS[method]
    out = {"world": world, "robots": robots_section(method), "base_station": {"tree": str(TREES / base)}}
    if team is not None:
        out["team"] = {**team, **(team_params or {})}
    return out


def sweep_doc(worlds: dict[str, dict], methods: list[str], seeds: list[int],
              team_params: dict[str, dict] | None = None) -> dict:
    """The sweep: one runs entry per world and method (labelled ``world/method``)."""
    team_params = team_params or {}
    return {"name": "team_exploration", "scenarios": ["scenario.yaml"], "seeds": seeds,
            "runs": [{"label": f"{w}/{m}", "set": run_set(spec, m, team_params.get(m))}
                     for w, spec in worlds.items() for m in methods]}


def parse_team_params(items: list[str]) -> dict[str, dict]:
    """``METHOD.KEY=VALUE`` items (VALUE in YAML) as {method: {key: value}}; ValueError if malformed."""
    import yaml

    out: dict[str, dict] = {}
    for item in items:
        name, sep, value = item.partition("=")
        method, dot, key = name.partition(".")
        if not (sep and dot and key) or method not in METHODS or METHODS[method][2] is None:
            teams = ", ".join(m for m, spec in METHODS.items() if spec[2] is not None)
            raise ValueError(f"--team-param {item!r}: expected METHOD.KEY=VALUE with METHOD one of {teams}")
        out.setdefault(method, {})[key] = yaml.safe_load(value)
    return out


def _number(row, column: str) -> float | None:
    value = row.get(column)
    return None if value is None or value != value else float(value)


def run_sweep(worlds: dict[str, dict], methods: list[str], seeds: list[int], duration_s: float, artifacts: int,
              out: Path, jobs: int, scheduler: str | None, radio: dict | None = None,
              team_params: dict[str, dict] | None = None) -> list[Run]:
    """Run the sweep into ``out``; its finished rows as Runs (a failed run is printed and left out)."""
    from bench_sweep import run_bench_sweep

    first = scenario_doc(next(iter(worlds.values())), seeds[0], duration_s, artifacts, radio)
    result = run_bench_sweep(out, first, sweep_doc(worlds, methods, seeds, team_params), jobs, scheduler)
    for r in result.table[result.table["status"] != "ok"].itertuples():
        print(f"FAILED {r.run_id}: {r.error}")
    runs = []
    for _, row in result.table[result.table["status"] == "ok"].iterrows():
        world, method = row["label"].split("/")
        distance = sum(_number(row, f"robots.uav{i + 1}.distance_m") or 0.0 for i in range(METHODS[method][3]))
        scored = _number(row, "artifacts.scored")
        runs.append(Run(world, method, int(row["seed"]), _number(row, f"coverage_reached_s.{TARGET}"),
                        _number(row, f"base_coverage_reached_s.{TARGET}"), float(row["coverage_fraction"]),
                        float(row["base_coverage_fraction"]), distance,
                        _number(row, "overlap_fraction"), None if scored is None else int(scored),
                        bool(row["succeeded"]), float(row["wall_time_s"])))
    return runs


def median_t(times: list[float | None]) -> float | None:
    """Median time, "not reached" counted as later than any time (None when the median is not reached)."""
    m = statistics.median(sorted(t if t is not None else float("inf") for t in times))
    return None if m == float("inf") else m


def fmt(value: float | None, spec: str = ".0f", none: str = "-") -> str:
    return none if value is None else format(value, spec)


def print_tables(runs: list[Run], worlds: list[str], methods: list[str]) -> None:
    print("| world | method | seed | T90 (s) | T90 at base (s) | coverage | at base | distance (m) | overlap | scored "
          "| succeeded | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(runs, key=lambda r: (worlds.index(r.world), methods.index(r.method), r.seed)):
        print(f"| {r.world} | {r.method} | {r.seed} | {fmt(r.t90_s, '.0f', 'not reached')} | "
              f"{fmt(r.base_t90_s, '.0f', 'not reached')} | {r.coverage:.1%} | "
              f"{r.base_coverage:.1%} | {r.distance_m:.0f} | {fmt(r.overlap, '.1%')} | {fmt(r.scored, 'd')} | "
              f"{'yes' if r.succeeded else 'no'} | {r.wall_s:.0f} |")
    print()
    print("Medians per world and method:")
    print()
    print("| world | method | runs | T90 (s) | T90 at base (s) | coverage | at base | distance (m) | overlap | scored |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    medians: dict[tuple[str, str], float | None] = {}
    base_medians: dict[tuple[str, str], float | None] = {}
    for w in worlds:
        for m in methods:
            rs = [r for r in runs if r.world == w and r.method == m]
            if not rs:
                continue
            medians[w, m] = median_t([r.t90_s for r in rs])
            base_medians[w, m] = median_t([r.base_t90_s for r in rs])
            overlaps = [r.overlap for r in rs if r.overlap is not None]
            scored = [r.scored for r in rs if r.scored is not None]
            print(f"| {w} | {m} | {len(rs)} | {fmt(medians[w, m], '.0f', 'not reached')} | "
                  f"{fmt(base_medians[w, m], '.0f', 'not reached')} | "
                  f"{statistics.median(r.coverage for r in rs):.1%} | "
                  f"{statistics.median(r.base_coverage for r in rs):.1%} | "
                  f"{statistics.median(r.distance_m for r in rs):.0f} | "
                  f"{fmt(statistics.median(overlaps) if overlaps else None, '.1%')} | "
                  f"{fmt(statistics.median(scored) if scored else None, '.0f')} |")
    print()
    print("Ratios of median T90 (the issue's goals: COHORT(3)/single <= 0.5, COHORT(3)/independent(3) <= 0.8):")
    print()
    print("| world | cohort / single | cohort / independent | csiro / single | csiro / independent |")
    print("|---|---|---|---|---|")

    def ratio(w: str, a: str, b: str, of: dict = medians) -> str:
        ta, tb = of.get((w, a)), of.get((w, b))
        return "-" if ta is None or tb is None else f"{ta / tb:.2f}"

    for w in worlds:
        print(f"| {w} | {ratio(w, 'cohort', 'single')} | {ratio(w, 'cohort', 'independent')} | "
              f"{ratio(w, 'csiro', 'single')} | {ratio(w, 'csiro', 'independent')} |")
    print()
    print("The same ratios of the median T90 of what the base station knows (a team's map reaches it over the "
          "radio; lone robots' when they come back within reach):")
    print()
    print("| world | cohort / single | cohort / independent | csiro / single | csiro / independent |")
    print("|---|---|---|---|---|")
    for w in worlds:
        print(f"| {w} | {ratio(w, 'cohort', 'single', base_medians)} | "
              f"{ratio(w, 'cohort', 'independent', base_medians)} | {ratio(w, 'csiro', 'single', base_medians)} | "
              f"{ratio(w, 'csiro', 'independent', base_medians)} |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller worlds and one seed")
    ap.add_argument("--seeds", type=int, nargs="+", default=None, help="world/mission seeds (default 1 to 5)")
    ap.add_argument("--worlds", nargs="+", choices=list(WORLDS), default=list(WORLDS))
    ap.add_argument("--methods", nargs="+", choices=list(METHODS), default=["single", "independent", "cohort", "csiro"])
    ap.add_argument("--duration-s", type=float, default=DURATION_S, help="mission limit (sim seconds)")
    ap.add_argument("--radio-range-m", type=float, default=RADIO_RANGE_M,
                    help=f"the base station's radio range (default {RADIO_RANGE_M:.0f} m)")
    ap.add_argument("--radio-clear", action="store_true",
                    help="links reach the range through rock (with --radio-range-m 1000: everywhere)")
    ap.add_argument("--team-param", action="append", default=[], metavar="METHOD.KEY=VALUE",
                    help="a team key for one method's runs, VALUE in YAML (e.g. cohort.box_m=[60,60,20]); repeatable")
    ap.add_argument("--jobs", type=int, default=1, help="workers of the local cluster (a team run needs ~2 GB)")
    ap.add_argument("--scheduler", metavar="ADDRESS", help="run the sweep on the Dask cluster at ADDRESS")
    ap.add_argument("--out", type=Path, help="keep the sweep in DIR (and resume it there); default: a temporary folder")
    args = ap.parse_args(argv)
    if not args.radio_range_m > 0:
        ap.error(f"--radio-range-m must be > 0, got {args.radio_range_m:g}")
    try:
        team_params = parse_team_params(args.team_param)
    except ValueError as err:
        ap.error(str(err))
    seeds = args.seeds or ([1] if args.quick else [1, 2, 3, 4, 5])
    artifacts = QUICK_ARTIFACTS if args.quick else ARTIFACTS
    radio = radio_doc(args.radio_range_m, args.radio_clear)
    worlds = {name: {**WORLDS[name], **({"total_length_m": QUICK_LENGTH_M[name]} if args.quick else {})}
              for name in args.worlds}
    print("$ " + " ".join(shlex.quote(a) for a in [Path(sys.executable).name, *sys.argv]))
    print()
    for name, spec in worlds.items():
        params = ", ".join(f"{k}={v}" for k, v in spec.items() if k != "generator")
        print(f"world {name}: {spec['generator']}({params})")
    print(f"robots: aerial (RMF-Obelix-like), endurance {ENDURANCE_S:.0f} s, mission limit {args.duration_s:.0f} s, "
          f"radio range {args.radio_range_m:.0f} m{' (clear)' if args.radio_clear else ''}, {artifacts} artifacts; "
          f"seeds {seeds}; "
          + "".join(f"{m} team {params}; " for m, params in team_params.items())
          + f"{args.scheduler or f'{args.jobs} worker(s)'}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print()
    t0 = time.perf_counter()
    if args.out:
        runs = run_sweep(worlds, args.methods, seeds, args.duration_s, artifacts, args.out, args.jobs, args.scheduler,
                         radio, team_params)
    else:
        with tempfile.TemporaryDirectory(prefix="team_exploration_") as tmp:
            runs = run_sweep(worlds, args.methods, seeds, args.duration_s, artifacts, Path(tmp), args.jobs,
                             args.scheduler, radio, team_params)
    print_tables(runs, list(worlds), args.methods)
    print(f"\n{len(runs)} runs in {time.perf_counter() - t0:.0f} s wall")
    return 0 if runs else 1


if __name__ == "__main__":
    raise SystemExit(main())
