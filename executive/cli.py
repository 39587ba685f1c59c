"""The ``delve`` command line.

    delve run SCENARIO [--out DIR] [--seed N] [--duration-s S] [--quiet] [--include-path DIR]...
    delve validate FILE... | --shipped [--include-path DIR]...
    delve render TREE --format svg|dot|png|txt [--out PATH] [--include-path DIR]...
    delve world SCENARIO [--preview DIR] [--seed N] [--include-path DIR]...
    delve sweep SWEEP [--out DIR] [--workers N | --scheduler ADDRESS] [--retry-failed] [--quiet]
    delve demo

Exit status: 0 when the mission succeeds (every robot's tree ends in SUCCESS, every
robot left its start and the team explored something: see executive/outcome.py), 1
when it fails (each reason printed as a ``why:`` line), 2 for bad input (one line
naming file and line, no traceback).
"""
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

from .. import SCENARIOS_DIR, TREES_DIR
from .errors import DelveError
from .outpaths import check_out_dir, check_out_file, default_out
from .yamlio import YamlDict, load_yaml

DEMO_SCENARIO = SCENARIOS_DIR / "demo.yaml"
#: The formats of ``delve render``: render.FORMATS' (not imported here: it loads py_trees and pydot).
RENDER_FORMATS = ("txt", "svg", "png", "dot")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="delve", description="Behaviour-tree mission executive for subterranean robot teams.")
    p.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a scenario and write its outputs")
    run.add_argument("scenario", type=Path, help="a scenario file, or the name of a shipped one (demo, cops_tunnel, ...)")
    run.add_argument("--out", type=Path, help="output directory (default: delve-out/<scenario name>)")
    run.add_argument("--seed", type=int, help="override the scenario's seed")
    run.add_argument("--duration-s", type=float, help="override the scenario's duration (sim seconds)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    val = sub.add_parser("validate", help="check tree and scenario files")
    val.add_argument("files", type=Path, nargs="*",
                     help="tree and scenario files (each is told apart by its keys)")
    val.add_argument("--shipped", action="store_true", help="also check every shipped tree and scenario")
    ren = sub.add_parser("render", help="draw a tree file")
    ren.add_argument("tree", type=Path, help="a tree file (YAML)")
    ren.add_argument("--format", choices=RENDER_FORMATS,
                     help="txt (a text tree), svg, png or dot (default: --out's suffix, else txt)")
    ren.add_argument("--out", type=Path, help="output file (default: TREE with the format's suffix)")
    wld = sub.add_parser("world", help="load a scenario's world and say what it is: extent, free space, "
                                       "where each start lands, warnings")
    wld.add_argument("scenario", type=Path, help="a scenario file, or the name of a shipped one")
    wld.add_argument("--preview", type=Path, metavar="DIR", help="also draw top.png and side.png into DIR")
    wld.add_argument("--seed", type=int, help="override the scenario's seed (generated worlds)")
    swp = sub.add_parser("sweep", help="run every run of a sweep file (scenarios x overrides x seeds) on Dask "
                                       "and write one table and plots (docs/sweeps.md)")
    swp.add_argument("sweep", type=Path, help="a sweep file")
    swp.add_argument("--out", type=Path, help="output directory (default: delve-out/<sweep name>)")
    swp.add_argument("--workers", type=int, help="worker processes of the local cluster (default: one per core)")
    swp.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS (tcp://host:8786) "
                                                            "instead of a local one")
    swp.add_argument("--retry-failed", action="store_true", help="run again the runs that failed before")
    swp.add_argument("--quiet", action="store_true", help="no progress bar")
    for command in (run, val, ren, wld, swp):
        command.add_argument("--include-path", type=Path, action="append", default=[], metavar="DIR",
                             help="a folder that tree includes (and a sweep's scenarios) may also resolve into "
                                  "(besides their own folder and the shipped ones); repeatable")
    demo = sub.add_parser("demo", help="run the default scenario into ./delve-out/demo")
    demo.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def _version() -> str:
    """The installed package's version."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("delve")
    except PackageNotFoundError:
        return "(not installed)"


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:  # noqa: ANN001
    """Print a warning (a deprecation in a user's file, say) as one line."""
    print(f"warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.showwarning = _one_line_warning
        return _command(args)


def _include_path(args: argparse.Namespace) -> tuple[Path, ...]:
    """The --include-path folders, each checked to be one."""
    folders = tuple(getattr(args, "include_path", None) or ())
    for folder in folders:
        if not folder.is_dir():
            raise DelveError(f"--include-path {str(folder)!r} is not a folder")
    return folders


def _command(args: argparse.Namespace) -> int:
    try:
        include_path = _include_path(args)
        if args.command == "run":
            return run(shipped_or_given(args.scenario), args.out, args.seed, args.duration_s, args.quiet,
                       include_path)
        if args.command == "demo":
            return run(DEMO_SCENARIO, Path("delve-out/demo"), None, None, args.quiet)
        if args.command == "validate":
            shipped = sorted(TREES_DIR.rglob("*.yaml")) + sorted(SCENARIOS_DIR.glob("*.yaml")) if args.shipped else []
            if not args.files and not shipped:
                raise DelveError("validate: name the files to check, or --shipped")
            return validate(args.files + shipped, include_path)
        if args.command == "world":
            return world(shipped_or_given(args.scenario), args.preview, args.seed, include_path)
        if args.command == "render":
            return render(args.tree, args.format, args.out, include_path)
        if args.command == "sweep":
            from .sweep import sweep_command

            return sweep_command(args.sweep, args.out, args.workers, args.scheduler, args.quiet, args.retry_failed,
                                 include_path)
    except DelveError as err:
        print(err, file=sys.stderr)
        return 2
    return 2


def shipped_or_given(path: Path) -> Path:
    """``path``, or the shipped scenario of that name when ``path`` is a bare name
    that is no file here (``delve run demo``)."""
    shipped = SCENARIOS_DIR / f"{path}.yaml"
    if not path.exists() and len(path.parts) == 1 and not path.suffix and shipped.exists():
        return shipped
    return path


def run(path: Path, out: Path | None, seed: int | None, duration_s: float | None, quiet: bool,
        include_path: tuple[Path, ...] = ()) -> int:
    """Run a scenario, write its outputs, print a summary; exit status per the mission.
    ``include_path``: folders the trees' includes may also resolve into."""
    from .outputs import write_outputs
    from .runner import Mission
    from .scenario import load_scenario, steps_problem, warn_late_events

    if seed is not None and seed < 0:
        raise DelveError(f"--seed must be >= 0, got {seed}")
    if duration_s is not None and (not math.isfinite(duration_s) or not duration_s > 0):
        raise DelveError(f"--duration-s must be a finite number of seconds > 0, got {duration_s}")
    scenario = load_scenario(path, include_path=include_path)
    if seed is not None:
        scenario.seed = seed  # the world, its description and the mission all take it
    if duration_s is not None and steps_problem(duration_s, scenario.dt_s):
        raise DelveError(f"--duration-s {steps_problem(duration_s, scenario.dt_s)}")
    if duration_s is not None and duration_s < scenario.duration_s:  # those after the file's end were named
        warn_late_events(scenario.doc, scenario.path, duration_s, scenario.duration_s, "--duration-s")
    out = out or default_out(scenario.name)
    check_out_dir(out)
    started = time.perf_counter()
    loaded = scenario.build_world()
    if not _print_world(scenario.world_backend.describe(scenario, loaded), quiet):
        return 2
    mission = Mission(scenario, duration_s=duration_s, world=loaded)
    if quiet:
        mission.run()
    else:
        _run_with_progress(mission)
    rep = write_outputs(mission, out, time.perf_counter() - started)
    print(f"{scenario.name}: {'succeeded' if rep['succeeded'] else 'FAILED'} after {rep['sim_time_s']:.0f} s sim "
          f"({rep['wall_time_s']:.1f} s wall), coverage {rep['coverage_fraction']:.1%}, "
          f"at base {rep['base_coverage_fraction']:.1%}")
    if "artifacts" in rep:
        a = rep["artifacts"]
        print(f"  artifacts: {a['scored']} of {a['total']} scored, {a['submitted']} of {a['report_limit']} reports "
              f"used, {a['detected']} detected, {a['reported_to_base']} reports delivered, {a['undelivered']} not")
    for reason in rep["outcome"]["reasons"]:
        print(f"  why: {reason}")
    for note in rep["outcome"]["notes"]:
        print(f"  note: {note}")
    lost = rep["outcome"]["lost"]
    for r in rep["robots"]:
        state = f"lost ({lost[r['name']]})" if r["name"] in lost else r["final_status"]
        print(f"  {r['name']} ({r['platform']}): {state}, {r['distance_m']:.0f} m, "
              f"home={'yes' if r['returned_home'] else 'no'}, {r['endurance_left_s']:.0f} s endurance left")
    print(f"outputs in {out}/")
    return 0 if rep["succeeded"] else 1


def world(path: Path, preview: Path | None, seed: int | None, include_path: tuple[Path, ...] = ()) -> int:
    """Load a scenario's world, print what it is and where each start lands (and its
    warnings); with ``preview``, draw it. Exit 2 when a start cannot be used."""
    from .scenario import load_scenario

    if seed is not None and seed < 0:
        raise DelveError(f"--seed must be >= 0, got {seed}")
    scenario = load_scenario(path, include_path=include_path)
    if seed is not None:
        scenario.seed = seed
    if preview is not None:
        check_out_dir(preview, "--preview")
    loaded = scenario.build_world()
    ok = _print_world(scenario.world_backend.describe(scenario, loaded), quiet=False)
    if preview is not None:
        for written in scenario.world_backend.preview(scenario, loaded, preview):
            print(f"wrote {written}")
    return 0 if ok else 2


def _print_world(description, quiet: bool) -> bool:
    """Print a world's description (not when ``quiet``), its warnings and errors (to
    stderr, always); whether it has no errors."""
    if not quiet:
        print("\n".join(description.lines))
    for line in description.warnings:
        print(f"warning: {line}", file=sys.stderr)
    for err in description.errors:
        print(err, file=sys.stderr)
    return not description.errors


def _run_with_progress(mission) -> None:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("[bold]{task.description}"), BarColumn(), TextColumn("{task.fields[status]}"),
               TimeElapsedColumn())
    with Progress(*columns, transient=False) as bar:
        task = bar.add_task(mission.scenario.name, total=mission.duration_s, status="")

        def update(m) -> None:
            s = m.state.samples[-1] if m.state.samples else None
            states = " ".join(f"{n}:{a.final_status.value}" for n, a in m.agents.items() if n != "base")
            cov = f"coverage {s.team:.0%}" if s else ""
            # After the end, the clock runs on while the radio delivers what is queued: show the end.
            t = m.clock.now_s if m.finished_s is None else m.finished_s
            bar.update(task, completed=min(t, m.duration_s), status=f"t={t:6.0f}s {cov} {states}")

        mission.run(progress=update)
        bar.update(task, completed=mission.duration_s)


def validate(files: list[Path], include_path: tuple[Path, ...] = ()) -> int:
    """Check each file (a scenario when its top level has a scenario's keys, or near
    misses of them; else a tree); print ``ok`` or the error. A scenario's world is
    built (as ``delve run`` does first) and its warnings and start errors printed as
    ``delve world`` prints them. Exit 2 if any file is wrong; warnings alone exit 0."""
    from .document_kind import scenario_keys
    from .scenario import load_scenario
    from .tree_loader import check_tree

    status = 0
    for f in files:
        try:
            doc = load_yaml(f)
            if isinstance(doc, YamlDict) and scenario_keys(doc):
                scenario = load_scenario(f, include_path=include_path)
                loaded = scenario.build_world()
                if not _print_world(scenario.world_backend.describe(scenario, loaded), quiet=True):
                    status = 2
                    continue
                scenario.check_starts(loaded)
            else:
                check_tree(f, include_path=include_path)
            print(f"ok: {f}")
        except DelveError as err:
            print(err, file=sys.stderr)
            status = 2
    return status


def render(tree: Path, fmt: str | None, out: Path | None, include_path: tuple[Path, ...] = ()) -> int:
    """``delve render``: the format is ``fmt``, or ``out``'s suffix, or txt; an ``out``
    whose suffix names another format, or that is the tree file itself, is refused."""
    from ..skills.base import AgentContext
    from .render import render_tree
    from .tree_loader import load_tree

    suffix = out.suffix.lstrip(".").lower() if out is not None else ""
    if fmt is not None and suffix in RENDER_FORMATS and suffix != fmt:
        raise DelveError(f"--out {out} has the suffix of {suffix}, not of --format {fmt}")
    fmt = fmt or (suffix if suffix in RENDER_FORMATS else "txt")
    out = out or tree.with_suffix(f".{fmt}")
    if out.resolve() == tree.resolve():
        raise DelveError(f"the {fmt} dump would overwrite the tree file itself: give --out", tree)
    ctx = AgentContext(name="render", namespace="/render", clock=_Still(), log=lambda *a, **k: None)
    check_out_file(out)
    root = load_tree(tree, ctx, include_path=include_path)
    render_tree(root, fmt, out)
    print(f"wrote {out}")
    return 0


class _Still:
    now_s = 0.0


if __name__ == "__main__":
    sys.exit(main())
