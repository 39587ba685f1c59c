"""delve.planners.cohort.frontiers: submap wavefronts, the re-check against the common
map, 26-connected clusters and f_min."""
import numpy as np
from delve.planners.cohort import (CommonMap, GlobalFrontiers, cluster_frontiers, map_frontier, recheck,
                                   submap_frontier)
from delve.planners.cohort.frontiers import near_surface
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN

from .worlds import Z, cut, fork, parallel


def common_of(truth):
    return CommonMap(truth.shape, truth.origin, truth.voxel_size_m, 0.4)


def add(common, truth, lo, hi, trajectory=None):
    """Merge the submap of ``truth`` in x range [lo, hi) and return its frontier points."""
    flat, values = cut(truth, lo, hi)
    common.merge(flat, values)
    blocks, pooled = common.pool(flat, values)
    return submap_frontier(common, blocks, pooled, trajectory), blocks, pooled


def test_the_wavefront_is_the_unknown_voxels_next_to_the_visited_ones():
    truth = fork()
    common = common_of(truth)
    points, blocks, pooled = add(common, truth, 0, 20, np.array([[3, 20, Z], [18, 20, Z]]))
    assert len(points) > 50
    assert np.all(~np.isin(points, blocks[pooled != UNKNOWN]))           # unvisited in the submap
    centres = common.centres(points)
    assert np.all(np.abs(centres[:, 0] - 20.2) < 0.3)                    # the end face of the mapped trunk
    ijk = np.stack(np.unravel_index(points, common.shape), axis=1)
    below = np.ravel_multi_index(tuple((ijk - [1, 0, 0]).T), common.shape)
    assert np.all(common.values(below) == FREE)                          # each one next to a visited voxel


def test_visited_voxels_the_robot_cannot_reach_give_no_frontier():
    truth = parallel()
    common = common_of(truth)
    both, _, _ = add(common, truth, 0, 15)
    one, _, _ = add(common_of(truth), truth, 0, 15, np.array([[3, 5, Z], [12, 5, Z]]))
    y_both, y_one = common.centres(both)[:, 1], common.centres(one)[:, 1]
    assert (y_both > 8).any() and (y_both < 8).any()
    assert len(one) and np.all(y_one < 8)


def test_a_frontier_point_known_to_another_submap_is_dropped():
    truth = fork()
    common = common_of(truth)
    frontiers = GlobalFrontiers()
    frontiers.add(("a", 0), add(common, truth, 0, 20, np.array([[18, 20, Z]]))[0])
    frontiers.add(("b", 0), add(common, truth, 15, 40, np.array([[30, 20, Z]]))[0])
    assert frontiers.recheck(common) > 0
    assert len(frontiers.points[("a", 0)]) == 0                          # b mapped past a's end face
    xs = common.centres(frontiers.all_points())[:, 0]
    assert len(xs) and np.all(xs > 39)                                   # b's branch ends remain
    clusters = cluster_frontiers(common, frontiers.all_points(), f_min=10)
    assert len(clusters) == 2 and {round(c.centroid[1] / 10) for c in clusters} == {1, 3}


def test_clusters_join_at_26_connectivity_and_those_under_f_min_go():
    common = CommonMap((20, 20, 20), np.zeros(3), 0.4, 0.4)
    diagonal = [(1, 1, 1), (2, 2, 2), (3, 3, 3), (4, 4, 4), (5, 5, 5)]   # 5 points touching by corners
    apart = [(10, 10, 10), (10, 10, 12), (10, 10, 14)]                   # 3 points two voxels apart
    pair = [(15, 15, 15), (15, 16, 15)]
    points = np.ravel_multi_index(tuple(np.array(diagonal + apart + pair).T), common.shape)
    clusters = cluster_frontiers(common, points, f_min=1)
    assert [c.size for c in clusters] == [5, 2, 1, 1, 1]                 # largest first
    assert np.allclose(clusters[0].centroid, [1.4, 1.4, 1.4])
    assert [c.size for c in cluster_frontiers(common, points, f_min=2)] == [5, 2]
    assert [c.size for c in cluster_frontiers(common, points, f_min=5)] == [5]
    assert cluster_frontiers(common, points, f_min=6) == []


def test_a_point_next_to_known_rock_is_in_the_surface_band_and_dropped():
    common = CommonMap((10, 10, 10), np.zeros(3), 0.4, 0.4)
    common.occupancy[:, :, :5] = FREE
    common.occupancy[2, 2, 6] = OCCUPIED                                 # one hit above the free space
    points = np.ravel_multi_index(([2, 2, 7], [2, 3, 7], [5, 5, 5]), common.shape)
    assert list(near_surface(common, points)) == [True, True, False]
    assert list(recheck(common, points)) == [points[2]]
    common.occupancy[7, 7, 5] = FREE                                     # mapped since: deleted as well
    assert len(recheck(common, points)) == 0


def test_the_whole_maps_frontier_is_the_open_end_and_none_once_every_dead_end_is_seen():
    truth = fork()
    common = common_of(truth)
    points, _, _ = add(common, truth, 0, 20, np.array([[3, 20, Z], [18, 20, Z]]))
    whole = map_frontier(common)
    assert len(whole) and np.all(np.abs(common.centres(whole)[:, 0] - 20.2) < 0.3)   # the trunk's end face
    assert set(recheck(common, points)) <= set(whole)
    add(common, truth, 20, 60)
    assert len(map_frontier(common)) == 0
