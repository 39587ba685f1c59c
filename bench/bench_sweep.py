"""Run a benchmark's sweep: write its scenario and sweep files into a folder and run
them (``delve.executive.sweep``), printing each finished run to stderr."""
from __future__ import annotations

import sys
import time
from pathlib import Path

import yaml


def run_bench_sweep(out: Path, scenario: dict, sweep: dict, jobs: int, scheduler: str | None):
    """Write ``scenario.yaml`` and ``sweep.yaml`` into ``out`` and run the sweep into
    ``out/results`` (resuming what is there); the sweep's result."""
    from delve.executive.sweep import run_sweep
    from delve.executive.sweep_spec import load_sweep

    out.mkdir(parents=True, exist_ok=True)
    (out / "scenario.yaml").write_text(yaml.safe_dump(scenario))
    (out / "sweep.yaml").write_text(yaml.safe_dump(sweep, sort_keys=False))
    t0 = time.perf_counter()

    def done(n: int, total: int, spec, record: dict | None) -> None:
        line = f"  {total} runs to run" if spec is None else \
            f"  [{n}/{total}] {spec.run_id} {record['status']} ({time.perf_counter() - t0:.0f} s)"
        print(line, file=sys.stderr, flush=True)

    return run_sweep(load_sweep(out / "sweep.yaml"), out / "results", workers=None if scheduler else jobs,
                     scheduler=scheduler, progress=done)
