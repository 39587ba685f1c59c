import numpy as np
from scipy.sparse import csr_matrix

from delve.planners.csiro.frontier_types import FrontierMesh
from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.point_cache import PointCache
from delve.planners.csiro.segmentation import grow_regions, make_frontier, segment_frontiers
from delve.planners.csiro.visibility_mesh import visible_mesh

from .frontier_clouds import corridor, room_with_doorway

P = CsiroFrontierParams()


def frontiers_of(points, agent):
    cache = PointCache(P.d_vox_m)
    cache.insert(points, agent)
    mesh, reason = visible_mesh(cache.cloud(agent, P), agent, P)
    assert reason is None
    return segment_frontiers(mesh, P)


def chain(n):
    """Adjacency of items 0-1-2-...-(n-1) in a row."""
    rows = np.arange(n - 1)
    m = csr_matrix((np.ones(n - 1), (rows, rows + 1)), shape=(n, n))
    return (m + m.T).tocsr()


def test_region_growing_stops_at_eta_dia_from_the_anchor_and_at_gaps():
    centroids = np.stack([np.arange(10.0), np.zeros(10), np.zeros(10)], axis=1)
    regions = grow_regions(chain(10), centroids, 3.0)
    assert [r.tolist() for r in regions] == [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9]]
    cut = chain(10).tolil()
    cut[4, 5] = cut[5, 4] = 0
    regions = grow_regions(cut.tocsr(), centroids, 100.0)
    assert [r.tolist() for r in regions] == [[0, 1, 2, 3, 4], [5, 6, 7, 8, 9]]


def test_region_growing_takes_only_items_reachable_through_near_ones():
    # 0 - 1(far) - 2(near 0): 2 is within reach of the anchor but only through 1, which is not
    centroids = np.array([[0.0, 0, 0], [5.0, 0, 0], [0.5, 0, 0]])
    regions = grow_regions(chain(3), centroids, 1.0)
    assert [r.tolist() for r in regions] == [[0], [1], [2]]


def test_a_straight_corridor_has_frontiers_only_at_its_open_ends_facing_out():
    agent = np.array([0.0, 0.0, 1.0])
    frontiers = frontiers_of(corridor(-20, 20), agent)
    ends = sorted(np.sign(f.mean[0]) for f in frontiers if abs(f.mean[0]) > 7.5)
    assert ends[0] == -1 and ends[-1] == 1
    for f in frontiers:
        assert abs(f.mean[0]) > 5.0 and f.area > P.eta_area_m2
        assert np.sign(np.average(f.normals[:, 0], weights=f.areas)) == np.sign(f.mean[0])
    assert frontiers_of(corridor(-20, 20, closed_at=(-6.0, 6.0)), agent) == []


def test_an_opening_in_a_wall_gives_a_discontinuity_frontier():
    frontiers = frontiers_of(room_with_doorway(open_door=True), np.zeros(3))
    assert len(frontiers) >= 1
    assert all(3.0 <= f.mean[0] <= 7.0 and abs(f.mean[1]) < 3.0 for f in frontiers)
    assert frontiers_of(room_with_doorway(open_door=False), np.zeros(3)) == []


def test_segments_of_area_eta_area_or_less_are_dropped():
    v = np.array([[5.0, 0, 0], [5.0, 0.5, 0], [5.0, 0, 0.5], [-5.0, 0, 0], [-5.0, 1.0, 0], [-5.0, 0, 1.0]])
    mesh = FrontierMesh(vertices=v, triangles=np.array([[0, 1, 2], [3, 4, 5]]),
                        frontier=np.array([True, True]), viewpoint=np.zeros(3))
    frontiers = segment_frontiers(mesh, P, first_id=7)
    assert [f.id for f in frontiers] == [7] and np.isclose(frontiers[0].area, 0.5)   # 0.125 m^2 dropped
    np.testing.assert_allclose(frontiers[0].normals[0], [-1.0, 0, 0])      # away from the viewpoint


def test_a_frontiers_gaussian_is_weighted_by_area():
    f = make_frontier(3, np.array([[0.0, 0, 0], [4.0, 0, 0]]), np.tile([1.0, 0, 0], (2, 1)), np.array([1.0, 3.0]))
    assert f.id == 3 and f.area == 4.0
    np.testing.assert_allclose(f.mean, [3.0, 0, 0])
    np.testing.assert_allclose(f.cov[0, 0], 0.25 * 9 + 0.75 * 1)


def test_segmentation_is_deterministic():
    a = frontiers_of(corridor(-20, 20), np.array([0.0, 0.0, 1.0]))
    b = frontiers_of(corridor(-20, 20), np.array([0.0, 0.0, 1.0]))
    assert [f.id for f in a] == [f.id for f in b]
    assert all(np.array_equal(x.points, y.points) and np.array_equal(x.cov, y.cov) for x, y in zip(a, b))
