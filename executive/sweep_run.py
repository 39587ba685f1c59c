"""One run of a sweep, on a worker: the scenario with its overrides and seed, run as
``delve run`` runs it, its outputs written into the run's folder, then a marker.

A run is finished when its folder holds the marker (:data:`MARKER`, written last,
atomically) with the run's digest: an interrupted sweep started again skips it. A
run that raises is recorded as failed with its error in one line (the traceback
goes to ``error.txt`` in its folder); it never stops the sweep.
"""
from __future__ import annotations

import json
import os
import shutil
import threading
import time
import traceback
import warnings
from pathlib import Path
from typing import Any

import py_trees

from .errors import DelveError, clip_message
from .sweep_spec import RunSpec, apply_overrides
from .yamlio import load_yaml

#: The file that marks a finished run: its status, error and wall time.
MARKER = "sweep_run.json"
#: py_trees keeps every blackboard in one process-global store, so a worker process
#: runs one mission at a time even when its worker has several threads.
_ONE_MISSION_AT_A_TIME = threading.Lock()


def run_one(spec: RunSpec, folder: Path) -> dict[str, Any]:
    """Run ``spec`` into ``folder`` (emptied first) and write its marker; the marker's
    record (run_id, digest, status ``ok`` or ``failed``, error, wall_time_s)."""
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    started = time.perf_counter()
    with _ONE_MISSION_AT_A_TIME, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the sweep showed each once when it checked the scenarios
        try:
            rep = _mission(spec, folder, started)
            status, error, wall_s = "ok", "", rep["wall_time_s"]
        except Exception as err:  # noqa: BLE001 - any failure of one run is recorded, never raised
            (folder / "error.txt").write_text(traceback.format_exc())
            status, error, wall_s = "failed", one_line(err) + _overrides_note(spec, err), round(
                time.perf_counter() - started, 3)
    record = {"run_id": spec.run_id, "digest": spec.digest, "status": status, "error": error, "wall_time_s": wall_s}
    partial = folder / f".{MARKER}.part"
    partial.write_text(json.dumps(record, indent=2) + "\n")
    os.replace(partial, folder / MARKER)
    return record


def _overrides_note(spec: RunSpec, err: BaseException) -> str:
    """For a mistake a scenario's check found in a run with overrides: which values the
    sweep set and at which of its lines (the error names the scenario's file and line,
    though the value at fault may be the sweep's)."""
    if not isinstance(err, DelveError) or not spec.overrides:
        return ""
    given = ", ".join(f"{o.path}={clip_message(o.value, 30)}" + (f" (sweep line {o.line})" if o.line else "")
                      for o in spec.overrides)
    return f" [this run's overrides: {given}]"


def _mission(spec: RunSpec, folder: Path, started: float) -> dict[str, Any]:
    """What ``delve run SCENARIO --seed N --quiet`` does, with the overrides applied;
    the report."""
    from .outputs import write_outputs
    from .runner import Mission
    from .scenario import load_scenario

    # Everything an earlier mission of this process left on py_trees' global blackboard
    # goes (Mission clears its agents' namespaces only; their clients' metadata stays).
    py_trees.blackboard.Blackboard.clear()
    doc = apply_overrides(load_yaml(spec.scenario_file), spec.overrides)
    scenario = load_scenario(spec.scenario_file, spec.include_path, doc=doc)
    world = scenario.build_world(spec.seed)
    errors = scenario.world_backend.describe(scenario, world).errors
    if errors:
        raise DelveError(str(errors[0]))
    mission = Mission(scenario, seed=spec.seed, world=world)
    mission.run()
    return write_outputs(mission, folder, time.perf_counter() - started)


def one_line(err: BaseException) -> str:
    """An error as one line: a DelveError as it prints; anything else as its type,
    message and the place it was raised."""
    if isinstance(err, DelveError):   # its own words, with the file and line it names whole
        line = " ".join(str(err).split())
        return line if len(line) <= 300 else line[:300] + "..."
    where = traceback.extract_tb(err.__traceback__)[-1] if err.__traceback__ else None
    at = f" (at {Path(where.filename).name}:{where.lineno})" if where else ""
    return clip_message(f"{type(err).__name__}: {err}{at}", 300)


def finished_record(spec: RunSpec, folder: Path) -> dict[str, Any] | None:
    """The marker's record when ``folder`` holds a finished run of ``spec`` (its
    marker with the same digest, and for a run that ended ``ok`` its report), else None."""
    try:
        record = json.loads((folder / MARKER).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or record.get("digest") != spec.digest:
        return None
    if record.get("status") == "ok" and not (folder / "report.json").is_file():
        return None
    return record


def failed_record(spec: RunSpec, error: str) -> dict[str, Any]:
    """The record of a run whose worker never returned (it died, or was lost): failed,
    with no marker, so that the next start of the sweep runs it again."""
    return {"run_id": spec.run_id, "digest": spec.digest, "status": "failed", "error": clip_message(error, 300),
            "wall_time_s": None}
