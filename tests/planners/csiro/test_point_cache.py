import numpy as np
import pytest

from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.point_cache import PointCache

from .frontier_clouds import rectangle

P = CsiroFrontierParams()


def test_count_mean_and_covariance_per_voxel_match_numpy_and_batches_add_up():
    rng = np.random.default_rng(1)
    pts = rng.uniform(0.31, 0.59, size=(50, 3))          # all in voxel (1, 1, 1)
    other = np.array([[5.0, 5.0, 5.0]])
    whole, parts = PointCache(0.3), PointCache(0.3)
    whole.insert(np.vstack([pts, other]), np.zeros(3))
    parts.insert(pts[:20], np.zeros(3))
    parts.insert(np.vstack([pts[20:], other]), np.zeros(3))
    for cache in (whole, parts):
        assert len(cache) == 2
        assert cache.counts().tolist() == [50, 1]
        np.testing.assert_allclose(cache.means()[0], pts.mean(axis=0))
        np.testing.assert_allclose(cache.covariances()[0], np.cov(pts.T, bias=True), atol=1e-12)
        np.testing.assert_allclose(cache.means()[1], other[0])


def test_voxels_near_the_agent_give_nine_points_in_their_plane_and_far_ones_their_mean():
    wall = rectangle((1.0, -5.95, -1.45), (0, 12, 0), (0, 0, 3))     # the plane x = 1, facing the agent
    cache = PointCache(P.d_vox_m)
    cache.insert(wall, np.zeros(3))
    mu = cache.means()
    near = np.linalg.norm(mu, axis=1) <= P.eta_subsample_m
    cloud = cache.cloud(np.zeros(3), P)
    assert near.sum() > 0
    assert len(cloud) == 9 * near.sum() + (~near).sum()
    np.testing.assert_allclose(cloud[:, 0], 1.0, atol=1e-9)            # equation 1 stays in the plane
    sub = cloud[len(cloud) - 9 * near.sum():].reshape(-1, 9, 3)
    np.testing.assert_allclose(sub.mean(axis=1), mu[near], atol=1e-12)
    assert np.all(np.ptp(sub[:, :, 1], axis=1) > 0) and np.all(np.ptp(sub[:, :, 2], axis=1) > 0)


def test_voxels_facing_away_from_the_agent_are_left_out():
    wall = rectangle((2.0, -1.15, -1.15), (0, 2.4, 0), (0, 0, 2.4))    # three points a side per voxel
    cache = PointCache(P.d_vox_m)
    cache.insert(wall, np.zeros(3))                      # seen from the -x side
    assert len(cache.cloud(np.array([0.5, 0, 0]), P)) > 0
    assert len(cache.cloud(np.array([4.0, 0, 0]), P)) == 0     # behind the surface


def test_voxels_beyond_d_max_are_left_out_and_prune_forgets_them():
    cache = PointCache(P.d_vox_m)
    cache.insert(np.array([[1.0, 0, 0], [20.0, 0, 0]]), np.zeros(3))
    np.testing.assert_allclose(cache.cloud(np.zeros(3), P), [[1.0, 0, 0]])
    cache.prune(np.zeros(3), P.d_max_m)
    assert len(cache) == 1


def test_cloud_is_deterministic():
    wall = rectangle((2.0, -3.0, -1.0), (0, 6, 0), (0, 0, 2))
    clouds = []
    for _ in range(2):
        cache = PointCache(P.d_vox_m)
        cache.insert(wall, np.zeros(3))
        clouds.append(cache.cloud(np.zeros(3), P))
    assert np.array_equal(clouds[0], clouds[1])


def test_kept_decompositions_give_the_cloud_of_a_cache_without_them():
    """cloud() decomposes only the voxels that points came into since its last call: after
    scans that add to old voxels and add new ones between them, and a prune, the cloud is
    the one of a cache that took the same scans with no call between."""
    rng = np.random.default_rng(3)
    scans = [rectangle((2.0, -3.0, -1.0), (0, 6, 0), (0, 0, 2)) + rng.normal(0, 0.05, (1, 3)) for _ in range(4)]
    scans.insert(2, rectangle((-2.0, -4.0, -1.0), (0, 8, 0), (0, 0, 2)))
    centre = np.array([0.0, 2.5, 0.0])
    kept, fresh = PointCache(P.d_vox_m), PointCache(P.d_vox_m)
    for k, scan in enumerate(scans):
        for cache in (kept, fresh):
            cache.insert(scan, np.zeros(3))
            if k == 2:
                cache.prune(centre, 4.0)
        kept.cloud(np.zeros(3), P)
    for agent in (np.zeros(3), np.array([0.5, 1.0, 0.0])):
        assert np.array_equal(kept.cloud(agent, P), fresh.cloud(agent, P))


def test_bad_voxel_size_raises():
    with pytest.raises(ValueError, match="d_vox_m"):
        PointCache(0.0)
