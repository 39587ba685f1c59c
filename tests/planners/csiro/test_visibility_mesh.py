import dataclasses

import numpy as np
from scipy.spatial import cKDTree

from delve.planners.csiro.params import CsiroFrontierParams
from delve.planners.csiro.point_cache import PointCache
from delve.planners.csiro.sequential import SequentialFrontiers
from delve.planners.csiro.visibility_mesh import (CloudDirections, behind_observed, blind_sphere_points,
                                                  exponential_inversion, sphere_points, split_long_edges,
                                                  triangle_geometry, visible_mesh)

from .frontier_clouds import banded_scan, box, corridor, rectangle, room_with_doorway

P = CsiroFrontierParams()
AGENT = np.array([0.0, 0.0, 1.0])


def corridor_mesh(**kw):
    cache = PointCache(P.d_vox_m)
    cache.insert(corridor(-20, 20, **kw), AGENT)
    mesh, reason = visible_mesh(cache.cloud(AGENT, P), AGENT, P)
    assert reason is None
    return mesh


def test_exponential_inversion_keeps_directions_and_maps_range_r_to_r_gamma():
    pts = np.array([[3.0, 0, 0], [0, -0.5, 0], [1, 2, 2]])
    out = exponential_inversion(pts + 1.0, np.ones(3), P.gamma)
    r = np.linalg.norm(pts, axis=1)
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), r ** P.gamma)
    np.testing.assert_allclose(out / np.linalg.norm(out, axis=1)[:, None], pts / r[:, None])
    assert np.linalg.norm(out[1]) > np.linalg.norm(out[0])         # near points land farther out


def test_sphere_points_lie_on_d_max_within_the_sensors_elevations_half_eta_disc_apart():
    s = sphere_points(AGENT, P) - AGENT
    np.testing.assert_allclose(np.linalg.norm(s, axis=1), P.d_max_m)
    el = np.degrees(np.arcsin(s[:, 2] / P.d_max_m))
    assert el.min() >= P.elevation_min_deg - 1e-9 and el.max() <= P.elevation_max_deg + 1e-9
    gap, _ = cKDTree(s).query(s, k=2)
    assert gap[:, 1].max() <= 0.5 * P.eta_disc_m * 1.01


def test_blind_sphere_points_fill_the_elevations_the_sensor_does_not_see():
    s = blind_sphere_points(AGENT, P) - AGENT
    np.testing.assert_allclose(np.linalg.norm(s, axis=1), P.d_max_m)
    el = np.degrees(np.arcsin(np.clip(s[:, 2] / P.d_max_m, -1, 1)))
    assert np.all((el > P.elevation_max_deg) | (el < P.elevation_min_deg))
    assert el.max() == 90.0 and el.min() == -90.0
    everywhere = dataclasses.replace(P, elevation_min_deg=-90.0, elevation_max_deg=90.0)
    assert len(blind_sphere_points(AGENT, everywhere)) == 0


def test_a_narrow_lidar_band_gives_no_frontier_off_the_drift_nor_in_its_blind_cones():
    """A legged robot's +-15 deg LiDAR never sees the roof of a 3 m drift within 9 m, nor the walls'
    tops beside it: the hull's rim over those blind cones made frontiers behind the walls and
    over the robot's head."""
    surface = corridor(-30.0, 60.0)                          # 4 m wide, 3 m high
    cache, seq = PointCache(P.d_vox_m), SequentialFrontiers(P)
    for x in range(9):
        sensor = np.array([float(x), 0.3, 0.6])
        cache.insert(banded_scan(surface, sensor), sensor)
        update = seq.update(float(x), sensor, cache.cloud(sensor, P))
    points = np.concatenate([f.points for f in update.frontiers])
    assert np.all(np.abs(points[:, 1]) <= 2.0 + 0.05) and np.all(points[:, 2] <= 3.0 + 0.05)
    centroids, _, areas = triangle_geometry(update.mesh)
    up = centroids[update.mesh.frontier] - sensor
    elevation = np.degrees(np.arctan2(up[:, 2], np.linalg.norm(up[:, :2], axis=1)))
    assert areas[update.mesh.frontier][elevation > P.elevation_max_deg + 2.0].sum() < 0.05 * \
        areas[update.mesh.frontier].sum()
    big = [f for f in update.frontiers if f.area > 5.0]       # the drift's two open ends
    assert len(big) == 2 and sorted(np.sign(f.mean[0] - sensor[0]) for f in big) == [-1.0, 1.0]


