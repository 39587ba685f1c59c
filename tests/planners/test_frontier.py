import numpy as np

from scipy.spatial import cKDTree

from delve.planners.frontier import (_close_blocks, clear_sight, frontier_clusters, frontier_voxels,
                                    nearest_frontier, observes, observes_samples,
                                    view_targets, viewpoint_nodes)
from delve.planners.navgraph import NavGraph
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
    goal = nearest_frontier(g, dist, clusters, grid, max_goal_offset_m=3.0)
    assert goal is not None
    # the side branch (y ~ 9 m) is nearer to x=3.5 than the corridor's end at x=8
    assert goal.cluster.centroid[1] > 8.0
    assert goal.path_length_m > 0


def test_no_frontier_when_all_known():
    occ = np.full((20, 20, 10), OCCUPIED, dtype=np.int8)
    occ[5:15, 5:15, 2:8] = FREE
    assert len(frontier_voxels(Grid(occ, np.zeros(3), 0.2))) == 0


def graph_from_start(grid: Grid) -> tuple:
    """The legged robot's graph of ``grid`` and its distances from x = 1 m."""
    g = legged_graph(grid, body_height_m=0.5, radius_m=0.4, max_step_m=0.3, max_inclination_deg=35)
    dist, _ = g.shortest_paths(g.nearest(np.array([1.0, 1.5, 0.9]), 1.0))
    return g, dist


def goal_on(grid: Grid, view_up_deg: float):
    """The goal for the largest frontier cluster of ``grid``, seen from a robot at x = 1 m."""
    g, dist = graph_from_start(grid)
    clusters = frontier_clusters(grid, frontier_voxels(grid), cluster_radius_m=0.8, min_cluster_voxels=10,
                                 max_extent_m=4.0)
    clusters = [max(clusters, key=lambda c: c.size)]
    return g, nearest_frontier(g, dist, clusters, grid, max_goal_offset_m=12.0, view_up_deg=view_up_deg,
                               min_targets=10)


def test_a_goal_under_an_unseen_roof_stands_back_where_a_narrow_lidar_sees_it():
    # the top 0.6 m of air over x = 17..20 m of a 20 m drift is unknown; the robot is at x = 1 m
    grid = drift_with_an_unseen_roof(20.0, 17.0, 20.0, stub=False)
    g, goal = goal_on(grid, 15.0)
    node = g.positions[goal.node]
    points, normals = view_targets(grid, goal.cluster.voxels)
    up = np.all(normals == 0, axis=1)  # most lie under the unknown air: their target is that air
    assert up.mean() > 0.5 and np.all(points[up, 2] >= 2.5)
    # from below, the roof air is out of a 15 degree view; the goal sees it from ~7 m back
    level = np.hypot(*(points[:, :2] - node[:2]).T)
    assert np.mean(points[:, 2] - node[2] <= level * np.tan(np.radians(15)) + 0.1) >= 0.8
    assert len(goal.targets) >= 0.8 * goal.cluster.size
    assert goal.cluster.centroid[0] - node[0] > 6.0  # (the centroid alone is in view from 4.4 m back)
    # a sensor that sees straight up goes under it
    g, up = goal_on(grid, 90.0)
    assert abs(up.cluster.centroid[0] - g.positions[up.node][0]) < 1.5  # (one candidate node per 1.2 m cell)


def test_a_frontier_a_narrow_lidar_sees_from_no_node_is_no_goal():
    # the stub's roof air is more than 15 degrees above the sensor from every node of the short drift
    grid = drift_with_an_unseen_roof(6.0, 2.6, 3.8, stub=True)
    assert len(frontier_voxels(grid)) > 50
    assert goal_on(grid, 15.0)[1] is None
    assert goal_on(grid, 90.0)[1] is not None


def test_a_frontier_in_a_wall_is_observed_from_in_front_not_along_it():
    grid = t_junction()  # the side branch's unknown end: frontier voxels facing +y at y = 8.9 m
    side = frontier_voxels(grid)
    side = side[np.unravel_index(side, grid.shape)[1] == 44]
    points, normals = view_targets(grid, side)
    assert np.all(normals == [0.0, 1.0, 0.0])
    target = points[np.argmin(np.linalg.norm(points - [3.5, 8.9, 1.5], axis=1))]
    in_front, along = target + [0.0, -4.0, 0.0], target + [-4.0, -0.5, 0.0]
    seen = observes(np.array([in_front, along]), target[None], normals[:1], 90.0, 12.0, 0.1)
    assert seen.tolist() == [True, False]


