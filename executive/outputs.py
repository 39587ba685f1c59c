"""What a run writes: report.json, log.jsonl, map.png, coverage.png and tree dumps."""
from __future__ import annotations

import json
from collections import Counter
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..planners.frontier import frontier_voxels  # noqa: E402
from ..planners.occupancy import Grid  # noqa: E402
from ..sim.graph_world import GraphWorld  # noqa: E402
from .render import render_tree  # noqa: E402
from .runner import Mission  # noqa: E402

#: Report fields that depend on the wall clock; everything else is deterministic.
WALL_CLOCK_FIELDS = ("wall_time_s", "real_time_factor", "cops_solve_time_s")


def report(mission: Mission, wall_time_s: float) -> dict[str, Any]:
    """The run's figures (see DESIGN.md, "Outputs of a run")."""
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
            "returned_home": bool(np.linalg.norm(robot.position - robot.home) <= home_tol),
            "endurance_left_s": round(robot.endurance_remaining_s, 1),
            "final_status": mission.agents[name].root.status.value,
            "coverage_fraction": last.robots[name],
            "safety_triggers": dict(sorted(triggers[name].items())),
            "messages_sent": robot.radio.sent,
            "messages_undelivered": robot.radio.pending,
            **mission.robot_figures(name),
        })
    sim_time = mission.finished_s or mission.clock.now_s
    return {
        "scenario": mission.scenario.name,
        "seed": mission.seed,
        "succeeded": mission.succeeded,
        "sim_time_s": round(sim_time, 3),
        "wall_time_s": round(wall_time_s, 3),
        "real_time_factor": round(sim_time / wall_time_s, 1) if wall_time_s > 0 else None,
        "coverage_fraction": last.team,
        "base_coverage_fraction": last.base,
        **mission.world_figures(),
        "robots": robots,
        **mission.wall_clock_figures(),
    }


def strip_wall_clock(rep: dict[str, Any]) -> dict[str, Any]:
    """The report without its wall-clock fields, for comparing runs."""
    return {k: v for k, v in rep.items() if k not in WALL_CLOCK_FIELDS}


def write_outputs(mission: Mission, out: Path, wall_time_s: float) -> dict[str, Any]:
    """Write every output of the run into ``out`` and return the report."""
    out.mkdir(parents=True, exist_ok=True)
    rep = report(mission, wall_time_s)
    (out / "report.json").write_text(json.dumps(rep, indent=2, sort_keys=False) + "\n")
    with open(out / "log.jsonl", "w") as f:
        for e in mission.state.events:
            f.write(json.dumps(e, sort_keys=False) + "\n")
    if isinstance(mission.world, GraphWorld):
        plot_graph_map(mission, out / "map.png")
        plot_coverage(mission, out / "coverage.png", "fraction of locations explored")
    else:
        plot_map(mission, out / "map.png")
        plot_coverage(mission, out / "coverage.png")
    for name, agent in mission.agents.items():
        render_tree(agent.root, "txt", out / f"tree_{name}.txt")
        render_tree(agent.root, "svg", out / f"tree_{name}.svg")
    return rep


def _top_down(mask: np.ndarray) -> np.ndarray:
    return mask.any(axis=2).T


