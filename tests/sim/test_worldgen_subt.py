"""Unit tests for the SubT-Final-like course (worldgen.subt_final), on small, coarse courses."""
from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest
from scipy import ndimage

from delve import TREES_DIR
from delve.executive.errors import DelveError
from delve.executive.scenario import load_scenario
from delve.sim import worldgen
from delve.sim.platforms import AERIAL, LEGGED
from delve.sim.worldgen_subt import HALL_SIZE_M, MAX_WALKABLE_SLOPE_DEG
from delve.sim.worldgen_subt_plan import SECTIONS
from delve.sim.worldgen_subt_urban import CORRIDOR_M, DOOR_WIDTH_M, URBAN_LEVEL_RISE_M, WALL_M

#: A course of about 500 m: sections of 175, 112 and 138 m, voxels the legged step height.
SMALL = dict(scale=0.25, voxel_size_m=0.3)


@pytest.fixture(scope="module")
def course():
    return worldgen.subt_final(4, **SMALL)


def section_nodes(world, section):
    return [n for n, d in world.centreline.nodes(data=True) if d["section"] == section]


def section_length(world, section):
    return sum(d["length_m"] for _, _, d in world.centreline.edges(data=True) if d["section"] == section)


def voxel_above(world, node, height_m=0.5):
    return tuple(world.to_index(world.centreline.nodes[node]["pos"][None] + [0.0, 0.0, height_m])[0])


def along_edges(world, step_m):
    """Points every ``step_m`` along every centreline edge, one array per edge."""
    g = world.centreline
    for a, b in g.edges:
        pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
        n = max(int(math.ceil(np.linalg.norm(pb - pa) / step_m)), 1) + 1
        yield (a, b), pa + np.linspace(0.0, 1.0, n)[:, None] * (pb - pa)


def test_the_same_seed_gives_the_same_course_and_another_seed_another():
    a, b = worldgen.subt_final(4, **SMALL), worldgen.subt_final(4, **SMALL)
    assert a.free.shape == b.free.shape and np.array_equal(a.free, b.free)
    assert np.array_equal(a.origin, b.origin)
    c = worldgen.subt_final(5, **SMALL)
    assert c.free.shape != a.free.shape or not np.array_equal(a.free, c.free)


def test_every_section_is_there_and_reachable_from_the_entrance(course):
    reach = course.reachable_free(course.start)
    g = course.centreline
    assert {d["section"] for _, d in g.nodes(data=True)} == set(SECTIONS)
    assert {d["section"] for _, _, d in g.edges(data=True)} == set(SECTIONS)
    assert nx.is_connected(g)
    for n in g.nodes:
        assert reach[voxel_above(course, n)], (n, g.nodes[n])
    assert g.nodes[0]["section"] == "hall"
    portal = [n for n, d in g.nodes(data=True) if d["section"] == "entrance" and g.degree(n) == 1]
    assert len(portal) == 1 and np.allclose(g.nodes[portal[0]]["pos"][:2], course.start[:2])


def test_the_entrance_is_an_inclined_drift_with_a_sharp_turn(course):
    g = course.centreline
    edges = [(a, b) for a, b, d in g.edges(data=True) if d["section"] == "entrance"]
    path = nx.shortest_path(g.subgraph({n for e in edges for n in e}), *[
        n for n in {n for e in edges for n in e} if g.degree(n) == 1 or g.nodes[n]["section"] == "hall"])
    pos = [g.nodes[n]["pos"] for n in path]
    legs = [b - a for a, b in zip(pos, pos[1:])]
    incline = [math.degrees(math.atan2(abs(v[2]), math.hypot(v[0], v[1]))) for v in legs]
    assert max(incline) == pytest.approx(15.0, abs=1.0) and sorted(incline)[:-1] == [0.0] * (len(legs) - 1)
    turns = [math.degrees(math.acos(np.dot(u[:2], w[:2]) / np.linalg.norm(u[:2]) / np.linalg.norm(w[:2])))
             for u, w in zip(legs, legs[1:])]
    assert max(turns) > 90.0                            # the way on turns by more than 90 deg


def test_section_lengths_follow_the_parameters(course):
    for section, default in (("tunnel", 700.0), ("urban", 450.0), ("cave", 550.0)):
        assert section_length(course, section) == pytest.approx(0.25 * default, rel=0.1)
    world = worldgen.subt_final(1, scale=0.25, urban_length_m=600.0, voxel_size_m=0.4)
    assert section_length(world, "urban") == pytest.approx(150.0, rel=0.1)
    total = sum(d["length_m"] for _, _, d in world.centreline.edges(data=True))
    fixed = section_length(world, "entrance") + section_length(world, "hall")
    assert total == pytest.approx(0.25 * (700 + 600 + 550) + fixed, rel=0.1)


def test_the_urban_section_has_two_levels_joined_by_stairs(course):
    g = course.centreline
    urban = section_nodes(course, "urban")
    z = {lvl: {round(float(g.nodes[n]["pos"][2]), 1) for n in urban if g.nodes[n]["level"] == lvl}
         for lvl in (0, 1)}
    assert z[0] == {0.0} and z[1] == {URBAN_LEVEL_RISE_M}
    stairs = [(a, b) for a, b, d in g.edges(data=True) if d["kind"] == "stairs"]
    assert len(stairs) == 2                       # up to the upper level, down to the tunnel
    for a, b in stairs:
        assert {g.nodes[a]["level"], g.nodes[b]["level"]} == {0, 1}
    # the upper level stands over the lower one: some column holds both, rock between
    v = course.voxel_size_m
    stacked = 0
    for n in urban:
        if g.nodes[n]["level"] == 1:
            i, j, k = voxel_above(course, n)
            below = course.free[i, j, : k - int(2.0 / v)]
            stacked += bool(below.any())
    assert stacked >= 1


