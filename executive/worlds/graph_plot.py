"""The map of a run on a graph world (``map.png``)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..colours import robot_colour  # noqa: E402

if TYPE_CHECKING:
    from ..runner import Mission


def plot_graph_map(mission: "Mission", at_base: set[str], path: Path) -> None:
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
    for group, style, label in ((set(xyz) - team, dict(color="0.7", ms=4), "unexplored"),
                                (team - at_base, dict(color="tab:orange", ms=6), "explored, not yet at base"),
                                (team & at_base, dict(color="tab:blue", ms=6), "known at base station")):
        pts = np.array([xyz[s] for s in sorted(group)]).reshape(-1, 3)
        ax.plot(pts[:, 0], pts[:, 1], "o", label=label, zorder=2, **style)
    for i, (name, robot) in enumerate(mission.robots.items()):
        trail = robot.traversed_path
        ax.plot(trail[:, 0], trail[:, 1], "-", lw=1, alpha=0.6, color=robot_colour(i), zorder=3,
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
