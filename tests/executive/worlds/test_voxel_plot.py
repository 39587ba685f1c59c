"""delve.executive.worlds.voxel_plot: what map.png draws of a voxel run (the frontiers left that
open onto unseen ground, the paths of flying robots over those of ground robots)."""
from __future__ import annotations

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from delve.executive.worlds import voxel_plot  # noqa: E402
from delve.executive.worlds.voxel_plot import (long_edges, open_frontiers, plot_voxel_map,  # noqa: E402
                                               seen_ground)
from delve.planners.frontier import frontier_voxels  # noqa: E402
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid  # noqa: E402

VOXEL = 0.2
MOUTH = 40   # the drift's air is seen up to x index 39; beyond it, a tunnel nobody went into


def drift_seen_without_its_roof() -> np.ndarray:
    """A drift along x (y 1-3 m): floor, walls and end wall seen, air seen up to 2.4 m, its
    roof never (the unknown above carpets the drift with frontier voxels); at x = 8 m the seen
    part ends in an unexplored tunnel."""
    occ = np.full((60, 24, 25), UNKNOWN, dtype=np.int8)
    occ[1:MOUTH, 5:15, 2:12] = FREE
    occ[1:MOUTH, 5:15, 1] = OCCUPIED        # floor
    occ[1:MOUTH, (4, 15), 1:12] = OCCUPIED  # walls
    occ[0, 4:16, 1:12] = OCCUPIED           # the drift's end behind the base
    return occ


def mission_of(robots: dict[str, tuple[np.ndarray, np.ndarray, bool]]) -> SimpleNamespace:
    """A finished run on the drift's grid: robots by name, (onboard occupancy, path, flies)."""
    first = next(iter(robots.values()))[0]
    origin = np.zeros(3)
    maps = {n: SimpleNamespace(occupancy=occ, origin=origin, voxel_size_m=VOXEL, shape=occ.shape)
            for n, (occ, _, _) in robots.items()}
    bots = {n: SimpleNamespace(onboard_map=maps[n], traversed_path=p, mobility=SimpleNamespace(aerial=flies))
            for n, (_, p, flies) in robots.items()}
    sample = SimpleNamespace(positions={n: path[-1] for n, (_, path, _) in robots.items()},
                             linked={n: False for n in robots}, team=0.5)
    return SimpleNamespace(world=SimpleNamespace(origin=origin, free=first >= FREE, voxel_size_m=VOXEL),
                           robots=bots, agents={}, state=SimpleNamespace(samples=[sample], events=[]),
                           base_position=np.array([0.5, 2.0, 0.3]), scenario=SimpleNamespace(name="drift"),
                           artifacts=SimpleNamespace(draw=lambda ax, mission, band: None),
                           team=SimpleNamespace(draw=lambda ax, mission, band: None))