def test_a_goal_behind_a_wall_is_passed_over_for_one_with_a_clear_line():
    # two drifts along x, 1 m of rock apart, joined at their start; the top 0.6 m of air over
    # x = 17..20 m of the second is unknown. From the first drift the roof is in the view's
    # band and nearer along the graph, but the rock between hides it.
    occ = np.full((102, 34, 17), OCCUPIED, dtype=np.int8)
    occ[1:-1, 1:14, 2:15] = FREE
    occ[1:-1, 19:32, 2:15] = FREE
    occ[1:15, 14:19, 2:15] = FREE
    occ[86:101, 19:32, 12:15] = UNKNOWN
    grid = Grid(occ, np.zeros(3), 0.2)
    g, goal = goal_on(grid, 15.0)
    assert goal.cluster.centroid[1] > 3.8
    assert g.positions[goal.node][1] > 3.8  # in the second drift
    assert len(goal.targets) >= 0.8 * goal.cluster.size


def test_observes_samples_answers_as_observes_of_the_gathered_rows():
    rng = np.random.default_rng(4)
    points = rng.uniform(-15, 15, (60, 3))
    faces = np.array([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 0)], float)
    normals = faces[rng.integers(0, 5, len(points))]
    sensors = rng.uniform(-15, 15, (300, 3))
    sample = rng.integers(0, len(points), (300, 16))
    for up in (15.0, 90.0):
        want = observes(sensors[:, None, :], points[sample], normals[sample], up, 12.0, 0.1)
        assert 0 < want.sum() < want.size
        np.testing.assert_array_equal(observes_samples(sensors, points, normals, sample, up, 12.0, 0.1), want)


def test_close_blocks_are_the_kd_tree_pairs_also_at_exactly_the_radius():
    rng = np.random.default_rng(5)
    shape = (30, 40, 20)
    packed = np.unique(rng.integers(0, np.prod(shape), 4000))
    blocks = np.stack(np.unravel_index(packed, shape), axis=1)
    centres = np.array([-12.3, 4.05, 0.7]) + (blocks * 2 + 1.0) * 0.2
    for radius in (0.8, 0.4 * np.sqrt(2), 0.5):   # 0.8 and 0.57 lie on lattice distances
        want = cKDTree(centres).query_pairs(radius, output_type="ndarray")
        i, j = _close_blocks(packed, shape, centres, radius, 0.4)
        got = np.sort(np.minimum(i, j) * len(packed) + np.maximum(i, j))
        assert len(want) > 0
        np.testing.assert_array_equal(got, np.sort(want.min(axis=1) * len(packed) + want.max(axis=1)))


def test_viewpoint_nodes_are_the_first_reachable_node_of_each_cell():
    rng = np.random.default_rng(6)
    pos = rng.uniform(-20, 20, (3000, 3))
    dist = np.where(rng.random(len(pos)) < 0.7, 1.0, np.inf)
    got = viewpoint_nodes(NavGraph(positions=pos, adjacency=None), dist, 1.2)
    reachable = np.flatnonzero(np.isfinite(dist))
    seen, want = set(), []
    for n in reachable:
        cell = tuple(np.floor(pos[n] / 1.2).astype(int))
        if cell not in seen:
            seen.add(cell)
            want.append(n)
    np.testing.assert_array_equal(got, want)


def test_clear_sight_is_blocked_by_rock_and_by_leaving_the_grid():
    occ = np.zeros((20, 10, 10), dtype=np.int8)
    occ[10, :, :] = OCCUPIED
    grid = Grid(occ, np.zeros(3), 0.2)
    a = np.array([[0.5, 1.0, 1.0], [0.5, 1.0, 1.0], [0.5, 1.0, 1.0]])
    b = np.array([[1.5, 1.0, 1.0], [3.5, 1.0, 1.0], [0.5, 1.0, 2.5]])   # clear, through rock, out of the grid
    np.testing.assert_array_equal(clear_sight(grid, a, b), [True, False, False])
