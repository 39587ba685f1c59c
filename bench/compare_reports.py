"""Compare the report.json of two sets of runs, wall-clock fields aside.

    .venv/bin/python bench/compare_reports.py OLD_DIR NEW_DIR

Each DIR holds one folder per run (``delve run X --out DIR/X``). Prints, per run,
``identical`` or each differing field by its path (``/robots[0]/distance_m: a -> b``).
Used to show that a refactor leaves every shipped scenario's report unchanged.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from delve.executive.outputs import strip_wall_clock


def differences(old: Any, new: Any, path: str = "") -> list[str]:
    """Every field that differs between two JSON values, by its path."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in list(old) + [k for k in new if k not in old]:
            if key not in new:
                out.append(f"{path}/{key}: only in old = {json.dumps(old[key])[:80]}")
            elif key not in old:
                out.append(f"{path}/{key}: only in new = {json.dumps(new[key])[:80]}")
            else:
                out += differences(old[key], new[key], f"{path}/{key}")
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [d for i, (a, b) in enumerate(zip(old, new)) for d in differences(a, b, f"{path}[{i}]")]
    return [] if old == new else [f"{path}: {json.dumps(old)[:60]} -> {json.dumps(new)[:60]}"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    args = ap.parse_args(argv)
    for run in sorted(p for p in args.old.iterdir() if (p / "report.json").exists()):
        other = args.new / run.name / "report.json"
        if not other.exists():
            print(f"{run.name}: no new run")
            continue
        found = differences(*(strip_wall_clock(json.loads(f.read_text())) for f in (run / "report.json", other)))
        print(f"{run.name}: " + ("identical" if not found else f"{len(found)} differences"))
        for line in found:
            print(f"    {line}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
