"""Unit tests for delve.sim.world.World on small hand-carved worlds."""

import math

import networkx as nx
import numpy as np
import open3d as o3d
import pytest
from scipy import ndimage

from delve.sim.world import World
from delve.sim.worldgen_geometry import (VoxelCanvas, carve_chamber, carve_tunnel,
                                         free_space_mesh)

V = 0.25
WIDTH, HEIGHT = 4.0, 3.0
END_RADIUS = 2.4


def _world(canvas: VoxelCanvas, start) -> World:
    mesh = free_space_mesh(canvas.free, canvas.origin, canvas.voxel_size_m)
    return World(name="test", voxel_size_m=canvas.voxel_size_m, origin=canvas.origin,
                 free=canvas.free, mesh=mesh, centreline=nx.Graph(), start=start)


@pytest.fixture(scope="module")
def twin():
    """Two parallel straight tunnels along x (y = 0 and y = 12), not connected.

    Floors at z = 0, 4 m wide, 3 m high (arched), round chambers of radius 2.4
    at the ends x = 0 and x = 30.
    """
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([33.0, 15.0, 3.0]), V)
    for y in (0.0, 12.0):
        carve_tunnel(canvas, [0.0, y, 0.0], [30.0, y, 0.0], WIDTH, HEIGHT)
        for x in (0.0, 30.0):
            carve_chamber(canvas, [x, y, 0.0], END_RADIUS, HEIGHT)
    return _world(canvas, [1.0, 0.0, 0.01])


def test_grid_helpers(twin):
    assert twin.shape == twin.free.shape
    np.testing.assert_allclose(twin.bounds_max - twin.bounds_min,
                               np.array(twin.shape) * V)
    idx = np.array([[0, 0, 0], [3, 4, 5], [twin.shape[0] - 1, 0, 2]])
    centres = twin.index_to_center(idx)
    np.testing.assert_array_equal(twin.to_index(centres), idx)
    np.testing.assert_allclose(centres[0], twin.origin + 0.5 * V)
    assert twin.in_bounds(idx).all()
    outside = np.array([[-1, 0, 0], [0, twin.shape[1], 0], [0, 0, 10**6]])
    assert not twin.in_bounds(outside).any()


def test_is_free(twin):
    pts = np.array([[15.0, 0.0, 1.0],      # in the first tunnel
                    [15.0, 6.0, 1.0],      # rock between the tunnels
                    [15.0, 12.0, 1.5],     # in the second tunnel
                    [15.0, 0.0, -0.5],     # under the floor
                    [500.0, 0.0, 1.0]])    # outside the grid
    np.testing.assert_array_equal(twin.is_free(pts), [True, False, True, False, False])
    assert twin.is_free(np.zeros((0, 3))).shape == (0,)


def test_is_free_of_one_point_answers_as_for_many(twin):
    """One point (a robot's probe) takes a shortcut on plain floats: the same answers,
    on voxel faces, just inside them and outside the grid."""
    rng = np.random.default_rng(3)
    lo, hi = twin.bounds_min - 1.0, twin.bounds_max + 1.0
    faces = twin.origin + rng.integers(-3, np.array(twin.shape) + 3, size=(3000, 3)) * twin.voxel_size_m
    pts = np.concatenate([rng.uniform(lo, hi, size=(3000, 3)), faces, np.nextafter(faces, -np.inf)])
    many = twin.is_free(pts)
    assert 0 < many.sum() < len(pts)
    np.testing.assert_array_equal([twin.is_free(p[None])[0] for p in pts], many)
    with np.errstate(invalid="ignore"):  # NaN takes the array path, which casts it
        assert not twin.is_free(np.array([[np.nan, 0.0, 1.0]]))[0]
    assert [twin.is_free_at(*map(float, p)) for p in pts] == many.tolist()
    assert not twin.is_free_at(math.nan, 0.0, 1.0) and not twin.is_free_at(15.0, 0.0, math.inf)


