"""Sweep files: scenarios x parameter overrides x seeds, each combination one run.

    name: exploration                 # optional (default: the file's name without .yaml)
    scenarios: [a.yaml, b.yaml]       # relative to this file
    seeds: [1, 2, 3]                  # or {count: 5, first: 1}; default: each scenario's own seed
    grid:                             # every combination of these values
      world.total_length_m: [200, 400]
      robots.0.tree: [../trees/gbplanner_explorer.yaml, ../trees/frontier_explorer.yaml]
    runs:                             # and/or a list of override sets, each crossed with the grid
      - {label: short, set: {duration_s: 600}}
      - {scenario: c.yaml, set: {radio.range_m: 40}}

An override names a scenario key by its dotted path (``world.total_length_m``; a number
indexes a list: ``robots.0.tree``); its value replaces the scenario's (a path in it
resolves from the scenario's folder, as the scenario's own do). Every generated
scenario is checked before any run starts: a mistake in the sweep file, or an
override the scenario does not accept, is one :class:`DelveError` naming the sweep
file and the line of the key at fault.
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import SCENARIOS_DIR
from ..skills.base import short_repr
from .errors import DelveError, did_you_mean, display_path
from .scenario import Scenario, load_scenario
from .tree_loader import path_inside
from .yamlio import YamlDict, YamlList, file_problem, load_yaml, plain

KEYS = ("name", "scenarios", "seeds", "grid", "runs")
RUN_KEYS = ("label", "scenario", "set")
SEED_KEYS = ("count", "first")
#: Most runs one sweep may make: at a minute a run, a week of a 64-core machine; more
#: is a typo (``count: 1000000``) that would fill the disk with run folders.
MAX_RUNS = 10_000
#: The world's keys that name a file (relative to the scenario).
WORLD_FILE_KEYS = ("mesh", "network", "trajectory")
#: The largest seed: the results table keeps seeds as 64-bit integers (Parquet).
MAX_SEED = 2**63 - 1
#: Longest run id (a folder name); a longer one is cut and ends in a digest of the whole.
MAX_ID_CHARS = 120
#: Characters of a run id besides letters and digits; any other becomes ``_``.
_ID_UNSAFE = re.compile(r"[^A-Za-z0-9._=+-]+")


@dataclass(frozen=True)
class Override:
    """One scenario key set by a sweep: its dotted ``path``, its ``value`` as read (a
    mapping or list keeps its lines, as the scenario's checks want them) and the sweep
    file's line that gives it."""

    path: str
    value: Any
    line: int | None


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep: a scenario file with overrides and a seed.

    ``digest`` fingerprints the generated scenario and seed: a finished run whose
    marker holds another digest was made from another scenario and runs again."""

    run_id: str
    scenario_file: Path
    scenario: str
    seed: int
    overrides: tuple[Override, ...]
    label: str | None
    digest: str
    include_path: tuple[Path, ...] = ()


@dataclass(frozen=True)
class Sweep:
    """A checked sweep file: its runs in file order and the override paths it sets."""

    path: Path
    name: str
    runs: tuple[RunSpec, ...]
    override_paths: tuple[str, ...]


def apply_overrides(doc: YamlDict, overrides: tuple[Override, ...]) -> YamlDict:
    """A copy of the scenario ``doc`` with each override set at its dotted path
    (missing mappings on the way are made). A DelveError at the override's line (no
    file) when a path runs through a value that is no mapping or list, or past a
    list's end."""
    doc = copy.deepcopy(doc)
    for o in overrides:
        node: Any = doc
        parts = o.path.split(".")
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            where = ".".join(parts[:depth]) or "the scenario"
            if isinstance(node, list):
                if not part.isdigit() or int(part) >= len(node):
                    raise DelveError(f"{o.path}: {where} is a list of {len(node)}: {short_repr(part)} is no index "
                                     f"of it", line=o.line)
                key: Any = int(part)
            elif isinstance(node, dict):
                key = part
                if not last and key not in node:
                    node[key] = YamlDict(line=getattr(node, "line", None))
            else:
                raise DelveError(f"{o.path}: {where} is {short_repr(node)}, not a mapping or list", line=o.line)
            if last:
                node[key] = copy.deepcopy(o.value)
            else:
                node = node[key]
    return doc


