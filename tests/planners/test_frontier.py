import numpy as np

from delve.planners.frontier import (frontier_clusters, frontier_voxels, nearest_frontier,
                                    observable_frontiers, viewpoint_nodes)
from delve.planners.navgraph import legged_graph
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

from .unseen_roof import drift_with_an_unseen_roof


def t_junction() -> Grid:
    """A corridor along x (known) with two unknown ends: x beyond 40 and a side branch."""
    occ = np.full((80, 60, 20), OCCUPIED, dtype=np.int8)
    occ[:, 20:35, 2:14] = FREE
    occ[10:25, 35:60, 2:14] = FREE
    occ[40:] = UNKNOWN
    occ[10:25, 45:] = UNKNOWN
    return Grid(occ, np.zeros(3), 0.2)


def test_frontier_voxels_border_unknown_space():
    grid = t_junction()
    f = frontier_voxels(grid)
    ijk = np.stack(np.unravel_index(f, grid.shape), axis=1)
    assert len(f) > 0
    assert set(np.unique(ijk[:, 0])) >= {39}
    assert np.all((ijk[:, 0] == 39) | (ijk[:, 1] == 44))
    again = frontier_voxels(grid, among=f)
    assert np.array_equal(np.sort(again), np.sort(f))


def test_clusters_and_nearest_choice():
    grid = t_junction()
    clusters = frontier_clusters(grid, frontier_voxels(grid), cluster_radius_m=0.8, min_cluster_voxels=5, max_extent_m=20.0)
    assert len(clusters) == 2
    g = legged_graph(grid, body_height_m=0.5, radius_m=0.4, max_step_m=0.3, max_inclination_deg=35)
    src = g.nearest(np.array([3.5, 5.5, 0.9]), 1.0)
    dist, _ = g.shortest_paths(src)
    goal = nearest_frontier(g, dist, clusters, max_goal_offset_m=3.0)
    assert goal is not None
    # the side branch (y ~ 9 m) is nearer to x=3.5 than the corridor's end at x=8
    assert goal.cluster.centroid[1] > 8.0
    assert goal.path_length_m > 0


def test_no_frontier_when_all_known():
    occ = np.full((20, 20, 10), OCCUPIED, dtype=np.int8)
    occ[5:15, 5:15, 2:8] = FREE
    assert len(frontier_voxels(Grid(occ, np.zeros(3), 0.2))) == 0


def viewpoints_of(grid: Grid) -> tuple:
    g = legged_graph(grid, body_height_m=0.5, radius_m=0.4, max_step_m=0.3, max_inclination_deg=35)
    dist, _ = g.shortest_paths(g.nearest(np.array([1.0, 1.5, 0.9]), 1.0))
    return g, dist, g.positions[viewpoint_nodes(g, dist)]


def test_frontiers_that_a_narrow_lidar_sees_from_nowhere_reachable_are_not_frontiers():
    # a short drift with a stub whose roof is unseen: from no node is the stub's top
    # within 15 degrees above the sensor with a clear line (the stub's walls hide it)
    short = drift_with_an_unseen_roof(6.0, 2.6, 3.8, stub=True)
    front = frontier_voxels(short)
    _, _, views = viewpoints_of(short)
    assert len(front) > 50
    assert len(observable_frontiers(short, front, views, view_up_deg=15.0, reach_m=12.0)) == 0
    # a sensor that sees straight up does observe them
    assert len(observable_frontiers(short, front, views, view_up_deg=90.0, reach_m=12.0)) == len(front)
    # the unseen roof at the end of a long drift is seen from 6 m and more along it
    long = drift_with_an_unseen_roof(20.0, 17.0, 20.0, stub=False)
    front = frontier_voxels(long)
    _, _, views = viewpoints_of(long)
    seen = observable_frontiers(long, front, views, view_up_deg=15.0, reach_m=12.0)
    assert len(front) > 50 and len(seen) >= 0.9 * len(front)
