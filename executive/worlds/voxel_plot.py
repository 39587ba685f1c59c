"""The top-down map of a run on a voxel world (``map.png``)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.ndimage import binary_dilation, find_objects, label, maximum_filter1d  # noqa: E402

from ...planners.frontier import FRONTIER_DEPTH, frontier_voxels  # noqa: E402
from ...planners.navgraph import FACES, Voxels  # noqa: E402
from ...planners.occupancy import OCCUPIED, UNKNOWN, Grid  # noqa: E402
from ..colours import robot_colour  # noqa: E402
from .height_bands import ALL_HEIGHTS, HeightBand, height_bands  # noqa: E402

if TYPE_CHECKING:
    from ..runner import Mission


def _top_down(mask: np.ndarray) -> np.ndarray:
    return mask.any(axis=2).T


#: A column counts as seen at a height when the team knows one of its voxels (free or rock)
#: within this much above or below (m): a drift's height, well under the 12-15 m between
#: the levels of a two-level mine.
SEEN_BAND_M = 3.0
#: Open edges shorter than this (m, in the top view) are not drawn: the single columns at
#: the corners of a wall's voxel steps that no ray reached.
MIN_EDGE_M = 1.0
#: Columns beyond a frontier voxel that must be unseen for it to open onto unseen ground:
#: the explorers' :data:`~delve.planners.frontier.FRONTIER_DEPTH` and two more.
OPEN_STRIP = FRONTIER_DEPTH + 2
#: The picture's height (inches) that views of several levels, one under the other, keep to.
MAX_HEIGHT_IN = 60.0


def seen_ground(maps: list[np.ndarray], voxel_size_m: float, band_m: float = SEEN_BAND_M) -> np.ndarray:
    """Whether the team (occupancy grids ``maps``, one shape) knows some voxel of each
    voxel's column within ``band_m`` above or below it: the ground a top view shows as seen."""
    known = np.zeros(maps[0].shape, dtype=bool)
    for occupancy in maps:
        known |= occupancy != UNKNOWN
    return maximum_filter1d(known, size=2 * round(band_m / voxel_size_m) + 1, axis=2)


def open_frontiers(grid: Grid, voxels: np.ndarray, seen: np.ndarray, rock: np.ndarray) -> np.ndarray:
    """The frontier ``voxels`` (flat indices of ``grid``) that open sideways onto ground nobody
    saw: along one of the four horizontal faces, the columns beyond the voxel in a strip
    :data:`OPEN_STRIP` deep and three wide are unseen at its height (``seen``:
    :func:`seen_ground`; beyond the grid counts as seen), and no map of the team holds the
    voxel as rock (``rock``: a ray that grazed a wall leaves its surface free in one map, a
    wall in another). Three wide, because a diagonal wall's voxels touch only at their edges.

    Why: a top view shows which ground was seen, and a frontier tells its reader something
    only where the seen area ends in unseen ground (a tunnel's mouth, the far end of a drift
    seen from afar, a branch). Drawn, the unknown straight above or below seen ground (a
    roof the legged robot's 30° LiDAR never saw, a floor under a flying robot) and behind
    walls carpeted explored drifts with dots. The explorers' minimum cluster size
    (``frontier_clusters``, 10 voxels) does not tell them apart: a carpet under a roof is
    one large cluster, and at 0.4 m voxels the rays' stripes at a drift's far end are small
    ones. A shaft's mouth in a seen roof or floor is not drawn either: a top view cannot
    show it apart from the drift around it."""
    v = Voxels(voxels, grid.shape)
    flat_seen = seen.reshape(-1)
    opens = np.zeros(len(voxels), dtype=bool)
    for dx, dy, _ in FACES[:4]:
        unseen = np.ones(len(voxels), dtype=bool)
        for k in range(1, OPEN_STRIP + 1):
            for side in (-1, 0, 1):   # across: (dy, -dx)
                unseen &= ~v.at(flat_seen, (dx * k + dy * side, dy * k - dx * side, 0), True)
        opens |= unseen
    return voxels[opens & ~rock.reshape(-1)[voxels]]