def load_sweep(path: str | Path, include_path: tuple[Path, ...] = ()) -> Sweep:
    """Read and check a sweep file and every scenario it generates (not their worlds).
    A warning that several generated scenarios give is shown once."""
    path = Path(path)
    doc = load_yaml(path)
    if not isinstance(doc, YamlDict):
        raise DelveError("a sweep file must be a mapping (scenarios:, seeds:, grid:, runs:)", path,
                         getattr(doc, "line", 1))
    _known_keys(doc, KEYS, "sweep", path)
    name = doc.get("name", path.stem)
    if not isinstance(name, str) or not name:
        raise DelveError(f"name: must be a non-empty string, not {short_repr(name)}", path, doc.key_line("name"))
    seeds, grid = _seeds(doc, path), _grid(doc, path)
    entries = _run_entries(doc, path, _scenario_files(doc, path, include_path), include_path)
    total = sum(len(files) for _, files, _ in entries) * math.prod(map(len, grid)) * max(1, len(seeds))
    if total > MAX_RUNS:
        raise DelveError(f"sweep: {total:,} runs, more than the limit of {MAX_RUNS:,}", path, doc.line)
    runs: list[RunSpec] = []
    docs: dict[Path, YamlDict] = {}
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        for label, files, fixed in entries:
            for (file, file_line), combo in itertools.product(files, itertools.product(*grid)):
                overrides = fixed + tuple(combo)
                seeded = [o for o in overrides if o.path == "seed"]
                if seeded and seeds:
                    raise DelveError("seed: give the seeds with 'seeds:', not as an override", path, seeded[0].line)
                if file not in docs:
                    docs[file] = _scenario_yaml(file, path, file_line)
                try:
                    scenario = apply_overrides(docs[file], overrides)
                except DelveError as err:
                    raise DelveError(err.message, path, err.line) from None
                _check_world_files(scenario, file, path, file_line, include_path)
                checked = _generated(file, docs[file], overrides, (path, file_line), include_path)
                for seed in seeds or [checked.seed]:
                    runs.append(RunSpec(
                        run_id=run_id(checked.name, label, fixed, tuple(combo), seed), scenario_file=file,
                        scenario=checked.name, seed=seed, overrides=overrides, label=label,
                        digest=_digest({"scenario": scenario, "seed": seed}), include_path=include_path))
    for message in dict.fromkeys(str(w.message) for w in shown):
        warnings.warn(next(w.message for w in shown if str(w.message) == message), stacklevel=2)
    _unique_ids(runs, path, doc)
    paths = tuple(dict.fromkeys(o.path for r in runs for o in r.overrides))
    return Sweep(path=path, name=name, runs=tuple(runs), override_paths=paths)


def run_id(scenario: str, label: str | None, fixed: tuple[Override, ...], combo: tuple[Override, ...],
           seed: int) -> str:
    """A run's folder name: the scenario's name, the run's label (else its overrides),
    the grid's overrides as ``path=value``, and ``s<seed>``; characters other than
    letters, digits and ``._=+-`` become ``_``."""
    parts = [scenario, *([label] if label else [f"{o.path}={_short_value(o.value)}" for o in fixed]),
             *(f"{o.path}={_short_value(o.value)}" for o in combo), f"s{seed}"]
    text = _ID_UNSAFE.sub("_", "-".join(parts))
    if len(text) > MAX_ID_CHARS:
        text = text[:MAX_ID_CHARS - 9] + "-" + hashlib.sha1(text.encode()).hexdigest()[:8]
    return text