def test_rooms_are_dead_ends_behind_a_wall_with_a_door():
    world = worldgen.subt_final(2, scale=0.5, voxel_size_m=0.3)
    g = world.centreline
    rooms = [(a, b) for a, b, d in g.edges(data=True) if d["kind"] == "room"]
    assert len(rooms) >= 4
    for a, b in rooms:
        inner, door = (b, a) if g.degree(b) == 1 else (a, b)
        assert g.degree(inner) == 1                   # a room is a dead end behind its door
        pi, pd = g.nodes[inner]["pos"], g.nodes[door]["pos"]
        side = np.sign(pi[0] - pd[0])
        wall = pd + [side * (0.5 * CORRIDOR_M + 0.5 * WALL_M), 0.0, 1.0]
        assert world.is_free(np.array([wall, pi + [0.0, 0.0, 1.0]])).all()
        beside = wall + [[0.0, DOOR_WIDTH_M, 0.0], [0.0, -DOOR_WIDTH_M, 0.0]]
        assert not world.is_free(beside).any()


def test_the_cavern_is_much_wider_than_the_passages(course):
    g = course.centreline
    v = course.voxel_size_m
    widest = {}
    for n in section_nodes(course, "cave"):
        i, j, k = voxel_above(course, n, 1.0)
        if k not in widest:
            widest[k] = ndimage.distance_transform_edt(course.free[:, :, k]) * v
        widest[n] = widest[k][i, j]
    radii = np.array([widest[n] for n in section_nodes(course, "cave")])
    assert radii.max() >= 0.3 * 20.0                  # the default cavern is 20 m wide
    assert np.median(radii) <= 2.6                    # passages at most 5 m wide


def test_crossovers_join_the_sections_besides_the_hall(course):
    g = course.centreline
    cycles = [{g.nodes[n]["section"] for n in c} for c in nx.cycle_basis(g)]
    assert any({"tunnel", "urban"} <= c for c in cycles)
    assert any({"tunnel", "cave"} <= c for c in cycles)
    # without the hall, the free space still joins the three sections
    free = course.free.copy()
    hx, hy, hz = 0.5 * HALL_SIZE_M[0], 0.5 * HALL_SIZE_M[1], HALL_SIZE_M[2]
    lo = course.to_index(np.array([[-hx - 1.0, -hy - 1.0, -1.0]]))[0]
    hi = course.to_index(np.array([[hx + 1.0, hy + 1.0, hz + 1.0]]))[0]
    free[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1, lo[2]:hi[2] + 1] = False
    labels, _ = ndimage.label(free, structure=np.ones((3, 3, 3), bool))
    far = {s: max(section_nodes(course, s), key=lambda n: np.linalg.norm(g.nodes[n]["pos"][:2]))
           for s in ("tunnel", "urban", "cave")}
    ids = {s: labels[voxel_above(course, n)] for s, n in far.items()}
    assert ids["tunnel"] > 0 and ids["tunnel"] == ids["urban"] == ids["cave"]


def test_a_legged_robot_can_walk_every_passage_and_an_aerial_one_fly_it(course):
    g = course.centreline
    v = course.voxel_size_m
    for a, b, d in g.edges(data=True):
        pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
        slope = math.degrees(math.atan2(abs(pb[2] - pa[2]), math.hypot(*(pb - pa)[:2])))
        assert slope <= MAX_WALKABLE_SLOPE_DEG + 1e-6, (d, slope)
    for (a, b), pts in along_edges(course, 0.1):
        ground = course.ground_height(pts + [0.0, 0.0, 1.0], 2.0)
        assert np.isfinite(ground).all(), (a, b, g.edges[a, b])
        assert np.abs(np.diff(ground)).max() <= max(LEGGED.max_step_m, v) + 1e-6
        body = ground[:, None] + [LEGGED.body_height_m, AERIAL.body_height_m]
        for k in range(2):
            assert course.is_free(np.column_stack([pts[:, :2], body[:, k]])).all(), (a, b)


@pytest.mark.parametrize("kwargs, message", [
    (dict(scale=0), "scale must be a positive"),
    (dict(tunnel_length_m=-5), "tunnel_length_m must be a positive"),
    (dict(cave_length_m="long"), "cave_length_m must be a number"),
    (dict(voxel_size_m=0.5), "voxel_size_m must be at most 0.4"),
    (dict(entrance_slope_deg=40), r"entrance_slope_deg must lie in \(0, 30\]"),
    (dict(stair_slope_deg=0), r"stair_slope_deg must lie in \(0, 30\]"),
    (dict(cavern_width_m=6), r"cavern_width_m must lie in \[10, 40\]"),
    (dict(cavern_height_m=2), r"cavern_height_m must lie in \[4.5, 40\]"),
    (dict(scale=0.05), "urban section needs at least"),
    (dict(scale=100), "scale: the sections add up to 170000 m, more than 20000 m"),
    (dict(voxel_size_m=0.05), "raise voxel_size_m"),
])
def test_impossible_parameters_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        worldgen.subt_final(1, **{"voxel_size_m": 0.4, **kwargs})


def test_a_scenario_names_the_key_at_fault(tmp_path):
    path = tmp_path / "course.yaml"
    path.write_text(f"""name: course
seed: 1
duration_s: 10
world:
  generator: subt_final
  scale: 0.25
  cavern_width_m: 60
robots:
  - name: anymal
    platform: legged
    tree: {TREES_DIR}/frontier_explorer.yaml
""")
    with pytest.raises(DelveError) as err:
        load_scenario(path).build_world()
    assert str(err.value).startswith(f"{path}:7: world: cavern_width_m must lie in [10, 40]")