def drawn_views(mission, tmp_path, monkeypatch) -> list[dict[str, matplotlib.lines.Line2D]]:
    """map.png's lines by label, per top view (the figure kept open)."""
    figures, close = [], plt.close
    monkeypatch.setattr(plt, "close", figures.append)
    truth = np.flatnonzero(mission.world.free.reshape(-1))
    plot_voxel_map(mission, truth, tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 0
    views = [{line.get_label(): line for line in ax.get_lines()} for ax in figures[0].axes]
    close(figures[0])
    return views


def drawn(mission, tmp_path, monkeypatch) -> dict[str, matplotlib.lines.Line2D]:
    """map.png's lines by label, of a world of one level."""
    (view,) = drawn_views(mission, tmp_path, monkeypatch)
    return view


PATH = np.array([[0.5, 2.0, 0.6], [7.5, 2.0, 0.6]])


def test_the_roof_nobody_saw_is_no_frontier_left_and_the_tunnel_mouth_is(tmp_path, monkeypatch):
    occ = drift_seen_without_its_roof()
    i, _, k = np.unravel_index(frontier_voxels(Grid(occ, np.zeros(3), VOXEL)), occ.shape)
    assert ((k == 11) & (i < MOUTH - 5)).sum() > 300                        # the carpet under the roof
    lines = drawn(mission_of({"anymal": (occ, PATH, False)}), tmp_path, monkeypatch)
    (label,) = [k for k in lines if k.startswith("frontiers left")]
    dots = lines[label].get_xydata()
    assert np.allclose(dots[:, 0], (MOUTH - 0.5) * VOXEL)                    # none under the roof;
    assert np.allclose(np.sort(dots[:, 1]), (np.arange(5, 15) + 0.5) * VOXEL)  # one a column of the mouth
    assert "opens\nonto unseen ground" in label and ">= 1 m" in label


def test_a_wall_one_map_holds_as_rock_is_no_frontier_though_another_grazed_it_free():
    occ = drift_seen_without_its_roof()
    grazed = occ.copy()
    grazed[10:30, 15, 2:12] = FREE                                           # the wall's surface, free
    teammate = occ.copy()
    grid = Grid(grazed, np.zeros(3), VOXEL)
    front = frontier_voxels(grid)
    alone = open_frontiers(grid, front, seen_ground([grazed], VOXEL), grazed == OCCUPIED)
    team = open_frontiers(grid, front, seen_ground([grazed, teammate], VOXEL),
                          (grazed == OCCUPIED) | (teammate == OCCUPIED))
    i, j, _ = np.unravel_index(alone, occ.shape)
    assert ((j == 15) & (i >= 10) & (i < 30)).any()                          # alone, it opens onto the rock
    i, j, _ = np.unravel_index(team, occ.shape)
    assert not (j == 15).any() and (i == MOUTH - 1).all()                   # with its wall: the mouth alone


def test_a_wall_voxel_no_ray_hit_between_two_that_rays_hit_is_no_opening():
    occ = np.full((30, 30, 6), UNKNOWN, dtype=np.int8)
    i, j = np.meshgrid(np.arange(30), np.arange(30), indexing="ij")
    occ[i + j < 30, 1:] = FREE                                              # free below a diagonal wall,
    occ[i + j < 30, 0] = OCCUPIED                                           # on a seen floor;
    occ[(i + j == 30) & (i % 2 == 0), :] = OCCUPIED                         # every other wall voxel hit
    grid = Grid(occ, np.zeros(3), VOXEL)
    front = frontier_voxels(grid)
    fi, fj, _ = np.unravel_index(front, occ.shape)
    assert ((fi + fj == 29) & (fi > 5) & (fj > 5)).any()                    # the voxels before the gaps
    assert len(open_frontiers(grid, front, seen_ground([occ], VOXEL), occ == OCCUPIED)) == 0


def test_ground_seen_a_level_below_is_unseen_ground_on_this_level():
    occ = np.full((4, 4, 80), UNKNOWN, dtype=np.int8)
    occ[:, :, 0] = OCCUPIED                                                 # a floor seen 14 m below
    seen = seen_ground([occ], VOXEL)
    assert seen[0, 0, int(voxel_plot.SEEN_BAND_M / VOXEL)] and not seen[0, 0, 70]


def test_short_open_edges_are_left_out_and_stripes_two_columns_apart_join():
    columns = np.zeros((30, 30), dtype=bool)
    columns[2, 2] = columns[2, 3] = True                                    # a speck of 0.4 m
    columns[10, 5:15:3] = True                                              # ray stripes' ends, 0.6 m apart
    columns[20, 5:12] = True                                                # an edge of 1.4 m
    columns[25, 5:15:4] = True                                              # three specks, 0.8 m apart
    kept = long_edges(columns, VOXEL)
    assert not kept[2].any() and kept[10].sum() == 4 and kept[20].sum() == 7 and not kept[25].any()


def test_no_frontier_left_says_so(tmp_path, monkeypatch):
    occ = drift_seen_without_its_roof()
    occ[MOUTH, 4:16, 1:12] = OCCUPIED                                       # the drift ends here
    lines = drawn(mission_of({"anymal": (occ, PATH, False)}), tmp_path, monkeypatch)
    (label,) = [k for k in lines if "frontiers left" in k]
    assert label.startswith("no frontiers left") and len(lines[label].get_xdata()) == 0


def test_a_flying_robots_path_is_dashed_above_the_ground_robots_where_they_overlap(tmp_path, monkeypatch):
    occ = drift_seen_without_its_roof()
    lines = drawn(mission_of({"anymal": (occ, PATH, False), "uav": (occ, PATH + [0, 0, 1.0], True)}),
                  tmp_path, monkeypatch)
    ground, (flying,) = lines["anymal path"], [v for k, v in lines.items() if k.startswith("uav path")]
    assert ground.get_linestyle() == "-" and flying.get_linestyle() == "--"
    assert flying.get_zorder() > ground.get_zorder()                        # the ground path between dashes
    assert ground.get_color() != flying.get_color()
    labels = list(lines)                                                    # the paths first in the legend
    assert labels.index("uav path (flying)") < labels.index(next(k for k in labels if "frontiers left" in k))


def test_each_level_of_a_two_level_world_has_its_own_top_view_with_what_lies_there(tmp_path, monkeypatch):
    occ = np.full((70, 24, 100), UNKNOWN, dtype=np.int8)
    for floor in (1, 79):                                                   # the lower drift, z 0.4-2.4 m,
        occ[0:60, 4:16, floor:floor + 12] = OCCUPIED                        # the upper one over it, 16-18 m,
        occ[1:59, 5:15, floor + 1:floor + 11] = FREE                        # seen with their walls
    occ[27:32, 7:12, 11:80] = OCCUPIED
    occ[28:31, 8:11, 11:80] = FREE                                          # the shaft between them
    occ[59, 5:15, 80:90] = FREE                                             # the upper drift goes on, unseen
    lower = np.array([[0.5, 2.0, 1.0], [11.0, 2.0, 1.0]])
    climb = np.array([[0.5, 2.0, 1.0], [5.9, 1.9, 1.0], [5.9, 1.9, 17.0], [11.0, 2.0, 17.0]])
    mission = mission_of({"anymal": (occ, lower, False), "uav": (occ, climb, True)})
    bands = []
    mission.team = SimpleNamespace(draw=lambda ax, mission, band: bands.append(band))
    low, high = drawn_views(mission, tmp_path, monkeypatch)
    assert len(bands) == 2 and bands[0].hi_m == bands[1].lo_m and 2.4 < bands[0].hi_m < 16.0
    assert "base station" in low and "base station" not in high
    assert np.allclose(low["anymal path"].get_xydata(), lower[:, :2]) and "anymal path" not in high
    flown_low, flown_high = low["uav path (flying)"].get_xydata(), high["uav path (flying)"].get_xydata()
    assert np.allclose(flown_low[:2], climb[:2, :2]) and np.isnan(flown_low[2:]).all()  # below: up to the shaft
    assert np.isnan(flown_high[:2]).all() and np.allclose(flown_high[2:], climb[2:, :2])
    (label,) = [k for k in high if k.startswith("frontiers left")]         # the upper drift's open end
    assert np.allclose(high[label].get_xdata(), 59.5 * VOXEL)
    (label,) = [k for k in low if "frontiers left" in k]                 # nothing open below
    assert label.startswith("no frontiers left") and len(low[label].get_xdata()) == 0