def test_rays_along_and_across_tunnel(twin):
    o = np.array([15.0, 0.0, 1.0])
    dirs = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0],
                     [0, 0, -1.0], [0, 0, 1.0]])
    d = twin.cast_rays(np.repeat(o[None], len(dirs), 0), dirs, 100.0)
    assert d.dtype == np.float32 and d.shape == (6,)
    # along the tunnel: to the far wall of the end chamber
    assert d[0] == pytest.approx(15.0 + END_RADIUS, abs=0.3)
    assert d[1] == pytest.approx(15.0 + END_RADIUS, abs=0.3)
    # across: half the width; down: 1 m to the floor; up: the roof crown at 3 m
    assert d[2] == pytest.approx(WIDTH / 2, abs=0.3)
    assert d[3] == pytest.approx(WIDTH / 2, abs=0.3)
    assert d[4] == pytest.approx(1.0, abs=0.3)
    assert d[5] == pytest.approx(HEIGHT - 1.0, abs=0.3)


def test_rays_beyond_range_and_empty(twin):
    o = np.array([[15.0, 0.0, 1.0]])
    assert np.isinf(twin.cast_rays(o, np.array([[1.0, 0.0, 0.0]]), 5.0)[0])
    assert np.isfinite(twin.cast_rays(o, np.array([[0.0, 1.0, 0.0]]), 5.0)[0])
    assert twin.cast_rays(np.zeros((0, 3)), np.zeros((0, 3)), 10.0).shape == (0,)
    with pytest.raises(ValueError):
        twin.cast_rays(np.zeros((2, 3)), np.zeros((3, 3)), 10.0)


def test_distance_down_is_cast_rays_of_one_ray(twin):
    down = np.array([[0.0, 0.0, -1.0]])
    rng = np.random.default_rng(2)
    for x, y, z in rng.uniform([0.0, -1.5, 0.1], [30.0, 13.5, 2.5], (40, 3)):
        for reach in (0.5, 3.0):
            assert twin.distance_down(x, y, z, reach) == twin.cast_rays(np.array([[x, y, z]]), down, reach)[0]
    assert twin.distance_down(15.0, 0.0, 1.0, 2.0) == pytest.approx(1.0, abs=0.25)
    assert math.isinf(twin.distance_down(15.0, 6.0, 1.0, 0.5))   # in rock: the mesh is beyond reach


