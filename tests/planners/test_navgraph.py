import numpy as np

from delve.planners.navgraph import aerial_graph, legged_graph
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

VOX = 0.2


def corridor(length=60, width=15, height=15, slope_cells_per_step=0, known=True) -> Grid:
    """Rock everywhere except a corridor along x whose floor may rise stepwise."""
    occ = np.full((length, width + 6, height + 30), OCCUPIED, dtype=np.int8)
    for i in range(length):
        floor = 2 + (i * slope_cells_per_step if slope_cells_per_step else 0)
        floor = int(floor)
        occ[i, 3 : 3 + width, floor : floor + height] = FREE
    if not known:
        occ[length // 2 :] = UNKNOWN
    return Grid(occ, np.zeros(3), VOX)


def legged(grid, **kw):
    args = dict(body_height_m=0.5, radius_m=0.4, max_step_m=0.3, max_inclination_deg=35.0)
    args.update(kw)
    return legged_graph(grid, **args)


def test_legged_nodes_stand_on_the_floor_away_from_walls():
    g = legged(corridor())
    assert len(g) > 0
    z = g.positions[:, 2]
    assert np.allclose(z, 2 * VOX + 0.5)
    y = g.positions[:, 1]
    assert y.min() >= 3 * VOX + 0.4 - 1e-9 and y.max() <= (3 + 15) * VOX - 0.4 + 1e-9


def test_legged_path_along_corridor():
    grid = corridor()
    g = legged(grid)
    src = g.nearest(np.array([0.5, 2.1, 0.9]), 1.0)
    dst = g.nearest(np.array([11.5, 2.1, 0.9]), 1.0)
    dist, pred = g.shortest_paths(src)
    assert np.isfinite(dist[dst])
    path = g.path(pred, dst)
    assert np.linalg.norm(path[0] - g.positions[src]) < 1e-9
    assert abs(dist[dst] - 11.0) < 0.6


def test_legged_refuses_steep_slope_but_takes_gentle_one():
    steep = corridor(slope_cells_per_step=1)  # 45 degrees
    assert len(legged(steep)) == 0 or np.ptp(legged(steep).positions[:, 0]) < 1.0
    gentle = legged(corridor(slope_cells_per_step=0.5))  # 26.6 degrees
    src = gentle.nearest(gentle.positions[np.argmin(gentle.positions[:, 0])], 0.1)
    dist, _ = gentle.shortest_paths(src)
    far = np.argmax(gentle.positions[:, 0])
    assert np.isfinite(dist[far]) and gentle.positions[far, 0] > 10


def test_unknown_space_is_not_walkable():
    g = legged(corridor(known=False))
    assert g.positions[:, 0].max() < 30 * VOX


def test_aerial_graph_keeps_a_margin_and_connects():
    grid = corridor()
    g = aerial_graph(grid, radius_m=0.4)
    assert len(g) > 0
    src, dst = np.argmin(g.positions[:, 0]), np.argmax(g.positions[:, 0])
    dist, _ = g.shortest_paths(int(src))
    assert np.isfinite(dist[dst])
    # no rock within the body radius of any node
    assert g.positions[:, 1].min() >= 3 * VOX + 0.4

