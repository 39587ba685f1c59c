"""``delve sweep SWEEP.yaml --out DIR``: every run of a sweep file on a Dask cluster.

By default a ``dask.distributed`` LocalCluster of one single-threaded worker process
per core (``workers``); with ``scheduler`` an existing cluster (``dask scheduler`` and
``dask worker ADDRESS``; the sweep's files and DIR must be at the same paths on every
worker). Each run writes its outputs into ``DIR/runs/<run id>/`` as ``delve run``
does (:mod:`.sweep_run`); runs finished by an earlier start are skipped; a run that
fails is recorded and the others go on. Then the table and plots (:mod:`.sweep_table`).
"""
from __future__ import annotations

import logging
import os
import sys
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

from .errors import DelveError, clip_message
from .outpaths import check_out_dir, default_out
from .sweep_run import failed_record, finished_record, run_one
from .sweep_spec import RunSpec, Sweep
from .sweep_table import plot_figures, results_table, write_table

#: Seconds to wait for an existing scheduler (``--scheduler``) to answer.
CONNECT_TIMEOUT_S = 10
#: Exit status of a sweep stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
INTERRUPTED = 130
#: ``progress(done, total, spec, record)``: before the first run (0, total, None, None),
#: then once per finished run.
ProgressFn = Callable[[int, int, "RunSpec | None", "dict | None"], None]


@dataclass
class SweepResult:
    """What a sweep did: runs skipped (finished before), run now, failed; the table."""

    skipped: int
    ran: int
    failed: int
    table: Any


def default_workers() -> int:
    """One worker per core this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None) -> Iterator[Any]:
    """A client of the cluster at ``scheduler``, else of a LocalCluster of ``workers``
    single-threaded processes (default: one per core), closed on exit."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as err:
            raise DelveError(f"--scheduler {scheduler}: cannot connect ({clip_message(err, 100)})") from None
        with client, _quiet_on_interrupt():
            yield client
        return
    # dashboard_address ":0": any free port, so that a second cluster on this machine does not warn that
    # the default one is taken.
    with LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1, processes=True,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, Client(cluster) as client, \
            _quiet_on_interrupt():
        yield client


@contextmanager
def _quiet_on_interrupt() -> Iterator[None]:
    """On Ctrl-C, silence Dask's loggers before the client and cluster close: runs cut off
    and heartbeats lost then are what the user asked for, not errors to show them."""
    try:
        yield
    except KeyboardInterrupt:
        for name in ("distributed", "tornado", "asyncio"):
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        raise


def run_sweep(sweep: Sweep, out: Path, *, workers: int | None = None, scheduler: str | None = None,
              retry_failed: bool = False, progress: ProgressFn | None = None, plots: bool = True) -> SweepResult:
    """Run every run of ``sweep`` not yet finished in ``out`` (failed ones too with
    ``retry_failed``), then write the table and (with ``plots``) the plots.
    ``progress(done, total, spec, record)`` is called once before the first run (0,
    total, None, None) and then as each run finishes."""
    check_out_dir(out)
    out = out.resolve()
    runs_dir = out / "runs"
    records: dict[str, dict] = {}
    for spec in sweep.runs:
        record = finished_record(spec, runs_dir / spec.run_id)
        if record is not None and not (retry_failed and record["status"] != "ok"):
            records[spec.run_id] = record
    skipped = len(records)
    todo = [spec for spec in sweep.runs if spec.run_id not in records]
    if progress is not None:
        progress(0, len(todo), None, None)
    if todo:
        from dask.distributed import as_completed

        with dask_client(workers, scheduler) as client:
            futures = {client.submit(run_one, spec, runs_dir / spec.run_id, key=f"delve-run-{spec.run_id}",
                                     pure=False): spec for spec in todo}
            for done, future in enumerate(as_completed(futures), start=1):
                spec = futures[future]
                try:
                    record = future.result()
                except Exception as err:  # noqa: BLE001 - a worker that died fails its run alone
                    record = failed_record(spec, f"the worker did not return the run: {type(err).__name__}: {err}")
                records[spec.run_id] = record
                if progress is not None:
                    progress(done, len(todo), spec, record)
    table = results_table(sweep, records, runs_dir)
    write_table(table, out)
    if plots:
        plot_figures(table, sweep, out / "plots")
    failed = int((table["status"] != "ok").sum())
    return SweepResult(skipped=skipped, ran=len(todo), failed=failed, table=table)


@contextmanager
def progress_bar(name: str) -> Iterator[ProgressFn]:
    """A progress bar on stderr that counts finished runs (of those to run now), with
    a line per run."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    with Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.fields[failed]}"), TimeElapsedColumn(), console=console) as bar:
        task = bar.add_task(f"sweep {name}", total=None, failed="")
        failures = 0

        def update(done: int, total: int, spec: RunSpec | None, record: dict | None) -> None:
            nonlocal failures
            if spec is None or record is None:   # before the first run: the total is known
                bar.update(task, total=total)
                return
            failures += record["status"] != "ok"
            wall = record.get("wall_time_s")
            took = f" ({wall:.1f} s)" if isinstance(wall, (int, float)) else ""
            error = f": {record['error']}" if record["status"] != "ok" else ""
            bar.console.print(f"{spec.run_id}: {record['status']}{took}{error}", highlight=False, markup=False,
                              soft_wrap=True)   # one line per run, whatever the width: grep finds it
            bar.update(task, completed=done, total=total, failed=f"{failures} failed" if failures else "")

        yield update


def sweep_command(path: Path, out: Path | None, workers: int | None, scheduler: str | None, quiet: bool,
                  retry_failed: bool, include_path: tuple[Path, ...]) -> int:
    """The ``delve sweep`` command: check, run, write; exit 0 when every run ran, 1
    when one failed, :data:`INTERRUPTED` on Ctrl-C."""
    from .sweep_spec import load_sweep

    if workers is not None and workers < 1:
        raise DelveError(f"--workers must be >= 1, got {workers}")
    if workers is not None and scheduler:
        raise DelveError("--workers sizes the local cluster: leave it out with --scheduler")
    sweep = load_sweep(path, include_path)
    out = out or default_out(sweep.name)
    try:
        with (_no_bar() if quiet else progress_bar(sweep.name)) as progress:
            result = run_sweep(sweep, out, workers=workers, scheduler=scheduler, retry_failed=retry_failed,
                               progress=progress)
    except KeyboardInterrupt:
        print(f"sweep {sweep.name}: interrupted; the same command resumes it (finished runs are kept)",
              file=sys.stderr)
        return INTERRUPTED
    print(f"sweep {sweep.name}: {len(sweep.runs)} runs, {result.ran} run now, {result.skipped} finished before, "
          f"{result.failed} failed")
    for _, row in result.table[result.table["status"] != "ok"].iterrows():
        print(f"  failed: {row['run_id']}: {row['error']}")
    print(f"table in {out}/results.csv and results.parquet, plots in {out}/plots/, runs in {out}/runs/")
    return 1 if result.failed else 0


@contextmanager
def _no_bar() -> Iterator[None]:
    yield None