def test_a_sweep_of_many_rays_all_hit_a_closed_tunnel(twin):
    """A LiDAR-sized batch (its time: bench/hot_paths.py)."""
    rng = np.random.default_rng(0)
    d = rng.normal(size=(6000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    o = np.repeat(np.array([[15.0, 0.0, 1.0]]), 6000, 0)
    out = twin.cast_rays(o, d, 30.0)
    assert out.shape == (6000,) and out.dtype == np.float32
    assert np.isfinite(out).all()      # a closed tunnel: every ray hits within 30 m
    assert out.max() <= 15.0 + END_RADIUS + 0.5  # the farthest rock: the chambers at the ends
    np.testing.assert_array_equal(twin.cast_rays(o, d, 30.0), out)  # the same rays, the same hits


def test_line_of_sight(twin):
    assert twin.line_of_sight(np.array([2.0, 0.0, 1.0]), np.array([28.0, 0.0, 1.0]))
    assert not twin.line_of_sight(np.array([15.0, 0.0, 1.0]), np.array([15.0, 12.0, 1.0]))
    assert twin.line_of_sight(np.array([5.0, 0.0, 1.0]), np.array([5.0, 0.0, 1.0]))


def test_mesh_lies_between_free_and_rock(twin):
    """A hit nudged 5 cm along its ray is in rock; faces sit on the rock side."""
    rng = np.random.default_rng(1)
    free_idx = np.argwhere(twin.free)
    pick = free_idx[rng.choice(len(free_idx), 4000)]
    o = twin.index_to_center(pick)
    d = rng.normal(size=(len(o), 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    t = twin.cast_rays(o, d, 100.0)
    ok = np.isfinite(t)
    assert ok.all()
    hit = o + d * t[:, None]
    assert np.mean(~twin.is_free(hit + 0.05 * d)) > 0.97
    # along grid lines from a free centre to a face-adjacent rock centre the
    # surface lies past the shared face but before the rock centre
    steps = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    pairs = []
    for s in steps:
        nb = free_idx + s
        inb = twin.in_bounds(nb)
        rock = np.zeros(len(nb), bool)
        rock[inb] = ~twin.free[nb[inb, 0], nb[inb, 1], nb[inb, 2]]
        pairs.append((free_idx[rock], np.repeat(s[None], rock.sum(), 0)))
    src = np.concatenate([p[0] for p in pairs])
    step = np.concatenate([p[1] for p in pairs]).astype(float)
    sel = rng.choice(len(src), 3000, replace=False)
    t = twin.cast_rays(twin.index_to_center(src[sel]), step[sel], 10.0)
    inside = (t >= 0.5 * V - 1e-4) & (t <= V + 1e-4)
    assert inside.mean() > 0.99


def test_mesh_normals_point_into_free_space(twin):
    ans = twin.scene.cast_rays(o3d.core.Tensor(
        np.array([[15.0, 0.0, 1.0, 0.0, 1.0, 0.0]], dtype=np.float32)))
    normal = ans["primitive_normals"].numpy()[0]
    assert normal[1] < -0.5        # the wall at +y faces back towards -y


def test_reachable_free(twin):
    comp = twin.reachable_free(np.array([15.0, 0.0, 1.0]))
    assert comp.shape == twin.shape and comp.dtype == bool
    assert comp[tuple(twin.to_index(np.array([[20.0, 0.0, 1.0]]))[0])]
    assert not comp[tuple(twin.to_index(np.array([[20.0, 12.0, 1.0]]))[0])]
    other = twin.reachable_free(np.array([3.0, 12.0, 1.0]))
    assert not (comp & other).any()
    assert comp.sum() + other.sum() == twin.free.sum()
    # cached per start voxel, read-only
    assert twin.reachable_free(np.array([15.0, 0.0, 1.0])) is comp
    assert not comp.flags.writeable
    # a start just inside the floor snaps to the nearest free voxel
    below = twin.reachable_free(np.array([15.0, 0.0, -0.3]))
    np.testing.assert_array_equal(below, comp)
    with pytest.raises(ValueError):
        twin.reachable_free(np.array([15.0, 6.0, 1.0]))     # 4 m into rock


def test_ground_height(twin):
    pts = np.array([[10.0, 0.0, 1.0], [10.0, 1.5, 2.0], [20.0, 12.0, 0.3]])
    np.testing.assert_allclose(twin.ground_height(pts, 3.0), 0.0, atol=1e-9)
    # the floor is farther down than max_drop_m
    assert np.isnan(twin.ground_height(np.array([[10.0, 0.0, 2.5]]), 1.0)[0])
    # inside rock, or outside the grid
    out = twin.ground_height(np.array([[10.0, 6.0, 1.0], [500.0, 0.0, 1.0],
                                       [10.0, 0.0, -50.0]]), 3.0)
    assert np.isnan(out).all()
    assert twin.ground_height(np.zeros((0, 3)), 1.0).shape == (0,)


def test_ground_height_over_a_shaft():
    canvas = VoxelCanvas(np.array([-3.0, -3.0, 0.0]), np.array([13.0, 3.0, 10.0]), V)
    carve_tunnel(canvas, [0.0, 0.0, 0.0], [10.0, 0.0, 0.0], WIDTH, HEIGHT)
    carve_tunnel(canvas, [0.0, 0.0, 7.0], [10.0, 0.0, 7.0], WIDTH, HEIGHT)
    from delve.sim.worldgen_geometry import carve_shaft
    carve_shaft(canvas, [5.0, 0.0], 1.0, 0.0, 7.0)
    w = _world(canvas, [1.0, 0.0, 0.01])
    assert np.isnan(w.ground_height(np.array([[5.0, 0.0, 8.0]]), 2.0)[0])
    assert w.ground_height(np.array([[5.0, 0.0, 8.0]]), 10.0)[0] == pytest.approx(0.0)
    assert w.ground_height(np.array([[8.0, 0.0, 8.0]]), 2.0)[0] == pytest.approx(7.0)


def test_start_problem(twin):
    assert twin.start_problem(twin.start) is None
    msg = twin.start_problem(np.array([500.0, 0.0, 1.0]))
    assert msg.startswith("outside the world (bounds x∈[")
    assert "y∈[" in msg and "z∈[" in msg
    assert twin.start_problem(np.array([15.0, 6.0, 1.0])) == \
        "inside rock (nearest free floor: [14.9, 1.9, 0.0], 4.2 m away)"
    # on the floor surface: in the rock voxel it passes through, free right above
    assert twin.start_problem(np.array([15.0, 0.0, -0.1])) is None
    deep = twin.start_problem(np.array([15.0, 0.0, -0.3]))
    assert deep.startswith("inside rock (nearest free floor: [") and deep.endswith(", 0.0], 0.3 m away)")


def test_nearest_floor_and_regions(twin):
    labels, sizes = twin.free_regions()
    assert np.count_nonzero(sizes) == 2 and sizes[0] == 0
    assert twin.region_label([5.0, 0.0, 0.5]) != twin.region_label([5.0, 12.0, 0.5])
    floor = twin.nearest_floor(np.array([5.0, 0.5, -2.0]))
    np.testing.assert_allclose(floor, [5.1, 0.5, 0.0], atol=V)


@pytest.mark.parametrize("suffix", [".ply", ".obj", ".stl"])
def test_save_mesh(twin, tmp_path, suffix):
    path = tmp_path / f"twin{suffix}"
    twin.save_mesh(path)
    back = o3d.io.read_triangle_mesh(str(path))
    assert len(back.triangles) == len(twin.mesh.triangles)


def test_save_mesh_rejects_unknown_format(twin, tmp_path):
    with pytest.raises(ValueError, match="cannot save mesh"):
        twin.save_mesh(tmp_path / "twin.xyz")


def test_world_validates_grid():
    with pytest.raises(ValueError):
        World(name="bad", origin=np.zeros(3), free=np.zeros((3, 3), bool),
              mesh=o3d.geometry.TriangleMesh(), start=np.zeros(3))
    w = World(name="empty", origin=np.zeros(3), free=np.zeros((2, 2, 2), bool),
              mesh=o3d.geometry.TriangleMesh(), start=np.zeros(3))
    assert w.voxel_size_m == 0.2 and w.free_volume_m3 == 0.0
    assert np.isinf(w.cast_rays(np.zeros((1, 3)), np.array([[1.0, 0, 0]]), 10.0)[0])
    assert math.isclose(w.bounds_max[0], 0.4)


def test_pickle_and_copy(twin):
    import copy
    import pickle
    twin.cast_rays(np.array([[15.0, 0.0, 1.0]]), np.array([[0.0, 1.0, 0.0]]), 10.0)
    for clone in (pickle.loads(pickle.dumps(twin)), copy.deepcopy(twin)):
        assert clone.free.tobytes() == twin.free.tobytes()
        assert len(clone.mesh.triangles) == len(twin.mesh.triangles)
        o, d = np.array([[15.0, 0.0, 1.0]]), np.array([[0.0, 1.0, 0.0]])
        assert clone.cast_rays(o, d, 10.0)[0] == pytest.approx(twin.cast_rays(o, d, 10.0)[0])


@pytest.mark.parametrize("shape, step, dtype", [((40, 40, 40), 8, np.uint8), ((44, 44, 44), 4, np.uint16),
                                                ((600, 500, 1), 2, np.uint32)])
def test_region_labels_are_scipys_in_the_smallest_dtype(shape, step, dtype):
    """Isolated free voxels every ``step`` voxels: 125, 1331 and 75 000 regions; the
    labels equal scipy's int32 ones, in uint8, uint16 and (over 65535 regions) uint32."""
    free = np.zeros(shape, dtype=bool)
    free[::step, ::step, ::step] = True
    world = World(name="dots", origin=np.zeros(3), free=free, mesh=o3d.geometry.TriangleMesh(),
                  start=np.zeros(3))
    labels, sizes = world.free_regions()
    expected, n = ndimage.label(free, structure=np.ones((3, 3, 3), dtype=bool))
    np.testing.assert_array_equal(labels, expected)
    assert labels.dtype == dtype and len(sizes) == n + 1 == np.count_nonzero(free) + 1
