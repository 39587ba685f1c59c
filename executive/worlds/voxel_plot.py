"""The top-down map of a run on a voxel world (``map.png``)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ...planners.frontier import (MAX_GOAL_OFFSET_M, VIEWPOINT_SPACING_M, frontier_voxels,  # noqa: E402
                                  observable_frontiers, viewpoint_nodes)
from ...planners.occupancy import Grid  # noqa: E402
from ...skills.navigation import navigator  # noqa: E402

if TYPE_CHECKING:
    from ..runner import Mission


def _top_down(mask: np.ndarray) -> np.ndarray:
    return mask.any(axis=2).T


def frontiers_left(mission: "Mission", name: str) -> np.ndarray:
    """World centres of the frontier voxels of robot ``name``'s map that its sensor could
    still observe from a node it can reach (what its frontier explorer would still
    go to: :func:`~delve.planners.frontier.observable_frontiers`); all frontier voxels
    when the robot is off its navigation graph."""
    robot = mission.robots[name]
    m = robot.onboard_map
    grid = Grid(m.occupancy, m.origin, m.voxel_size_m)
    front = frontier_voxels(grid)
    agent = mission.agents.get(name)
    plan = navigator(agent.ctx, robot).from_robot(force=True) if agent is not None else None
    if plan is not None:
        views = plan.graph.positions[viewpoint_nodes(plan.graph, plan.distances, VIEWPOINT_SPACING_M)]
        front = observable_frontiers(grid, front, views, view_up_deg=robot.view_up_deg,
                                     reach_m=MAX_GOAL_OFFSET_M)
    return grid.to_world(np.stack(np.unravel_index(front, m.shape), axis=1))


def plot_voxel_map(mission: "Mission", truth_voxels: np.ndarray, path: Path) -> None:
    """Top-down map: free space, what the team saw, walls, paths, the frontiers left at
    the end (:func:`frontiers_left`), radio links."""
    world = mission.world
    extent = (world.origin[0], world.origin[0] + world.free.shape[0] * world.voxel_size_m,
              world.origin[1], world.origin[1] + world.free.shape[1] * world.voxel_size_m)
    fig, ax = plt.subplots(figsize=(9, 9 * (extent[3] - extent[2]) / max(extent[1] - extent[0], 1e-6) + 0.8))
    truth = np.zeros(world.free.size, dtype=bool)
    truth[truth_voxels] = True
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
        pts = frontiers_left(mission, name)[::5]
        if len(pts):
            ax.plot(pts[:, 0], pts[:, 1], ".", ms=1.5, color="red", label="frontiers left" if i == 0 else None)
        pos = np.array([s.positions[name] for s in mission.state.samples])
        linked = np.array([s.linked[name] for s in mission.state.samples])
        ax.plot(pos[linked, 0], pos[linked, 1], "o", ms=3, color="green", label="radio link to base" if i == 0 else None)
    ax.plot(*mission.base_position[:2], "k^", ms=9, label="base station")
    mission.artifacts.draw(ax, mission)
    mission.team.draw(ax, mission)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{mission.scenario.name}: team coverage {mission.state.samples[-1].team:.0%}")
    # Beside the map, not on it: with a team's many entries it hid part of the world.
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
