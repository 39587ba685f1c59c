"""What a run writes: report.json, log.jsonl, map.png, coverage.png, scored.png (with
artifacts) and tree dumps."""
from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .colours import robot_colour  # noqa: E402
from .render import render_tree  # noqa: E402
from .runner import Mission  # noqa: E402
from .teams import wall_clock_fields  # noqa: E402

#: Report fields of every run that depend on the wall clock (team strategies add theirs).
WALL_CLOCK_FIELDS = ("wall_time_s", "real_time_factor")
#: Coverage fractions whose first sim time the report gives, of the team's coverage
#: (``coverage_reached_s``: T80 and T90 of bench/exploration.py) and of what the base
#: station knows (``base_coverage_reached_s``).
COVERAGE_MILESTONES = (0.8, 0.9)


def coverage_reached_s(samples: list, fraction: float, of: str = "team") -> float | None:
    """Sim time at which a coverage (``of``: the samples' ``team``, or ``base``: what
    the base station knows; ``samples``: the runner's, in time order) first reaches
    ``fraction``, interpolated linearly between samples; None when it never does."""
    prev = None
    for s in samples:
        value = getattr(s, of)
        if value >= fraction:
            if prev is None or value == getattr(prev, of):
                return round(float(s.t), 3)
            before = getattr(prev, of)
            return round(float(prev.t + (fraction - before) / (value - before) * (s.t - prev.t)), 3)
        prev = s
    return None


def report(mission: Mission, wall_time_s: float) -> dict[str, Any]:
    """The run's figures (see DESIGN.md, "Outputs of a run")."""
    outcome = mission.outcome
    last = mission.state.samples[-1]
    triggers: dict[str, Counter] = {n: Counter() for n in mission.robots}
    for e in mission.state.events:
        if e.get("trigger") and e.get("agent") in triggers:
            triggers[e["agent"]][e["event"]] += 1
    robots = []
    for name, robot in mission.robots.items():
        home_tol = 1.5
        robots.append({
            "name": name,
            "platform": robot.platform,
            "distance_m": round(robot.distance_m, 2),
            "returned_home": bool(np.linalg.norm(robot.true_position - robot.home) <= home_tol),
            "endurance_left_s": round(robot.endurance_remaining_s, 1),
            "final_status": mission.agents[name].final_status.value,
            "coverage_fraction": last.robots[name],
            "safety_triggers": dict(sorted(triggers[name].items())),
            "messages_sent": robot.radio.sent,
            "messages_undelivered": robot.radio.pending,
            **mission.backend.robot_figures(name, mission.lost),
            **mission.team.robot_figures(mission, name),
        })
    sim_time = mission.finished_s or mission.clock.now_s
    return {
        "scenario": mission.scenario.name,
        "seed": mission.seed,
        "succeeded": outcome.succeeded,
        "outcome": outcome.to_dict(),
        "sim_time_s": round(sim_time, 3),
        "wall_time_s": round(wall_time_s, 3),
        "real_time_factor": round(sim_time / wall_time_s, 1) if wall_time_s > 0 else None,
        "coverage_fraction": last.team,
        "base_coverage_fraction": last.base,
        "coverage_reached_s": {f"{f:.0%}": coverage_reached_s(mission.state.samples, f)
                               for f in COVERAGE_MILESTONES},
        "base_coverage_reached_s": {f"{f:.0%}": coverage_reached_s(mission.state.samples, f, "base")
                                    for f in COVERAGE_MILESTONES},
        **mission.backend.figures(mission),
        **mission.team.figures(mission),
        **mission.artifacts.figures(mission),
        "robots": robots,
        **mission.team.wall_clock_figures(mission),
    }


def finite(value: Any) -> Any:
    """``value`` with every NaN or infinite number replaced by None (strict JSON has
    neither), and numpy scalars and arrays made plain."""
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    if isinstance(value, np.ndarray):
        return finite(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def strip_wall_clock(rep: dict[str, Any]) -> dict[str, Any]:
    """The report without its wall-clock fields, for comparing runs."""
    dropped = WALL_CLOCK_FIELDS + wall_clock_fields()
    return {k: v for k, v in rep.items() if k not in dropped}


def write_outputs(mission: Mission, out: Path, wall_time_s: float) -> dict[str, Any]:
    """Write every output of the run into ``out`` and return the report."""
    out.mkdir(parents=True, exist_ok=True)
    rep = finite(report(mission, wall_time_s))
    (out / "report.json").write_text(json.dumps(rep, indent=2, sort_keys=False, allow_nan=False) + "\n")
    with open(out / "log.jsonl", "w") as f:
        for e in mission.state.events:
            f.write(json.dumps(e, sort_keys=False) + "\n")
    mission.backend.plot_map(mission, out / "map.png")
    plot_coverage(mission, out / "coverage.png", mission.backend.COVERAGE_LABEL)
    mission.artifacts.write_plots(mission, out)
    for name, agent in mission.agents.items():
        render_tree(agent.root, "txt", out / f"tree_{name}.txt", agent.stopped_statuses)
        render_tree(agent.root, "svg", out / f"tree_{name}.svg", agent.stopped_statuses)
    return rep


def plot_coverage(mission: Mission, path: Path, ylabel: str) -> None:
    """Explored fraction over sim time: team and base station (black), robots (each in
    its :func:`robot_colour`, as on map.png)."""
    s = mission.state.samples
    t = np.array([x.t for x in s]) / 60.0
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, [x.team for x in s], lw=2, color="black", label="team")
    ax.plot(t, [x.base for x in s], lw=2, ls="--", color="0.45", label="known at base station")
    if len(mission.robots) > 1:
        for i, name in enumerate(mission.robots):
            ax.plot(t, [x.robots[name] for x in s], lw=1, color=robot_colour(i), label=name)
    ax.set_xlabel("sim time (min)")
    ax.set_ylabel(ylabel)
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
