"""A sweep's results: one table of every run's report figures (``results.csv`` and
``results.parquet``) and one summary plot per figure (``plots/<figure>.png``).

A row is one run: its id, scenario, seed, the value of each override, its status
(``ok`` or ``failed``), error and wall time, then its report's figures, flattened:
a mapping's fields become ``section.field`` columns, each robot's
``robots.<name>.<field>``; other lists stay in the run's ``report.json``.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from .sweep_spec import Sweep  # noqa: E402

#: The columns every row starts with, before the overrides and the report's figures.
RUN_COLUMNS = ("run_id", "scenario", "seed", "label", "status", "error", "wall_time_s")
#: Report fields that the run columns already give.
_IN_RUN_COLUMNS = ("scenario", "seed", "wall_time_s")
#: Seeds in a group from which a summary plot draws a box besides the points.
BOX_FROM_SEEDS = 5
_FILE_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def flatten(report: dict[str, Any]) -> dict[str, Any]:
    """The report's numbers, words and truths as ``dotted.name -> value`` (robots by
    name); lists other than ``robots`` are left out."""
    flat: dict[str, Any] = {}

    def put(prefix: str, value: Any) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                put(f"{prefix}.{k}" if prefix else str(k), v)
        elif value is None or isinstance(value, (bool, int, float, str)):
            flat[prefix] = value

    for key, value in report.items():
        if key == "robots" and isinstance(value, list):
            for robot in value:
                put(f"robots.{robot.get('name')}", {k: v for k, v in robot.items() if k != "name"})
        elif key not in _IN_RUN_COLUMNS:
            put(key, value)
    return flat


def _cell(value: Any) -> Any:
    """An override's value as a table cell: a list or mapping as its JSON."""
    return json.dumps(value) if isinstance(value, (list, dict)) else value


def results_table(sweep: Sweep, records: dict[str, dict[str, Any]], runs_dir: Path) -> pd.DataFrame:
    """One row per run of ``sweep`` (in the sweep's order) from its ``records`` and
    the ``report.json`` in its folder under ``runs_dir``."""
    rows = []
    for spec in sweep.runs:
        record = records.get(spec.run_id, {})
        row: dict[str, Any] = {"run_id": spec.run_id, "scenario": spec.scenario, "seed": spec.seed,
                               "label": spec.label, "status": record.get("status", "failed"),
                               "error": record.get("error", "not run"), "wall_time_s": record.get("wall_time_s")}
        row.update({o.path: _cell(o.value) for o in spec.overrides})
        report = runs_dir / spec.run_id / "report.json"
        if row["status"] == "ok" and report.is_file():
            row.update(flatten(json.loads(report.read_text())))
        rows.append(row)
    columns = list(RUN_COLUMNS) + list(sweep.override_paths)
    table = pd.DataFrame(rows)
    table = table[columns + [c for c in table.columns if c not in columns]]
    for column in table.columns:  # Parquet wants one type a column: mixed ones become text
        kinds = {type(v) for v in table[column] if v is not None and not (isinstance(v, float) and np.isnan(v))}
        if len(kinds) > 1 and not kinds <= {int, float}:
            table[column] = [None if v is None else str(v) for v in table[column]]
    return table


def write_table(table: pd.DataFrame, out: Path) -> list[Path]:
    """``results.csv`` and ``results.parquet`` in ``out``; the files written."""
    csv, parquet = out / "results.csv", out / "results.parquet"
    table.to_csv(csv, index=False)
    table.to_parquet(parquet, index=False)
    return [csv, parquet]


def figure_columns(table: pd.DataFrame, sweep: Sweep) -> list[str]:
    """The report's figures worth a plot: numbers or truths that differ between runs (or
    that some runs have and others not, such as a coverage only some reach)."""
    skip = set(RUN_COLUMNS) | set(sweep.override_paths)
    ok = table[table["status"] == "ok"]
    figures = []
    for column in table.columns:
        if column in skip:
            continue
        values = ok[column].dropna().infer_objects()
        numeric = pd.api.types.is_numeric_dtype(values) or pd.api.types.is_bool_dtype(values)
        if len(values) and numeric and (values.nunique() > 1 or len(values) < len(ok)):
            figures.append(column)
    return figures