def long_edges(columns: np.ndarray, voxel_size_m: float, min_length_m: float = MIN_EDGE_M) -> np.ndarray:
    """The ``columns`` (a top view's mask) in groups at least ``min_length_m`` long (along x or
    y); columns with up to two others between them join a group (at a drift's far end, the
    rays' stripes end one or two unseen columns apart)."""
    labels, _ = label(binary_dilation(columns, np.ones((3, 3), dtype=bool)))
    labels = np.where(columns, labels, 0)
    length = [max(s.stop - s.start for s in box) * voxel_size_m for box in find_objects(labels)]
    keep = np.array([False] + [n >= min_length_m for n in length])
    return keep[labels]


def frontiers_left(mission: "Mission", bands: list[HeightBand]) -> list[np.ndarray]:
    """Per height band of ``bands``, (N, 2) world x, y of the
    columns drawn as frontiers left: each robot's frontier voxels in the band that open onto
    ground the team did not see (:func:`open_frontiers`), seen from above, in edges of at
    least :data:`MIN_EDGE_M` (:func:`long_edges`)."""
    maps = [robot.onboard_map for robot in mission.robots.values()]
    if not maps:
        return [np.zeros((0, 2)) for _ in bands]
    seen = seen_ground([m.occupancy for m in maps], maps[0].voxel_size_m)
    rock = np.zeros(maps[0].shape, dtype=bool)
    for m in maps:
        rock |= m.occupancy == OCCUPIED
    opening = np.concatenate([open_frontiers(grid, frontier_voxels(grid), seen, rock)
                              for grid in (Grid(m.occupancy, m.origin, m.voxel_size_m) for m in maps)])
    i, j, k = np.unravel_index(opening, maps[0].shape)
    vs, origin = maps[0].voxel_size_m, np.asarray(maps[0].origin, float)
    height = origin[2] + (k + 0.5) * vs
    out = []
    for band in bands:
        columns = np.zeros(maps[0].shape[:2], dtype=bool)
        inside = band.holds_heights(height)
        columns[i[inside], j[inside]] = True
        out.append(origin[:2] + (np.argwhere(long_edges(columns, vs)) + 0.5) * vs)
    return out


#: The fills of a top view: free space nobody saw, free space the team saw, mapped rock.
FREE_UNSEEN_RGB, SEEN_RGB, WALL_RGB = (0.85, 0.85, 0.85), (0.72, 0.84, 0.95), (0.35, 0.35, 0.35)