def test_a_shaft_straight_above_is_a_frontier_only_for_a_robot_that_sees_into_its_blind_cones():
    room = box((-3, -3, -1), (3, 3, 2))
    room = room[~((np.abs(room[:, 0]) < 1.0) & (np.abs(room[:, 1]) < 1.0) & (room[:, 2] > 1.9))]   # a hole
    shaft = np.concatenate([rectangle((-1, y, 2), (2, 0, 0), (0, 0, 18)) for y in (-1, 1)]
                           + [rectangle((x, -1, 2), (0, 2, 0), (0, 0, 18)) for x in (-1, 1)])
    cache = PointCache(P.d_vox_m)
    cache.insert(np.concatenate([room, shaft]), np.zeros(3))
    uav = dataclasses.replace(P, elevation_min_deg=-45.0, elevation_max_deg=45.0)
    for blind, above in ((False, 0), (True, 1)):
        params = dataclasses.replace(uav, blind_frontiers=blind)
        mesh, _ = visible_mesh(cache.cloud(np.zeros(3), params), np.zeros(3), params)
        centroids, _, _ = triangle_geometry(mesh)
        up = centroids[mesh.frontier]
        assert ((up[:, 2] > 5.0) & (np.linalg.norm(up[:, :2], axis=1) < 1.0)).any() == bool(above)


def test_sphere_points_straight_behind_an_observed_point_are_left_out_of_the_hull():
    wall = rectangle((3.0, -1.05, -1.05), (0, 2, 0), (0, 0, 2))
    s = sphere_points(np.zeros(3), P)
    behind = behind_observed(s, CloudDirections(wall, np.zeros(3)), np.zeros(3), P.d_vox_m)
    direction = s / P.d_max_m
    inside = (direction[:, 0] > 0) & (np.abs(direction[:, 1] / direction[:, 0]) < 0.3) & \
        (np.abs(direction[:, 2] / direction[:, 0]) < 0.3)
    assert behind[inside].all() and not behind[direction[:, 0] < 0.2].any()


def test_one_long_edge_is_split_at_its_middle_into_a_frontier_point_and_two_triangles():
    v = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.5, 0.3, 0]])          # only edge 0-1 is over 0.8 m
    vv, tt, ff = split_long_edges(v, np.array([[0, 1, 2]]), np.zeros(3, bool), P.eta_disc_m)
    np.testing.assert_allclose(vv[3], [0.5, 0, 0])
    assert ff.tolist() == [False, False, False, True] and len(tt) == 2
    area = lambda t: 0.5 * np.linalg.norm(np.cross(vv[t[:, 1]] - vv[t[:, 0]], vv[t[:, 2]] - vv[t[:, 0]]), axis=1)
    assert np.isclose(area(tt).sum(), 0.15)


def test_split_shares_the_middle_of_an_edge_between_its_two_triangles_and_keeps_orientation():
    v = np.array([[0.0, 0, 0], [1.0, -2, 0], [1.0, 2, 0], [2.0, 0, 0]])    # long edge 0-3 between two
    tri = np.array([[0, 1, 3], [0, 3, 2]])
    vv, tt, ff = split_long_edges(v, tri, np.zeros(4, bool), 0.8)
    # every edge of the four side edges is long too: each triangle has three long edges -> 4 each
    assert len(tt) == 8 and ff[4:].all()
    assert len(vv) == 4 + 5                                    # five distinct long edges, five middles
    n = np.cross(vv[tt[:, 1]] - vv[tt[:, 0]], vv[tt[:, 2]] - vv[tt[:, 0]])
    assert np.all(n[:, 2] > 0)                                 # the input's orientation (anticlockwise in xy)