def group_labels(table: pd.DataFrame, sweep: Sweep) -> pd.Series:
    """Each run's group: what sets it apart from the other groups (scenario, label,
    the overrides whose values vary), every seed of a group alike."""
    varying = [c for c in ("scenario", "label", *sweep.override_paths) if table[c].astype(str).nunique() > 1]
    if not varying:
        return pd.Series([str(s) for s in table["scenario"]], index=table.index)

    def label(row: pd.Series) -> str:
        parts = []
        for c in varying:
            value = row[c]
            shown = Path(value).name if isinstance(value, str) and "/" in value else value
            parts.append(str(shown) if c in ("scenario", "label") else f"{c}={shown}")
        return "\n".join(parts)

    return table.apply(label, axis=1)


def plot_figures(table: pd.DataFrame, sweep: Sweep, folder: Path) -> list[Path]:
    """One ``<figure>.png`` per figure in ``folder``: the figure per group across
    seeds, each run a point, the median a bar (and a box from :data:`BOX_FROM_SEEDS`
    seeds); truths as the share of runs where they hold. The files written."""
    folder.mkdir(parents=True, exist_ok=True)
    ok = table[table["status"] == "ok"]
    groups = group_labels(table, sweep)[ok.index]
    order = list(dict.fromkeys(groups))
    failed = int((table["status"] != "ok").sum())
    written = []
    for figure in figure_columns(table, sweep):
        path = folder / f"{_FILE_UNSAFE.sub('_', figure)}.png"
        _plot_one(figure, ok[figure], groups, order, failed, path)
        written.append(path)
    return written


def _plot_one(figure: str, values: pd.Series, groups: pd.Series, order: list[str], failed: int, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(max(6.5, 1.2 * len(order) + 2.0), 4.6))
    truth = pd.api.types.is_bool_dtype(values.dropna().infer_objects())
    x = np.arange(len(order))
    blank = False
    for i, group in enumerate(order):
        runs = values[groups == group]
        ys = runs.dropna().astype(float).to_numpy()
        if len(ys) < len(runs):   # e.g. a coverage never reached: said, not hidden in the median
            blank = True
            ax.text(i, 0.02, f"{len(runs) - len(ys)} of {len(runs)}:\nno value", transform=ax.get_xaxis_transform(),
                    ha="center", va="bottom", fontsize=7, color="dimgray")
        if truth:
            ax.bar(i, ys.mean() if len(ys) else 0.0, width=0.6, color="tab:blue", alpha=0.7)
            ax.text(i, ys.mean() if len(ys) else 0.0, f"{int(ys.sum())}/{len(ys)}", ha="center", va="bottom")
            continue
        if len(ys) >= BOX_FROM_SEEDS:
            ax.boxplot(ys, positions=[i], widths=0.5, showfliers=False, medianprops={"color": "none"})
        # Spread points of one group a little so that equal values stay visible (no randomness).
        spread = np.linspace(-0.12, 0.12, len(ys)) if len(ys) > 1 else np.zeros(len(ys))
        ax.scatter(i + spread, ys, s=22, color="tab:blue", alpha=0.8, zorder=3)
        if 2 * len(ys) > len(runs):   # the median of the runs with a value is the group's
            ax.hlines(np.median(ys), i - 0.25, i + 0.25, color="tab:red", lw=2, zorder=4)
    long_labels = max(map(len, order), default=0) > 14
    ax.set_xticks(x, order, fontsize=8, rotation=25 if long_labels else 0, ha="right" if long_labels else "center")
    ax.set_xlim(-0.6, len(order) - 0.4)
    ax.set_ylabel(f"share of runs where {figure}" if truth else figure)
    if truth:
        ax.set_ylim(0, 1.1)
    what = "bar: share of runs (count above)" if truth else "each point one seed, red bar: median"
    notes = [f"{failed} failed run(s) left out"] if failed else []
    notes += ["runs with no value: counted at the foot, no median if half or more"] if blank else []
    ax.set_title("\n".join([figure, what, "; ".join(notes)] if notes else [figure, what]), fontsize=9)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)

