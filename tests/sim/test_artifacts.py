"""Unit tests for delve.sim.artifacts: seeded placement and listed artifacts."""

from collections import Counter

import networkx as nx
import numpy as np
import pytest

from delve.sim.artifacts import (ARTIFACT_CLASSES, PlacementSpec, listed_artifacts,
                                 place_artifacts)
from delve.sim.world import World
from delve.sim.worldgen import tunnel_network

SMALL = dict(spacing_m=15, width_m=(3, 4), height_m=(2.5, 3), voxel_size_m=0.25, loops=0)


@pytest.fixture(scope="module")
def mine():
    return tunnel_network(1, total_length_m=150, **SMALL)


@pytest.fixture(scope="module")
def two_levels():
    return tunnel_network(2, total_length_m=200, levels=2, **SMALL)


@pytest.fixture(scope="module")
def mesh_like(mine):
    """The same mine as a mesh world would come: no centreline graph."""
    return World(name="mesh_like", voxel_size_m=mine.voxel_size_m, origin=mine.origin,
                 free=mine.free, mesh=mine.mesh, start=mine.start)


def _dead_ends(world):
    g = world.centreline
    return [np.asarray(g.nodes[n]["pos"]) for n in sorted(g) if g.degree(n) == 1
            and np.linalg.norm(g.nodes[n]["pos"] - world.start) > 10.0]


def _positions(arts):
    return np.array([a.position for a in arts])


def test_placement_is_deterministic_per_seed(mine):
    a = place_artifacts(mine, count=10, seed=3)
    b = place_artifacts(mine, count=10, seed=3)
    c = place_artifacts(mine, count=10, seed=4)
    assert [x.name for x in a] == [x.name for x in b]
    np.testing.assert_array_equal(_positions(a), _positions(b))
    assert not np.array_equal(_positions(a), _positions(c))


def test_artifacts_in_reachable_free_space_on_their_surfaces(mine):
    arts = place_artifacts(mine, count=10, seed=3)
    reach = mine.reachable_free(mine.start)
    v = mine.voxel_size_m
    for a in arts:
        i = mine.to_index(a.position)[0]
        assert reach[tuple(i)], a
        assert np.isclose(np.linalg.norm(a.normal), 1.0)
        foot = a.position - a.normal * 0.5 * a.size_m
        if a.surface == "floor":
            np.testing.assert_array_equal(a.normal, [0, 0, 1])
            assert not mine.is_free((foot - [0, 0, 0.5 * v])[None])[0]    # rock below
        elif a.surface == "wall":
            assert abs(a.normal[2]) < 1e-9
            assert not mine.is_free((foot - a.normal * 0.5 * v)[None])[0]  # rock behind
            assert mine.is_free((foot + a.normal * 0.5 * v)[None])[0]
    surfaces = {a.artifact_class: a.surface for a in arts}
    assert surfaces["gas"] == "room" and surfaces["vent"] == "wall"


def test_classes_drawn_evenly_and_spread(mine):
    spec = PlacementSpec(min_spacing_m=7.0)
    arts = place_artifacts(mine, count=13, seed=5, spec=spec)
    counts = Counter(a.artifact_class for a in arts)
    assert set(counts) == set(ARTIFACT_CLASSES) and max(counts.values()) - min(counts.values()) <= 1
    assert len({a.name for a in arts}) == len(arts)
    p = _positions(arts)
    d = np.linalg.norm(p[:, None] - p[None], axis=2) + np.eye(len(p)) * 1e9
    assert d.min() >= spec.min_spacing_m
    start_d = np.linalg.norm(p - mine.start, axis=1)
    assert start_d.min() >= 8.0


@pytest.mark.parametrize("world_name", ["mine", "mesh_like"])
def test_dead_ends_get_artifacts(world_name, mine, request):
    world = request.getfixturevalue(world_name)
    arts = place_artifacts(world, count=10, seed=3)
    p = _positions(arts)
    for end in _dead_ends(mine):
        assert np.linalg.norm(p - end, axis=1).min() <= PlacementSpec().dead_end_radius_m + 1.5, end


def test_every_level_gets_artifacts(two_levels):
    levels = {d["level"]: d["pos"][2] for _, d in two_levels.centreline.nodes(data=True)}
    assert set(levels) == {0, 1}
    for seed in range(3):
        z = _positions(place_artifacts(two_levels, count=6, seed=seed))[:, 2]
        assert (z > 8.0).any() and (z < 4.0).any(), z


def test_too_many_artifacts_says_how_many_fit(mine):
    with pytest.raises(ValueError, match=r"can hold only \d+ of the 40 artifacts 10 m apart"):
        place_artifacts(mine, count=40, seed=1)


def test_bad_arguments(mine):
    with pytest.raises(ValueError, match="unknown artifact class 'drll'.*'drill'"):
        place_artifacts(mine, count=2, classes=["drll"], seed=1)
    with pytest.raises(ValueError, match="count"):
        place_artifacts(mine, count=-1, seed=1)
    with pytest.raises(ValueError, match="wall_share"):
        PlacementSpec(wall_share=1.5)


def test_listed_artifacts(mine):
    floor = mine.start + [0.0, -3.0, 0.3]
    arts = listed_artifacts(mine, [{"class": "drill", "position": floor.tolist()},
                                   {"class": "drill", "position": floor + [0, 0, 0.5]},
                                   {"class": "gas", "position": floor + [0, 0, 1.0]}])
    assert [a.name for a in arts] == ["drill_1", "drill_2", "gas_1"]
    assert [a.surface for a in arts] == ["floor", "floor", "room"]
    np.testing.assert_allclose(arts[0].position, floor)


def test_listed_wall_artifact_normal_points_into_free_space():
    free = np.zeros((20, 20, 10), dtype=bool)
    free[2:18, 5:15, 1:9] = True                                   # a box; walls at y = 0.5, 1.5
    import open3d as o3d
    world = World(name="box", voxel_size_m=0.1, origin=np.zeros(3), free=free,
                  mesh=o3d.geometry.TriangleMesh(), centreline=nx.Graph(), start=[1.0, 1.0, 0.11])
    (a,) = listed_artifacts(world, [{"class": "vent", "position": [1.0, 0.55, 0.5]}])
    assert a.surface == "wall"
    np.testing.assert_allclose(a.normal, [0.0, 1.0, 0.0], atol=1e-9)


@pytest.mark.parametrize("item, message", [
    ({"class": "drill", "position": [1, 2]}, r"artifacts\[1\]: position must be three numbers"),
    ({"class": "drils", "position": [1, 2, 3]}, r"artifacts\[1\]: unknown artifact class 'drils'"),
    ({"class": "drill", "position": [1e4, 0, 0]}, r"artifacts\[1\]: position .* is outside the world"),
    ({"class": "drill", "position": [0, 0, -0.5]},
     r"artifacts\[1\]: position .* is in rock; nearest free point \[.*\], 0\.\d m away"),
    ({"class": "drill", "position": [0, -3, 0.3], "surface": "room"}, r"artifacts\[1\]: only gas is a room"),
    ({"class": "gas", "position": [0, -3, 0.3], "surface": "floor"}, r"artifacts\[1\]: gas must be a room"),
    ({"class": "drill", "position": [0, -3, 0.3], "surface": "roof"}, r"artifacts\[1\]: unknown surface"),
])
def test_listed_artifact_errors_name_the_item(mine, item, message):
    ok = {"class": "rope", "position": (mine.start + [0.0, -3.0, 0.3]).tolist()}
    with pytest.raises(ValueError, match=message):
        listed_artifacts(mine, [ok, item])
