import pickle

import numpy as np

from delve.planners.csiro.frontier_types import FrontierMesh
from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.point_cache import PointCache
from delve.planners.csiro.sequential import (SequentialFrontiers, gaussian_kl, mesh_scene, on_surface,
                                             seen_from)
from scipy.spatial import cKDTree

from .frontier_clouds import corridor, rectangle

P = CsiroFrontierParams()


def drive(points, xs, params=P):
    """Updates of a SequentialFrontiers at (x, 0, 1) for each x of ``xs`` (one per second) in the
    cloud ``points``; returns it and the updates."""
    cache = PointCache(params.d_vox_m)
    cache.insert(points, np.array([0.0, 0.0, 1.0]))
    seq = SequentialFrontiers(params)
    updates = []
    for x in xs:
        agent = np.array([float(x), 0.0, 1.0])
        updates.append(seq.update(float(x), agent, cache.cloud(agent, params)))
    return seq, updates


def end_ids(frontiers, sign):
    return [f.id for f in frontiers if np.sign(f.mean[0]) == sign and abs(f.mean[0]) > 7.5 and f.area > 5.0]


def test_a_frontier_seen_from_a_later_viewpoint_disappears():
    seq, (first, later) = drive(corridor(-40, 40, closed_at=(14.0,)), [0, 6])
    assert any(f.mean[0] > 7.5 for f in first.frontiers)              # the drift goes on beyond 9 m
    assert not any(f.mean[0] > 0 for f in later.frontiers)            # from x = 6 its end wall is seen
    assert set(later.removed_ids) >= {f.id for f in first.frontiers if f.mean[0] > 7.5}
    assert len(later.frontiers) >= 1 and all(f.mean[0] < -7.5 for f in later.frontiers)


def test_discarded_frontiers_are_forgotten():
    seq, (first,) = drive(corridor(-40, 40), [0])
    ids = [f.id for f in first.frontiers]
    seq.discard(ids[:1] + [999])
    assert [f.id for f in seq.frontiers] == ids[1:]


def test_a_frontier_point_on_surface_observed_since_is_seen():
    floor = rectangle((-5, -5, 0), (10, 0, 0), (0, 10, 0))
    points = np.array([[1.0, 0.0, -0.05], [1.0, 0.0, 1.5], [20.0, 0.0, 0.0]])   # on, above, out of range
    agent = np.array([0.0, 0.0, 1.0])
    assert on_surface(points, cKDTree(floor), agent, P).tolist() == [True, False, False]
    assert not on_surface(points, cKDTree(np.zeros((0, 3))), agent, P).any()


def test_the_kl_assignment_keeps_the_ids_of_the_frontiers_being_followed():
    seq, updates = drive(corridor(-40, 40), [0, 1, 2, 3, 4, 5, 6])
    ahead = end_ids(updates[0].frontiers, 1)
    behind = end_ids(updates[0].frontiers, -1)
    assert len(ahead) == 1 and len(behind) == 1
    for x, u in zip(range(7), updates):
        (f,) = [f for f in u.frontiers if f.id == ahead[0]]
        assert abs(f.mean[0] - (x + 8)) < 1.0                         # it moves on with the agent
        assert end_ids(u.frontiers, -1) == behind                     # the one behind stays put
    assert len({f.id for u in updates for f in u.frontiers}) < 2 * len(updates)


def test_kept_viewpoints_are_d_vp_apart_and_updates_need_d_min_and_t_min():
    seq, updates = drive(corridor(-40, 40), [0, 1, 2, 3, 4, 5, 6, 10])
    assert [u.viewpoint_kept for u in updates] == [True, False, False, False, False, True, False, True]
    assert [vp.t_s for vp in seq.viewpoints] == [0.0, 5.0, 10.0]
    assert not seq.due(10.2, np.array([12.0, 0, 1]))                  # too soon
    assert not seq.due(11.0, np.array([10.5, 0, 1]))                  # too close
    assert seq.due(10.5, np.array([11.0, 0, 1]))
    assert np.allclose(seq.last_viewpoint, [10.0, 0.0, 1.0])              # where the last update saw from
    assert SequentialFrontiers().last_viewpoint is None


def test_a_degenerate_cloud_is_no_error_and_gives_no_frontier():
    seq = SequentialFrontiers(P)
    floor = rectangle((-3, -3, 0), (6, 0, 0), (0, 6, 0))
    u = seq.update(0.0, np.array([0.0, 0, 1]), floor)
    assert u.frontiers == () and u.mesh is None and "plane" in u.reason
    u = seq.update(1.0, np.array([0.0, 0, 1]), np.zeros((0, 3)))
    assert u.frontiers == () and "too few points" in u.reason


def test_updates_are_deterministic_and_survive_pickling():
    xs = [0, 1, 2, 5, 7]
    (a, ua), (b, ub) = drive(corridor(-40, 40), xs), drive(corridor(-40, 40), xs)
    for u, v in zip(ua, ub):
        assert [f.id for f in u.frontiers] == [f.id for f in v.frontiers]
        assert all(np.array_equal(f.points, g.points) for f, g in zip(u.frontiers, v.frontiers))
    copy = pickle.loads(pickle.dumps(a))
    cache = PointCache(P.d_vox_m)
    cache.insert(corridor(-40, 40), np.array([0.0, 0.0, 1.0]))
    agent = np.array([8.0, 0, 1])
    assert [f.id for f in copy.update(8.0, agent, cache.cloud(agent, P)).frontiers] == \
        [f.id for f in a.update(8.0, agent, cache.cloud(agent, P)).frontiers]


def test_a_point_is_seen_when_it_lies_at_least_eta_vis_in_front_of_the_mesh():
    # a square wall 2 m in front of the viewpoint, as two triangles
    v = np.array([[2.0, -1, -1], [2.0, 1, -1], [2.0, 1, 1], [2.0, -1, 1]])
    mesh = FrontierMesh(vertices=v, triangles=np.array([[0, 1, 2], [0, 2, 3]]), frontier=np.zeros(2, bool),
                        viewpoint=np.zeros(3))
    pts = np.array([[1.0, 0.1, 0.2], [2.0 - 0.01, 0.1, 0.2], [2.0 - 0.001, 0.1, 0.2], [3.0, 0.1, 0.2]])
    assert seen_from(pts, mesh, mesh_scene(mesh), P).tolist() == [True, True, False, False]


def test_kl_divergence_of_gaussians():
    m, c = np.zeros((1, 3)), np.diag([1.0, 2.0, 3.0])[None]
    assert abs(gaussian_kl(m, c, m, c)[0, 0]) < 1e-12
    kl = gaussian_kl(np.zeros((2, 3)), np.stack([np.eye(3), 2 * np.eye(3)]), np.array([[2.0, 0, 0]]), np.eye(3)[None])
    assert kl.shape == (2, 1)
    assert np.isclose(kl[0, 0], 2.0)                                   # |dm|^2 / 2 with unit covariances
    assert np.isclose(kl[1, 0], 0.5 * (6 + 4 - 3 - 3 * np.log(2)))