def _short_value(value: Any) -> str:
    """A value as a run id shows it: a number or word as it is, a path by its last part,
    a list or mapping by a digest of it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return f"{value:g}" if isinstance(value, float) else str(value)
    if isinstance(value, str):
        return Path(value).name if "/" in value else value
    return "h" + _digest(value)[:8]


def _digest(value: Any) -> str:
    return hashlib.sha256(json.dumps(plain(value), sort_keys=True, default=str).encode()).hexdigest()


def _known_keys(doc: YamlDict, allowed: tuple[str, ...], where: str, path: Path) -> None:
    for key in doc:
        if key not in allowed:
            raise DelveError(f"{where}: unknown key {short_repr(key)}{did_you_mean(str(key), allowed)} "
                             f"(one of {', '.join(allowed)})", path, doc.key_line(key))


def _scenario_files(doc: YamlDict, path: Path, include_path: tuple[Path, ...]) -> list[tuple[Path, int | None]]:
    """The ``scenarios:`` files, relative to the sweep file, with their lines."""
    given, line = doc.get("scenarios", []), doc.key_line("scenarios")
    items = [given] if isinstance(given, str) else given
    if not isinstance(items, list):
        raise DelveError("scenarios: must be a list of scenario files", path, line)
    return [_scenario_file(item, path, items.item_line(i) if isinstance(items, YamlList) else line, "scenarios",
                           include_path) for i, item in enumerate(items)]


def _scenario_file(item: Any, path: Path, line: int | None, where: str,
                   include_path: tuple[Path, ...]) -> tuple[Path, int | None]:
    if not isinstance(item, str) or not item:
        raise DelveError(f"{where}: a scenario file name, not {short_repr(item)}", path, line)
    file = path.parent / item
    shipped = SCENARIOS_DIR / f"{item}.yaml"
    if not file.exists() and "/" not in item and not Path(item).suffix and shipped.is_file():
        file = shipped   # a shipped scenario by its name, as `delve run demo`
    _check_allowed(file, path, line, include_path)   # first: nothing said of a file elsewhere
    problem = file_problem(file)
    if problem:
        raise DelveError(f"{where}: scenario file {problem}: {short_repr(item)[1:-1]}", path, line)
    return file, line


def _check_allowed(file: Path, path: Path, line: int | None, include_path: tuple[Path, ...],
                   what: str = "scenario", scenario: Path | None = None) -> None:
    """A file a sweep makes delve read (a scenario, a world file of one) must lie, symbolic
    links followed, in the sweep's folder, the ``scenario``'s folder, the shipped scenarios
    or an ``include_path`` folder (as a tree's file must): a sweep file from elsewhere
    cannot have delve read, and quote in its errors, any file of the machine."""
    folders = [path.parent, *([scenario.parent] if scenario is not None else []), SCENARIOS_DIR, *include_path]
    if not any(path_inside(os.path.realpath(file), os.path.realpath(f)) for f in folders):
        given = file.relative_to(path.parent) if file.is_relative_to(path.parent) else file
        also = " and the scenario's" if scenario is not None else ""
        raise DelveError(f"{what} {short_repr(str(given))} is outside the allowed folders (the sweep's folder "
                         f"{os.path.join(display_path(path.parent), '')}{also}, the shipped scenarios; add "
                         "--include-path)", path, line)


def _check_world_files(scenario: Any, file: Path, path: Path, line: int | None,
                       include_path: tuple[Path, ...]) -> None:
    """:func:`_check_allowed` for the files the generated scenario's world names (relative
    to the scenario ``file``), before any is read."""
    world = scenario.get("world") if isinstance(scenario, dict) else None
    for key in WORLD_FILE_KEYS if isinstance(world, dict) else ():
        if isinstance(world.get(key), str):
            _check_allowed(file.parent / world[key], path, line, include_path, f"world.{key}", file)


def _seeds(doc: YamlDict, path: Path) -> list[int]:
    """The ``seeds:``: a list of integers >= 0, or ``{count, first}``; empty when the
    key is absent (each scenario's own seed)."""
    given = doc.get("seeds")
    line = doc.key_line("seeds")
    if given is None:
        return []
    if isinstance(given, dict):
        _known_keys(given, SEED_KEYS, "seeds", path)
        count, first = given.get("count"), given.get("first", 1)
        for key, value, low, high in (("count", count, 1, MAX_RUNS), ("first", first, 0, MAX_SEED - MAX_RUNS)):
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                span = f"from {low} to {high}"
                raise DelveError(f"seeds: {key} must be an integer {span}, not {short_repr(value)}", path,
                                 given.key_line(key))
        return [first + i for i in range(count)]
    if not isinstance(given, list) or not given:
        raise DelveError("seeds: a non-empty list of integers, or {count: N, first: S}", path, line)
    seeds = []
    for i, seed in enumerate(given):
        at = given.item_line(i) if isinstance(given, YamlList) else line
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
            raise DelveError(f"seeds/{i}: a seed is an integer from 0 to {MAX_SEED}, not {short_repr(seed)}", path, at)
        if seed in seeds:
            raise DelveError(f"seeds/{i}: seed {seed} is given twice", path, at)
        seeds.append(seed)
    return seeds


def _scenario_yaml(file: Path, path: Path, line: int | None) -> YamlDict:
    """A scenario file's YAML; its mistakes named at the sweep's line too."""
    try:
        return load_yaml(file)
    except DelveError as err:
        raise DelveError(f"scenario {short_repr(file.name)}: {err}", path, line) from None


def _check_path(key: Any, path: Path, line: int | None, where: str) -> str:
    """A dotted override path: non-empty parts without spaces."""
    if not isinstance(key, str) or not all(part and not part.isspace() and " " not in part
                                           for part in key.split(".")):
        raise DelveError(f"{where}: {short_repr(key)} is not a dotted path of scenario keys "
                         "(world.total_length_m, robots.0.tree)", path, line)
    return key


def _overrides(mapping: Any, path: Path, where: str, line: int | None) -> tuple[Override, ...]:
    if not isinstance(mapping, dict):
        raise DelveError(f"{where}: a mapping of dotted scenario keys to values", path, line)
    return tuple(Override(_check_path(k, path, mapping.key_line(k), where), v, mapping.key_line(k))
                 for k, v in mapping.items())


def _grid(doc: YamlDict, path: Path) -> list[list[Override]]:
    """For each ``grid:`` key, its overrides, one per value (in file order)."""
    grid = doc.get("grid", {})
    if not isinstance(grid, dict):
        raise DelveError("grid: a mapping of dotted scenario keys to lists of values", path, doc.key_line("grid"))
    axes = []
    for key, values in grid.items():
        line = grid.key_line(key)
        _check_path(key, path, line, "grid")
        if not isinstance(values, list) or not values:
            raise DelveError(f"grid: {short_repr(key)}: a non-empty list of values, not {short_repr(values)}", path,
                             line)
        axes.append([Override(key, v, values.item_line(i) if isinstance(values, YamlList) else line)
                     for i, v in enumerate(values)])
    return axes


def _run_entries(doc: YamlDict, path: Path, scenarios: list[tuple[Path, int | None]],
                 include_path: tuple[Path, ...]) -> list[tuple[str | None, list[tuple[Path, int | None]], tuple[Override, ...]]]:
    """Each ``runs:`` entry (or one empty entry when there is none) as its label, its
    scenario files (its own ``scenario:``, else ``scenarios:``) and its overrides."""
    given = doc.get("runs")
    if given is None:
        if not scenarios:
            raise DelveError("sweep: name the scenarios to run ('scenarios:', or 'scenario:' in each of 'runs:')",
                             path, doc.line)
        return [(None, scenarios, ())]
    if not isinstance(given, list) or not given:
        raise DelveError("runs: a non-empty list of {label:, scenario:, set: {...}}", path, doc.key_line("runs"))
    entries = []
    for i, entry in enumerate(given):
        line = given.item_line(i) if isinstance(given, YamlList) else None
        if not isinstance(entry, dict):
            raise DelveError(f"runs/{i}: a mapping with set: (and optionally label:, scenario:)", path, line)
        _known_keys(entry, RUN_KEYS, f"runs/{i}", path)
        label = entry.get("label")
        if label is not None and (not isinstance(label, str) or not label):
            raise DelveError(f"runs/{i}: label must be a non-empty string", path, entry.key_line("label"))
        files = ([_scenario_file(entry["scenario"], path, entry.key_line("scenario"), f"runs/{i}", include_path)]
                 if "scenario" in entry else scenarios)
        if not files:
            raise DelveError(f"runs/{i}: no scenario: give 'scenario:' here or 'scenarios:' at the top", path, line)
        entries.append((label, files, _overrides(entry.get("set", {}), path, f"runs/{i}/set",
                                                 entry.key_line("set"))))
    return entries


def _generated(file: Path, doc: YamlDict, overrides: tuple[Override, ...], where: tuple[Path, int | None],
               include_path: tuple[Path, ...]) -> Scenario:
    """Check the scenario that ``overrides`` make of ``doc``. A mistake is named at the
    sweep file's line of the override that brings it in (the scenario's own mistakes
    at the line that names the scenario), with the scenario's own file and line.
    ``where``: the sweep file and the line that names the scenario."""
    path, file_line = where
    try:
        return load_scenario(file, include_path, doc=apply_overrides(doc, overrides))
    except DelveError as err:
        culprit = len(overrides)
        for i in range(len(overrides)):  # the shortest prefix of the overrides that fails
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    load_scenario(file, include_path, doc=apply_overrides(doc, overrides[:i]))
            except DelveError:
                culprit = i
                break
        if culprit == 0:
            raise DelveError(f"scenario {short_repr(file.name)}: {err}", path, file_line) from None
        o = overrides[culprit - 1]
        raise DelveError(f"{o.path}: {short_repr(o.value)} does not fit scenario {short_repr(file.name)}: {err}",
                         path, o.line) from None


def _unique_ids(runs: list[RunSpec], path: Path, doc: YamlDict) -> None:
    seen: dict[str, RunSpec] = {}
    for r in runs:
        if r.run_id in seen:
            first = seen[r.run_id]
            line = next((o.line for o in r.overrides if o not in first.overrides), doc.line)
            raise DelveError(f"two runs get the same id {short_repr(r.run_id)}: give the runs entries labels, or "
                             "values that differ in their last path part", path, line)
        seen[r.run_id] = r