def test_a_long_edge_whose_middle_lies_on_seen_surface_is_left_whole():
    v = np.array([[0.0, 0, 0], [2.0, 0, 0], [0.0, 0.5, 0]])
    surface = cKDTree(np.array([[1.0, 0.05, 0]]))
    vv, tt, ff = split_long_edges(v, np.array([[0, 1, 2]]), np.zeros(3, bool), 0.8, surface, P.d_vox_m)
    assert len(vv) == 3 and len(tt) == 1 and not ff.any()


def test_the_visible_mesh_is_watertight_and_faces_away_from_the_agent():
    mesh = corridor_mesh()
    edges = np.sort(np.concatenate([mesh.triangles[:, [0, 1]], mesh.triangles[:, [1, 2]],
                                    mesh.triangles[:, [2, 0]]]), axis=1)
    _, count = np.unique(edges, axis=0, return_counts=True)
    assert np.all(count == 2)
    centroids, normals, areas = triangle_geometry(mesh)
    assert np.all(np.einsum("ij,ij->i", normals, centroids - AGENT) >= 0)
    assert np.all(areas >= 0)


def test_only_max_range_points_at_the_open_ends_of_a_corridor_are_frontier():
    mesh = corridor_mesh()
    centroids, _, _ = triangle_geometry(mesh)
    assert np.all(np.abs(centroids[mesh.frontier, 0]) > 5.0)
    assert np.any(centroids[mesh.frontier, 0] > 8.5) and np.any(centroids[mesh.frontier, 0] < -8.5)
    assert not corridor_mesh(closed_at=(-6.0, 6.0)).frontier.any()


def test_points_behind_a_wall_are_not_visible():
    wall = rectangle((3.0, -3.05, -1.05), (0, 6, 0), (0, 0, 3))
    behind = np.array([[5.0, 0.1, 0.2], [6.0, -0.3, 0.4]])
    mesh, _ = visible_mesh(np.vstack([wall, behind]), np.zeros(3), P)
    assert cKDTree(mesh.vertices).query(behind)[0].min() > 0.5
    assert cKDTree(mesh.vertices).query(wall[::50])[0].max() == 0.0


def test_an_opening_gives_discontinuity_frontiers_and_no_maximum_range_ones():
    cache = PointCache(P.d_vox_m)
    cache.insert(room_with_doorway(open_door=True), np.zeros(3))
    mesh, _ = visible_mesh(cache.cloud(np.zeros(3), P), np.zeros(3), P)
    centroids, _, _ = triangle_geometry(mesh)
    assert mesh.frontier.any()
    assert np.all(centroids[mesh.frontier, 0] >= 3.0 - 1e-9)     # in or beyond the door
    assert np.linalg.norm(mesh.vertices, axis=1).max() < P.d_max_m - 1   # no sphere point is visible


def test_a_degenerate_cloud_gives_no_mesh_and_a_reason():
    mesh, reason = visible_mesh(np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]), np.zeros(3), P)
    assert mesh is None and "too few points" in reason
    floor = rectangle((-3, -3, -1), (6, 0, 0), (0, 6, 0))
    mesh, reason = visible_mesh(floor, np.zeros(3), P)
    assert mesh is None and "plane" in reason
    mesh, reason = visible_mesh(np.array([[20.0, 0, 0]] * 10), np.zeros(3), P)
    assert mesh is None and "0 within 9.0 m" in reason


def test_the_mesh_is_deterministic():
    a, b = corridor_mesh(), corridor_mesh()
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.triangles, b.triangles)
    assert np.array_equal(a.frontier, b.frontier)


def test_a_wider_elevation_range_adds_sphere_points():
    wide = dataclasses.replace(P, elevation_min_deg=-90.0, elevation_max_deg=90.0)
    assert len(sphere_points(AGENT, wide)) > 3 * len(sphere_points(AGENT, P))