def plot_map(mission: Mission, path: Path) -> None:
    """Top-down map: free space, what the team saw, walls, paths, frontiers, radio links."""
    world = mission.world
    extent = (world.origin[0], world.origin[0] + world.free.shape[0] * world.voxel_size_m,
              world.origin[1], world.origin[1] + world.free.shape[1] * world.voxel_size_m)
    fig, ax = plt.subplots(figsize=(9, 9 * (extent[3] - extent[2]) / max(extent[1] - extent[0], 1e-6) + 0.8))
    truth = np.zeros(world.free.size, dtype=bool)
    truth[mission.truth] = True
    seen = np.zeros(world.free.shape, dtype=bool)
    walls = np.zeros(world.free.shape, dtype=bool)
    for robot in mission.robots.values():
        seen |= robot.onboard_map.occupancy == 0
        walls |= robot.onboard_map.occupancy == 1
    img = np.ones(world.free.shape[:2][::-1] + (3,))
    img[_top_down(truth.reshape(world.free.shape))] = (0.85, 0.85, 0.85)
    img[_top_down(seen)] = (0.72, 0.84, 0.95)
    img[_top_down(walls) & ~_top_down(seen)] = (0.35, 0.35, 0.35)
    ax.imshow(img, origin="lower", extent=extent, interpolation="nearest")
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (name, robot) in enumerate(mission.robots.items()):
        trail = robot.traversed_path
        ax.plot(trail[:, 0], trail[:, 1], "-", lw=1.3, color=colours[i % len(colours)], label=f"{name} path")
        m = robot.onboard_map
        front = frontier_voxels(Grid(m.occupancy, m.origin, m.voxel_size_m))
        if len(front):
            pts = m.origin + (np.stack(np.unravel_index(front[::5], m.shape), axis=1) + 0.5) * m.voxel_size_m
            ax.plot(pts[:, 0], pts[:, 1], ".", ms=1.5, color="red", label=f"{name} frontiers" if i == 0 else None)
        pos = np.array([s.positions[name] for s in mission.state.samples])
        linked = np.array([s.linked[name] for s in mission.state.samples])
        ax.plot(pos[linked, 0], pos[linked, 1], "o", ms=3, color="green", label="radio link to base" if i == 0 else None)
    ax.plot(*mission.base_position[:2], "k^", ms=9, label="base station")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{mission.scenario.name}: team coverage {mission.state.samples[-1].team:.0%}")
    ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_graph_map(mission: Mission, path: Path) -> None:
    """A graph world from above: tunnels, communication edges, the locations the team
    explored and those known at the base station, robot paths, the base station."""
    world = mission.world
    xyz = {s: world.pos(s) for s in world.graph.nodes}
    span = np.ptp(np.array(list(xyz.values()))[:, :2], axis=0) + 1.0
    fig, ax = plt.subplots(figsize=(9, min(max(9 * span[1] / span[0], 3.0), 12) + 0.8))
    for u, v in sorted(world.communication):
        ax.plot([xyz[u][0], xyz[v][0]], [xyz[u][1], xyz[v][1]], ":", lw=0.6, color="0.75")
    for u, v in world.graph.edges:
        ax.plot([xyz[u][0], xyz[v][0]], [xyz[u][1], xyz[v][1]], "-", lw=2.5, color="0.8", zorder=1)
    team = set().union(*(r.explored for r in mission.robots.values()))
    st = mission.base_state()
    at_base = st.knowledge.topology.explored if st is not None else set()
    for group, style, label in ((set(xyz) - team, dict(color="0.7", ms=4), "unexplored"),
                                (team - at_base, dict(color="tab:orange", ms=6), "explored, not yet at base"),
                                (team & at_base, dict(color="tab:blue", ms=6), "known at base station")):
        pts = np.array([xyz[s] for s in sorted(group)]).reshape(-1, 3)
        ax.plot(pts[:, 0], pts[:, 1], "o", label=label, zorder=2, **style)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (name, robot) in enumerate(mission.robots.items()):
        trail = robot.traversed_path
        ax.plot(trail[:, 0], trail[:, 1], "-", lw=1, alpha=0.6, color=colours[i % len(colours)], zorder=3,
                label=name if len(mission.robots) <= 10 else None)
    ax.plot(*mission.base_position[:2], "k^", ms=10, label="base station", zorder=4)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    last = mission.state.samples[-1]
    ax.set_title(f"{mission.scenario.name}: {last.team:.0%} of locations explored, {last.base:.0%} known at base")
    ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_coverage(mission: Mission, path: Path, ylabel: str = "fraction of free volume observed") -> None:
    """Explored fraction over sim time: team, base station, robots."""
    s = mission.state.samples
    t = np.array([x.t for x in s]) / 60.0
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, [x.team for x in s], lw=2, label="team")
    ax.plot(t, [x.base for x in s], lw=2, ls="--", label="known at base station")
    if len(mission.robots) > 1:
        for name in mission.robots:
            ax.plot(t, [x.robots[name] for x in s], lw=1, label=name)
    ax.set_xlabel("sim time (min)")
    ax.set_ylabel(ylabel)
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
