"""delve.executive.worlds.voxel_preview: the pictures of a world before a run (``delve world
--preview``); the whole command is tried in tests/executive/test_world_check.py."""
from __future__ import annotations

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import open3d as o3d  # noqa: E402
from delve.executive.worlds.voxel_preview import draw_preview  # noqa: E402
from delve.sim.world import World  # noqa: E402


def test_a_two_level_world_has_a_top_view_per_level_with_its_own_starts(tmp_path, monkeypatch):
    free = np.zeros((60, 20, 100), dtype=bool)
    free[1:59, 5:15, 2:12] = True                          # a drift at 0.4-2.4 m
    free[1:59, 5:15, 80:90] = True                         # another right over it at 16-18 m
    free[28:31, 8:11, 12:80] = True                        # a shaft between them
    world = World(name="two", voxel_size_m=0.2, origin=np.zeros(3), free=free,
                  mesh=o3d.geometry.TriangleMesh(), start=np.array([1.0, 2.0, 0.4]))
    below = SimpleNamespace(name="anymal", landing=SimpleNamespace(problem=None, moved_m=0.0,
                                                                   start=np.array([1.0, 2.0, 0.4])))
    above = SimpleNamespace(name="uav", landing=SimpleNamespace(problem=None, moved_m=0.0,
                                                                start=np.array([2.0, 2.0, 16.2])))
    scenario = SimpleNamespace(name="two", base_position=np.array([0.5, 2.0, 0.4]))
    figures, close = [], plt.close
    monkeypatch.setattr(plt, "close", figures.append)
    paths = draw_preview(scenario, world, [below, above], tmp_path)
    assert [p.name for p in paths] == ["top.png", "side.png"] and all(p.stat().st_size > 0 for p in paths)
    top, side = figures
    low, high = top.axes
    assert "level 1 of 2: heights 0 to" in low.get_title() and "level 2 of 2: heights" in high.get_title()
    assert [t.get_text() for t in low.texts] == ["anymal"] and [t.get_text() for t in high.texts] == ["uav"]
    assert "base station" in [h.get_label() for h in low.get_lines()]
    assert "base station" not in [h.get_label() for h in high.get_lines()]
    assert len(side.axes) == 1 and [t.get_text() for t in side.axes[0].texts] == ["anymal", "uav"]
    for figure in figures:
        close(figure)