def plot_voxel_map(mission: "Mission", truth_voxels: np.ndarray, path: Path) -> None:
    """Top-down map: free space, what the team saw, walls, paths (flying robots' dashed, on
    top), the frontiers left at the end that open onto unseen ground (:func:`frontiers_left`),
    radio links (under the paths). A world of several levels (:func:`height_bands` of the
    reachable free space, ``truth_voxels``) gets one top view per level, the lowest first,
    each drawing only what lies at its heights."""
    world = mission.world
    truth = np.zeros(world.free.size, dtype=bool)
    truth[truth_voxels] = True
    truth = truth.reshape(world.free.shape)
    bands = height_bands(truth, float(world.origin[2]), world.voxel_size_m)
    extent = (world.origin[0], world.origin[0] + world.free.shape[0] * world.voxel_size_m,
              world.origin[1], world.origin[1] + world.free.shape[1] * world.voxel_size_m)
    aspect = (extent[3] - extent[2]) / max(extent[1] - extent[0], 1e-6)
    # Narrower views when several would make the picture taller than MAX_HEIGHT_IN.
    width = min(9.0, MAX_HEIGHT_IN / len(bands) / max(aspect, 1e-6))
    fig, axes = plt.subplots(len(bands), 1, figsize=(width, (width * aspect + 0.8) * len(bands)), squeeze=False)
    seen = np.zeros(world.free.shape, dtype=bool)
    walls = np.zeros(world.free.shape, dtype=bool)
    for robot in mission.robots.values():
        seen |= robot.onboard_map.occupancy == 0
        walls |= robot.onboard_map.occupancy == 1
    title = f"{mission.scenario.name}: team coverage {mission.state.samples[-1].team:.0%}"
    for k, (ax, band, left) in enumerate(zip(axes[:, 0], bands, frontiers_left(mission, bands))):
        at = band.layers(float(world.origin[2]), world.voxel_size_m, world.free.shape[2])
        _draw_band(ax, mission, band, (truth[..., at], seen[..., at], walls[..., at]), extent, left)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        if len(bands) > 1:
            level = f"level {k + 1} of {len(bands)}: {band.label}"
            ax.set_title(f"{title}\n{level}" if k == 0 else level)
            ax.set_xlim(extent[0], extent[1])   # the same frame in every view
            ax.set_ylim(extent[2], extent[3])
        else:
            ax.set_title(title)
        # Beside the map, not on it: with a team's many entries it hid part of the world.
        # A level's beside its view: its counts are the level's.
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def _draw_band(ax: Any, mission: "Mission", band: HeightBand, grids: tuple[np.ndarray, np.ndarray, np.ndarray],
               extent: tuple[float, ...], left: np.ndarray) -> None:
    """One top view: the ``grids`` (truth, seen, walls: the voxel layers at the band's
    heights), and what lies in the band of the paths, frontiers left (``left``), radio
    links, base station, artifacts and the team strategy's marks."""
    truth, seen, walls = grids
    img = np.ones(truth.shape[:2][::-1] + (3,))
    saw = _top_down(seen)
    rock = _top_down(walls) & ~saw
    fills = ((_top_down(truth) & ~saw & ~rock, FREE_UNSEEN_RGB, "free space the team did not see"),
             (saw, SEEN_RGB, "free space the team saw"), (rock, WALL_RGB, "rock the team mapped"))
    for where, rgb, label in fills:
        img[where] = rgb
        if where.any():
            ax.fill([], [], color=rgb, label=label)   # a legend entry for the fill
    ax.imshow(img, origin="lower", extent=extent, interpolation="nearest")
    for i, (name, robot) in enumerate(mission.robots.items()):
        trail = np.array(robot.traversed_path, float).reshape(-1, 3)
        inside = band.holds(trail)
        if band is not ALL_HEIGHTS and inside.sum() < 2:
            continue   # no line of it at these heights
        trail[~inside] = np.nan   # the path's parts at other heights leave gaps
        aerial = robot.mobility.aerial
        # A flying robot's path dashed and above the ground robots' solid ones: where it flew
        # over a ground robot's path, that path shows between its dashes.
        ax.plot(trail[:, 0], trail[:, 1], ls=(0, (4, 2.5)) if aerial else "-", lw=1.3,
                color=robot_colour(i), zorder=2.2 if aerial else 2.0,
                label=f"{name} path (flying)" if aerial else f"{name} path")
    ax.plot(left[:, 0], left[:, 1], ".", ms=2, color="red", zorder=3,
            label=f"frontiers left: where the seen area opens\nonto unseen ground (edges >= {MIN_EDGE_M:g} m)"
            if len(left) else "no frontiers left: the seen area nowhere\nopens onto unseen ground")
    links = [band.within(np.array([s.positions[name] for s in mission.state.samples if s.linked[name]]))
             for name in mission.robots]
    # Labelled once: on the first robot with links here (robot 0 on a world of one level).
    first = next((i for i, p in enumerate(links) if len(p)), 0 if band is ALL_HEIGHTS else None)
    for i, pos in enumerate(links):
        # Gold with a dark edge: no robot's path has that colour.
        ax.plot(pos[:, 0], pos[:, 1], "o", ms=3.5, mfc="gold", mec="0.2", mew=0.5,
                zorder=1.9,   # under the paths
                label="radio link to base" if i == first else None)
    if band.holds(mission.base_position).all():
        ax.plot(*mission.base_position[:2], "k^", ms=9, label="base station")
    mission.artifacts.draw(ax, mission, band)
    mission.team.draw(ax, mission, band)
