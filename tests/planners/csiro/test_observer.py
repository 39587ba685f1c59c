"""delve.planners.csiro.observer: traversable vertices, candidates, equations 12-13."""
from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from delve.planners.csiro.frontier_types import Frontier, FrontierMesh
from delve.planners.csiro.observer import (
    observation_rewards,
    observer_candidates,
    plan_observer,
    surface_normals,
    traversable_vertices,
)
from delve.planners.csiro.selection_params import CsiroSelectionParams

P = CsiroSelectionParams()
D_MAX = 9.0


def grid_mesh(xs: np.ndarray, ys: np.ndarray, height=lambda x, y: 0.0 * x, *, flip_every_other=False,
              viewpoint=(0.0, 0.0, 1.0)) -> FrontierMesh:
    """A height field over ``xs`` x ``ys``, two triangles per cell; with
    ``flip_every_other`` half the triangles are wound the other way."""
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    vertices = np.column_stack([gx.ravel(), gy.ravel(), height(gx, gy).ravel()])
    n = len(ys)
    tris = []
    for i in range(len(xs) - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            tris += [[a, b, c], [a, c, d]] if not (flip_every_other and (i + j) % 2) else [[a, c, b], [a, d, c]]
    tris = np.array(tris, dtype=np.int64)
    return FrontierMesh(vertices, tris, np.zeros(len(tris), bool), np.array(viewpoint, float))


def merge(*meshes: FrontierMesh) -> FrontierMesh:
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return FrontierMesh(np.concatenate([m.vertices for m in meshes]),
                        np.concatenate([m.triangles + o for m, o in zip(meshes, offsets)]),
                        np.concatenate([m.frontier for m in meshes]), meshes[0].viewpoint)


def one_triangle_frontier(point, normal, area=1.0) -> Frontier:
    point = np.array([point], float)
    return Frontier(id=0, points=point, normals=np.array([normal], float), areas=np.array([area]),
                    mean=point[0], cov=np.eye(3) * 0.01)


AXIS = np.arange(-4.0, 4.01, 0.25)


def test_floor_normals_point_up_whatever_the_winding():
    normals = surface_normals(grid_mesh(AXIS, AXIS, flip_every_other=True))
    assert np.allclose(normals, [0, 0, 1])


def test_a_flat_floor_is_traversable():
    assert traversable_vertices(grid_mesh(AXIS, AXIS), P).all()


def test_steep_slopes_are_excluded():
    xs = np.arange(-4.0, 8.01, 0.25)
    slope = np.tan(np.radians(45.0))
    mesh = grid_mesh(xs, AXIS, lambda x, y: np.where(x > 4.0, (x - 4.0) * slope, 0.0))
    keep = traversable_vertices(mesh, P)
    x = mesh.vertices[:, 0]
    assert not keep[x >= 4.0].any()  # the slope (equation 10) and its foot (equation 11)
    assert keep[x <= 4.0 - 2 * P.eta_trav_m].all()


def test_vertices_near_a_steep_one_are_excluded():
    mesh = grid_mesh(AXIS, AXIS)
    normals = np.tile([0.0, 0.0, 1.0], (len(mesh.vertices), 1))
    wall = int(np.flatnonzero(np.all(mesh.vertices == [1.0, 1.0, 0.0], axis=1))[0])
    normals[wall] = [1.0, 0.0, 0.0]
    keep = traversable_vertices(mesh, P, vertex_normals=normals)
    gap = np.linalg.norm(mesh.vertices - mesh.vertices[wall], axis=1)
    assert not keep[gap <= P.eta_trav_m].any()  # equation 11, the boundary included
    assert keep[gap > P.eta_trav_m].all()


def test_a_gentle_slope_is_traversable():
    slope = np.tan(np.radians(20.0))
    assert traversable_vertices(grid_mesh(AXIS, AXIS, lambda x, y: x * slope), P).all()


def test_a_ceiling_is_not_ground():
    floor = grid_mesh(AXIS, AXIS)
    ceiling = grid_mesh(AXIS, AXIS, lambda x, y: 0.0 * x + 3.0)
    keep = traversable_vertices(merge(floor, ceiling), P)
    assert keep[: len(floor.vertices)].all() and not keep[len(floor.vertices):].any()


def test_candidates_are_subsampled_and_connected():
    cand = observer_candidates(grid_mesh(AXIS, AXIS), np.array([0.0, 0.0, 0.5]), P)
    assert 0 < len(cand) <= (8.0 / P.observer_spacing_m + 1) ** 2
    gaps = np.linalg.norm(cand.positions[:, None] - cand.positions[None], axis=2)
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() > 0.25  # one vertex per neighbourhood, not every vertex
    assert len(cand.graph) == len(cand) and len(cand.graph.edges) > 0
    assert nx.is_connected(cand.graph)


def test_only_candidates_reachable_from_the_agent_are_kept():
    near = grid_mesh(AXIS, AXIS)
    far = grid_mesh(AXIS + 20.0, AXIS)  # no triangle joins the two floors
    cand = observer_candidates(merge(near, far), np.array([0.0, 0.0, 0.5]), P)
    assert len(cand) > 0 and (cand.positions[:, 0] < 5.0).all()
    cand = observer_candidates(merge(near, far), np.array([20.0, 0.0, 0.5]), P)
    assert (cand.positions[:, 0] > 15.0).all()


def test_reward_of_equation_12_with_the_reduced_dynamic_range():
    frontier = one_triangle_frontier([3.0, 0.0, 0.0], [1.0, 0.0, 0.0], area=1.0)
    a = np.array([[0.0, 0.0, 0.0]])
    # A cos / 3 * (d^2 / r - r) = 1/3 * (81/3 - 3) = 8
    assert observation_rewards(a, frontier, D_MAX, P)[0, 0] == pytest.approx(8.0)
    full = CsiroSelectionParams(reduced_dynamic_range=False)
    # A cos / 3 * (d^3 / r^2 - r) = 1/3 * (729/9 - 3) = 26
    assert observation_rewards(a, frontier, D_MAX, full)[0, 0] == pytest.approx(26.0)
    beyond = np.array([[-7.0, 0.0, 0.0]])
    assert observation_rewards(beyond, frontier, D_MAX, P)[0, 0] == 0.0


def test_reward_favours_observers_facing_the_frontier():
    frontier = one_triangle_frontier([5.0, 0.0, 0.5], [1.0, 0.0, 0.0])
    facing, oblique, side, behind = [0.0, 0.0, 0.5], [5 - 5 / np.sqrt(2), 5 / np.sqrt(2), 0.5], \
        [5.0, 5.0, 0.5], [8.0, 0.0, 0.5]
    r = observation_rewards(np.array([facing, oblique, side, behind]), frontier, D_MAX, P)[:, 0]
    assert r[0] > r[1] > 0.0
    assert r[2] == pytest.approx(0.0) and r[3] == 0.0


def test_a_triangle_outside_the_sensors_elevations_gives_no_reward():
    roof = one_triangle_frontier([0.0, 0.0, 3.0], [0.0, 0.0, 1.0])          # straight above, facing up
    floor = np.array([[x, 0.0, 0.0] for x in np.arange(-8.0, 8.1, 1.0)])
    seen = observation_rewards(floor, roof, D_MAX, P, sensor_height_m=0.5)
    assert seen.max() > 0                                                   # a sensor seeing every elevation
    band = observation_rewards(floor, roof, D_MAX, P, sensor_height_m=0.5, elevations_deg=(-15.0, 15.0))
    assert np.all(band == 0.0)                                              # 2.5 m up needs 9.3 m away
    wall = one_triangle_frontier([5.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    band = observation_rewards(floor, wall, D_MAX, P, sensor_height_m=0.5, elevations_deg=(-15.0, 15.0))
    assert band.max() > 0


def test_a_frontier_no_candidate_sees_has_an_observer_of_no_reward():
    cand = observer_candidates(grid_mesh(AXIS, AXIS), np.array([0.0, 0.0, 0.5]), P)
    roof = one_triangle_frontier([1.0, 0.0, 3.0], [0.0, 0.0, 1.0])
    assert plan_observer(cand, roof, D_MAX, P, sensor_height_m=0.5).reward > 0
    band = plan_observer(cand, roof, D_MAX, P, sensor_height_m=0.5, elevations_deg=(-15.0, 15.0))
    assert band.reward == 0.0


def test_observer_is_the_candidate_observing_most():
    mesh = grid_mesh(AXIS, AXIS)
    cand = observer_candidates(mesh, np.array([0.0, 0.0, 0.5]), P)
    frontier = one_triangle_frontier([6.0, 0.0, 0.5], [1.0, 0.0, 0.0])
    obs = plan_observer(cand, frontier, D_MAX, P)
    totals = observation_rewards(cand.positions, frontier, D_MAX, P).sum(axis=1)
    assert obs.reward == pytest.approx(totals.max()) and obs.index == int(np.argmax(totals))
    assert np.array_equal(obs.position, cand.positions[obs.index])
    assert abs(obs.position[1]) < 1.0  # in front of the frontier, not off to a side
    assert plan_observer(observer_candidates(grid_mesh(AXIS, AXIS, lambda x, y: 2.0 * x), np.zeros(3), P),
                         frontier, D_MAX, P) is None  # no traversable vertex: no observer


def test_deterministic():
    mesh = grid_mesh(AXIS, AXIS, lambda x, y: 0.05 * np.sin(x) * np.cos(y))
    a = observer_candidates(mesh, np.zeros(3), P)
    b = observer_candidates(mesh, np.zeros(3), P)
    assert np.array_equal(a.positions, b.positions)
    assert sorted(a.graph.edges(data="weight")) == sorted(b.graph.edges(data="weight"))
