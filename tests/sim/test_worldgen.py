"""Unit tests for the procedural world generators and mesh worlds (small, coarse worlds)."""

import math
from pathlib import Path

import networkx as nx
import numpy as np
import pytest
from scipy import ndimage

from delve.sim import worldgen
from delve.sim.meshio import up_axis_rotation, write_scan_mesh
from delve.sim.platforms import LEGGED
from delve.sim.robot import ARRIVED, FOLLOWING, SimRobot

SMALL_MINE = dict(total_length_m=120.0, spacing_m=10.0, width_m=(2.5, 3.5),
                  height_m=(2.5, 3.0), voxel_size_m=0.3)
SMALL_CAVE = dict(total_length_m=100.0, voxel_size_m=0.4)


@pytest.fixture(scope="module")
def mine():
    return worldgen.tunnel_network(11, **SMALL_MINE)


@pytest.fixture(scope="module")
def mine_shaft_only():
    """Two levels joined by a shaft alone (no ramp)."""
    return worldgen.tunnel_network(5, levels=2, ramp=False, shaft=True, loops=1,
                                   **{**SMALL_MINE, "total_length_m": 150.0,
                                      "voxel_size_m": 0.4})


@pytest.fixture(scope="module")
def mine_ramp():
    """Two levels joined by a ramp and a shaft."""
    return worldgen.tunnel_network(8, levels=2, ramp=True, shaft=True, loops=1,
                                   **{**SMALL_MINE, "total_length_m": 150.0,
                                      "voxel_size_m": 0.4})


@pytest.fixture(scope="module")
def small_cave():
    return worldgen.cave(3, **SMALL_CAVE)


# ----------------------------------------------------------------- helpers
def walk_length(world):
    return sum(d["length_m"] for _, _, d in world.centreline.edges(data=True)
               if d["kind"] != "shaft")


def slope_deg(world, a, b):
    """Slope of an edge's floor where it climbs (between the flat landings at its ends)."""
    pa, pb = world.centreline.nodes[a]["pos"], world.centreline.nodes[b]["pos"]
    landing = world.centreline.edges[a, b].get("landing_m", 0.0)
    dz = abs(pb[2] - pa[2])
    if dz < 1e-9:
        return 0.0
    return math.degrees(math.atan2(dz, float(np.hypot(*(pb[:2] - pa[:2]))) - 2.0 * landing))


def floor_components(world):
    """Label the voxels a legged robot can stand in: free, with rock right below."""
    floor = world.free.copy()
    floor[:, :, 0] = False
    floor[:, :, 1:] &= ~world.free[:, :, :-1]
    labels, _ = ndimage.label(floor, structure=np.ones((3, 3, 3), bool))
    return labels


def floor_label(world, labels, pos):
    """Floor label under a centreline point (searching a small patch around it)."""
    v = world.voxel_size_m
    idx = world.to_index(np.asarray(pos)[None] + [0.0, 0.0, 0.5 * v])[0]
    r = 2
    patch = labels[idx[0] - r:idx[0] + r + 1, idx[1] - r:idx[1] + r + 1,
                   idx[2] - r:idx[2] + r + 1]
    vals = patch[patch > 0]
    assert len(vals), f"no floor under {pos}"
    return int(np.bincount(vals).argmax())


def off_shaft(world, nodes):
    """The nodes that do not stand over a shaft mouth (those have no floor)."""
    ends = {n for a, b, d in world.centreline.edges(data=True) if d["kind"] == "shaft"
            for n in (a, b)}
    return [n for n in nodes if n not in ends]


def levels_joined_without(world, kind):
    g = nx.Graph(world.centreline)
    g.remove_edges_from([(a, b) for a, b, d in world.centreline.edges(data=True)
                         if d["kind"] == kind])
    up = [n for n, d in g.nodes(data=True) if d["level"] == 1]
    return any(nx.has_path(g, 0, n) for n in up)


# ------------------------------------------------------------- tunnel network
def test_mine_is_deterministic(mine):
    again = worldgen.tunnel_network(11, **SMALL_MINE)
    assert again.free.tobytes() == mine.free.tobytes()
    np.testing.assert_array_equal(again.origin, mine.origin)
    other = worldgen.tunnel_network(12, **SMALL_MINE)
    assert other.free.shape != mine.free.shape or other.free.tobytes() != mine.free.tobytes()


def test_mine_length_and_attributes(mine):
    assert walk_length(mine) == pytest.approx(120.0, rel=0.1)
    g = mine.centreline
    for a, b, d in g.edges(data=True):
        assert d["kind"] in {"tunnel", "ramp"}
        assert 2.5 <= d["width_m"] <= 3.5 and 2.5 <= d["height_m"] <= 3.0
        assert d["length_m"] == pytest.approx(
            float(np.linalg.norm(g.nodes[a]["pos"] - g.nodes[b]["pos"])))
    assert all(d["level"] == 0 and d["pos"].shape == (3,) for _, d in g.nodes(data=True))


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_mine_length_for_default_spacing(seed):
    w = worldgen.tunnel_network(seed, total_length_m=300.0, voxel_size_m=0.5)
    assert walk_length(w) == pytest.approx(300.0, rel=0.1)


def test_mine_slopes_within_limit_and_some_steep(mine):
    slopes = [slope_deg(mine, a, b) for a, b in mine.centreline.edges()]
    assert max(slopes) <= 30.0 + 1e-6
    assert max(slopes) >= 0.75 * 30.0            # ramp=True: some tunnels climb near the limit
    assert min(slopes) == pytest.approx(0.0, abs=1e-6)   # and some are flat
    gentle = worldgen.tunnel_network(11, ramp=False, max_slope_deg=20.0, **SMALL_MINE)
    assert max(slope_deg(gentle, a, b) for a, b in gentle.centreline.edges()) <= 20.0 + 1e-6


def test_mine_loops_and_dead_ends(mine):
    g = mine.centreline
    assert len(nx.cycle_basis(g)) >= 2
    assert nx.is_connected(g)
    dead_ends = [n for n in g if g.degree(n) == 1 and n != 0]
    assert dead_ends
    tree = worldgen.tunnel_network(11, loops=0, **SMALL_MINE)
    assert nx.is_tree(tree.centreline)


def test_mine_floor_and_start(mine):
    assert mine.start_problem(mine.start) is None
    np.testing.assert_allclose(mine.start[:2], mine.centreline.nodes[0]["pos"][:2])
    v = mine.voxel_size_m
    pos = np.array([d["pos"] for _, d in mine.centreline.nodes(data=True)])
    ground = mine.ground_height(pos + [0.0, 0.0, 1.0], 2.0)
    np.testing.assert_allclose(ground, pos[:, 2], atol=v + 1e-6)
    assert mine.is_free(pos + [0.0, 0.0, 0.5]).all()
    assert mine.reachable_free(mine.start)[tuple(mine.to_index(pos[-1:] + [0, 0, 0.5])[0])]


def test_mine_flat_tunnel_geometry(mine):
    """Along a flat tunnel the floor is level and the walls are width_m apart."""
    g = mine.centreline
    flat = [(a, b, d) for a, b, d in g.edges(data=True)
            if slope_deg(mine, a, b) < 1e-6 and d["length_m"] > 6.0]
    assert flat
    a, b, d = flat[0]
    pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
    mid = 0.5 * (pa + pb)
    axis = (pb - pa) / np.linalg.norm(pb - pa)
    side = np.array([-axis[1], axis[0], 0.0])
    o = np.repeat((mid + [0.0, 0.0, 1.0])[None], 2, 0)
    dist = mine.cast_rays(o, np.array([side, -side]), 50.0)
    assert dist.sum() == pytest.approx(d["width_m"], abs=3 * mine.voxel_size_m)
    lateral = mid + np.outer([-0.3, 0.0, 0.3], side) * d["width_m"] + [0.0, 0.0, 1.0]
    np.testing.assert_allclose(mine.ground_height(lateral, 2.0), mid[2],
                               atol=mine.voxel_size_m + 1e-6)


def test_mine_hits_nudged_land_in_rock(mine):
    rng = np.random.default_rng(4)
    idx = np.argwhere(mine.free)
    o = mine.index_to_center(idx[rng.choice(len(idx), 3000)])
    d = rng.normal(size=o.shape)
    d /= np.linalg.norm(d, axis=1)[:, None]
    t = mine.cast_rays(o, d, 200.0)
    assert np.isfinite(t).all()
    hit = o + d * t[:, None]
    assert np.mean(~mine.is_free(hit + 0.05 * d)) > 0.97


def test_shaft_only_levels(mine_shaft_only):
    w = mine_shaft_only
    g = w.centreline
    shafts = [(a, b, d) for a, b, d in g.edges(data=True) if d["kind"] == "shaft"]
    assert len(shafts) == 1
    a, b, d = shafts[0]
    pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
    np.testing.assert_allclose(pa[:2], pb[:2])             # vertical
    assert 10.0 <= abs(pb[2] - pa[2]) <= 17.0
    assert {g.nodes[a]["level"], g.nodes[b]["level"]} == {0, 1}
    assert 3.0 <= d["width_m"] <= 4.0
    assert not any(dd["kind"] == "ramp" and g.nodes[x]["level"] != g.nodes[y]["level"]
                   for x, y, dd in g.edges(data=True))
    assert not levels_joined_without(w, "shaft")
    # a legged robot's floor on the lower level does not reach the upper level
    labels = floor_components(w)
    low = floor_label(w, labels, g.nodes[0]["pos"])
    up_nodes = [n for n, dd in g.nodes(data=True) if dd["level"] == 1]
    assert all(floor_label(w, labels, g.nodes[n]["pos"]) != low
               for n in off_shaft(w, up_nodes))
    # ... but the air does (a flying robot can go up the shaft)
    air = w.reachable_free(w.start)
    top = pb if pb[2] > pa[2] else pa
    assert air[tuple(w.to_index(top[None] + [0.0, 0.0, 1.0])[0])]
    # over the shaft mouth there is no ground within reach
    assert np.isnan(w.ground_height(top[None] + [0.0, 0.0, 1.0], 2.0)[0])
    # the upper level lies above part of the lower one
    low_xy = np.array([dd["pos"][:2] for _, dd in g.nodes(data=True) if dd["level"] == 0])
    up_xy = np.array([g.nodes[n]["pos"][:2] for n in up_nodes])
    gap = np.min(np.linalg.norm(low_xy[:, None] - up_xy[None], axis=2))
    assert gap < 1.0


def test_ramp_joins_levels(mine_ramp):
    w = mine_ramp
    g = w.centreline
    ramps = [(a, b) for a, b, d in g.edges(data=True) if d["kind"] == "ramp"
             and g.nodes[a]["level"] != g.nodes[b]["level"]]
    assert len(ramps) == 1
    a, b = ramps[0]
    assert 0.75 * 30.0 <= slope_deg(w, a, b) <= 30.0 + 1e-6
    rise = abs(g.nodes[a]["pos"][2] - g.nodes[b]["pos"][2])
    assert 10.0 <= rise <= 17.0
    assert walk_length(w) == pytest.approx(150.0, rel=0.1)
    assert levels_joined_without(w, "shaft")
    labels = floor_components(w)
    low = floor_label(w, labels, g.nodes[0]["pos"])
    up = [n for n, d in g.nodes(data=True) if d["level"] == 1]
    assert any(floor_label(w, labels, g.nodes[n]["pos"]) == low for n in off_shaft(w, up))
    assert any(d["kind"] == "shaft" for _, _, d in g.edges(data=True))


def test_single_level_shaft_to_gallery():
    w = worldgen.tunnel_network(2, shaft=True, loops=1,
                                **{**SMALL_MINE, "voxel_size_m": 0.4})
    g = w.centreline
    gallery = [n for n, d in g.nodes(data=True) if d["level"] == 1]
    assert 2 <= len(gallery) <= 3
    shafts = [(a, b) for a, b, d in g.edges(data=True) if d["kind"] == "shaft"]
    assert len(shafts) == 1
    a, b = shafts[0]
    np.testing.assert_allclose(g.nodes[a]["pos"][:2], g.nodes[b]["pos"][:2])
    assert not levels_joined_without(w, "shaft")
    labels = floor_components(w)
    low = floor_label(w, labels, g.nodes[0]["pos"])
    assert all(floor_label(w, labels, g.nodes[n]["pos"]) != low
               for n in off_shaft(w, gallery))
    # gallery tunnels are dead ends
    assert any(g.degree(n) == 1 for n in gallery)


def blocked_walks(world):
    """(from, to, reason) of every walkable centreline edge a legged robot cannot walk
    along, in either direction, with the simulator's motion model (0.1 s steps)."""
    g = world.centreline
    out = []
    for a, b, d in g.edges(data=True):
        if d["kind"] == "shaft":
            continue
        for s, t in ((a, b), (b, a)):
            start = g.nodes[s]["pos"].copy()
            ground = world.ground_height(start[None] + [0.0, 0.0, 0.6], 2.0)[0]
            start[2] = ground if np.isfinite(ground) else start[2]     # a cave's floor may lie lower
            robot = SimRobot("walker", LEGGED, world, start, radio=None)
            robot.follow_path(g.nodes[t]["pos"][None] + [0.0, 0.0, LEGGED.body_height_m])
            for _ in range(int(2 * d["length_m"] / (LEGGED.speed_mps * 0.1)) + 10):
                if robot.path_status != FOLLOWING:
                    break
                robot.step(0.1)
            if robot.path_status != ARRIVED:
                out.append((s, t, robot.blocked_reason))
    return out


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
@pytest.mark.parametrize("kwargs", [dict(total_length_m=300, loops=2, max_slope_deg=30),
                                    dict(total_length_m=300, levels=2, ramp=True, loops=1,
                                         max_slope_deg=20)], ids=["network", "two_level"])
def test_mine_passages_are_walkable(kwargs, seed):
    """Junction floors meet the climbing tunnels without a step (landings) and no tunnel
    runs along another from a shared junction: every passage is walkable both ways."""
    w = worldgen.tunnel_network(seed, **kwargs)
    assert blocked_walks(w) == []



@pytest.mark.parametrize("kwargs, message", [
    (dict(total_length_m=-5.0), "total_length_m"),
    (dict(total_length_m=float("nan")), "total_length_m"),
    (dict(spacing_m=0.0), "spacing_m"),
    (dict(levels=3), "levels"),
    (dict(levels=2, ramp=False, shaft=False), "ramp"),
    (dict(width_m=(5.0, 3.0)), "width_m"),
    (dict(width_m=(0.1, 3.0)), "width_m"),
    (dict(height_m=(2.0, float("inf"))), "height_m"),
    (dict(max_slope_deg=0.0), "max_slope_deg"),
    (dict(max_slope_deg=75.0), "max_slope_deg"),
    (dict(loops=-1), "loops"),
    (dict(spacing_m=5.0), "spacing_m"),
    (dict(total_length_m=30.0, loops=3), "loop"),
    (dict(region_m=(60.0,)), "region_m"),
    (dict(region_m=(60.0, -1.0)), "region_m"),
])
def test_mine_rejects_impossible_parameters(kwargs, message):
    params = {**SMALL_MINE, **kwargs}
    with pytest.raises(ValueError, match=message):
        worldgen.tunnel_network(0, **params)


def test_mine_grows_within_its_region():
    """A network given a long, narrow region fills it: about 60 m along x and
    200 m across y (plus the tunnels' half widths and the grid's margin)."""
    world = worldgen.tunnel_network(3, total_length_m=700.0, spacing_m=20.0, loops=1,
                                    region_m=(60.0, 200.0))
    pos = np.array([p for _, p in world.centreline.nodes(data="pos")])
    assert pos[:, 0].min() > -5 and pos[:, 0].max() < 65
    assert pos[:, 1].min() > -105 and pos[:, 1].max() < 105
    assert pos[:, 1].max() - pos[:, 1].min() > 2 * (pos[:, 0].max() - pos[:, 0].min())


# -------------------------------------------------------------------- cave
def test_cave_is_deterministic(small_cave):
    again = worldgen.cave(3, **SMALL_CAVE)
    assert again.free.tobytes() == small_cave.free.tobytes()
    other = worldgen.cave(4, **SMALL_CAVE)
    assert other.free.shape != small_cave.free.shape or \
        other.free.tobytes() != small_cave.free.tobytes()


def test_cave_length_and_graph(small_cave):
    g = small_cave.centreline
    assert walk_length(small_cave) == pytest.approx(100.0, rel=0.1)
    kinds = {d["kind"] for _, _, d in g.edges(data=True)}
    assert kinds == {"cave", "shaft"}
    assert nx.is_tree(g)
    assert sum(1 for n in g if g.degree(n) == 1) >= 3      # branches end in dead ends
    assert small_cave.start_problem(small_cave.start) is None


def test_cave_widths_span_the_range(small_cave):
    g = small_cave.centreline
    cave_edges = [(a, b, d) for a, b, d in g.edges(data=True) if d["kind"] == "cave"]
    widths = [d["width_m"] for _, _, d in cave_edges]
    assert min(widths) <= 2.0 and max(widths) >= 10.5
    assert all(1.0 - 1e-9 <= w <= 15.0 + 1e-9 for w in widths)

    def measured(a, b):
        """Wall-to-wall width across the passage at each end of the edge."""
        pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
        axis = (pb - pa)[:2] / np.linalg.norm((pb - pa)[:2])
        side = np.array([-axis[1], axis[0], 0.0])
        out = []
        for p in (pa, pb):
            o = p + [0.0, 0.0, 0.3 * g.edges[a, b]["height_m"]]
            out.append(float(small_cave.cast_rays(np.repeat(o[None], 2, 0),
                                                  np.array([side, -side]), 50.0).sum()))
        return out

    a, b, d = min(cave_edges, key=lambda e: e[2]["width_m"])
    assert min(measured(a, b)) < d["width_m"] + 1.5
    a, b, d = max(cave_edges, key=lambda e: e[2]["width_m"])
    assert min(measured(a, b)) > 0.6 * d["width_m"]


def test_cave_floors_are_walkable(small_cave):
    g = small_cave.centreline
    pos = np.array([g.nodes[n]["pos"] for n in off_shaft(small_cave, g.nodes)])
    v = small_cave.voxel_size_m
    ground = small_cave.ground_height(pos + [0.0, 0.0, 1.0], 2.0)
    # the floor is at the node, or lower where a wider passage it branches off takes over
    assert np.all(ground <= pos[:, 2] + v + 1e-6) and np.all(ground >= pos[:, 2] - 1.0)
    assert np.mean(np.abs(ground - pos[:, 2]) <= v + 1e-6) > 0.9
    slopes = [slope_deg(small_cave, a, b) for a, b, d in g.edges(data=True)
              if d["kind"] == "cave"]
    assert max(slopes) <= 12.0 + 1e-6


@pytest.mark.parametrize("seed", [2, 3])
def test_cave_passages_are_walkable(seed):
    """A segment's rounded cap rises away from an end where another segment goes on, so it
    does not undercut one that climbs (seeds 2 and 3 had 0.4 m steps there)."""
    w = worldgen.cave(seed, total_length_m=250.0, shaft=False, width_m=(2.0, 6.0), height_m=(2.0, 4.0))
    assert blocked_walks(w) == []


def test_cave_shaft_reaches_an_isolated_upper_passage(small_cave):
    w = small_cave
    g = w.centreline
    (a, b, d), = [(a, b, d) for a, b, d in g.edges(data=True) if d["kind"] == "shaft"]
    low, up = (a, b) if g.nodes[a]["level"] == 0 else (b, a)
    assert g.nodes[up]["level"] == 1
    np.testing.assert_allclose(g.nodes[low]["pos"][:2], g.nodes[up]["pos"][:2])
    assert g.nodes[up]["pos"][2] - g.nodes[low]["pos"][2] == pytest.approx(15.0)
    assert d["length_m"] == pytest.approx(15.0)
    assert not levels_joined_without(w, "shaft")
    labels = floor_components(w)
    low_label = floor_label(w, labels, g.nodes[0]["pos"])
    upper = [n for n, dd in g.nodes(data=True) if dd["level"] == 1]
    assert len(upper) >= 2
    assert all(floor_label(w, labels, g.nodes[n]["pos"]) != low_label
               for n in off_shaft(w, upper))
    assert w.reachable_free(w.start)[tuple(w.to_index(g.nodes[up]["pos"][None]
                                                      + [0.0, 0.0, 1.0])[0])]


def test_cave_without_shaft():
    w = worldgen.cave(5, shaft=False, **SMALL_CAVE)
    assert all(d["level"] == 0 for _, d in w.centreline.nodes(data=True))
    assert all(d["kind"] == "cave" for _, _, d in w.centreline.edges(data=True))
    assert walk_length(w) == pytest.approx(100.0, rel=0.1)


@pytest.mark.parametrize("kwargs, message", [
    (dict(total_length_m=0.0), "total_length_m"),
    (dict(width_m=(0.0, 5.0)), "width_m"),
    (dict(width_m=(6.0, 5.0)), "width_m"),
    (dict(height_m=(3.0,)), "height_m"),
    (dict(shaft_height_m=4.0), "shaft_height_m"),
    (dict(voxel_size_m=-0.1), "voxel_size_m"),
])
def test_cave_rejects_impossible_parameters(kwargs, message):
    with pytest.raises(ValueError, match=message):
        worldgen.cave(0, **{**SMALL_CAVE, **kwargs})


# ------------------------------------------------------------ mesh worlds
@pytest.mark.parametrize("up_axis, suffix", [("y", ".ply"), ("-x", ".stl"), ("z", ".obj")])
def test_from_mesh_round_trip(mine, tmp_path, up_axis, suffix):
    """Save the mesh in centimetres with another up axis; loading restores the world."""
    path = tmp_path / f"mine{suffix}"
    if suffix == ".ply":
        write_scan_mesh(mine.mesh, path, scale=0.01, up_axis=up_axis)
    else:
        import open3d as o3d
        verts = (np.asarray(mine.mesh.vertices) @ up_axis_rotation(up_axis)) * 100.0
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts), mine.mesh.triangles)
        mesh.compute_triangle_normals()
        o3d.io.write_triangle_mesh(str(path), mesh)
    back = worldgen.from_mesh(path, scale=0.01, up_axis=up_axis,
                              voxel_size_m=mine.voxel_size_m)
    assert back.name == "mine"
    assert back.free_volume_m3 == pytest.approx(mine.free_volume_m3, rel=0.1)
    np.testing.assert_allclose(back.bounds_min, mine.bounds_min, atol=3 * mine.voxel_size_m)
    assert back.start_problem(back.start) is None
    assert np.isfinite(back.ground_height(back.start[None], 0.5)[0])
    assert back.centreline.number_of_nodes() == 0
    o = back.start + [0.0, 0.0, 1.0]
    assert np.isfinite(back.cast_rays(o[None], np.array([[0.0, 0.0, 1.0]]), 20.0)[0])


def test_from_mesh_start_and_errors(mine, tmp_path):
    path = tmp_path / "mine.ply"
    mine.save_mesh(path)
    w = worldgen.from_mesh(path, start=mine.start, name="given", voxel_size_m=0.3)
    np.testing.assert_allclose(w.start, mine.start)
    assert w.name == "given"
    # the rock voxel furthest from any passage and from the grid's edge
    depth = ndimage.distance_transform_edt(~np.pad(w.free, 1, constant_values=True))[1:-1, 1:-1, 1:-1]
    rock = w.origin + (np.asarray(np.unravel_index(np.argmax(depth), depth.shape)) + 0.5) * 0.3
    with pytest.raises(ValueError, match="inside rock"):
        worldgen.from_mesh(path, start=rock, voxel_size_m=0.3)
    with pytest.raises(ValueError, match="cannot read mesh"):
        worldgen.from_mesh(tmp_path / "missing.ply")
    junk = tmp_path / "junk.ply"
    junk.write_text("not a mesh\n")
    with pytest.raises(ValueError, match="cannot read mesh"):
        worldgen.from_mesh(junk)
    with pytest.raises(ValueError, match="up_axis"):
        worldgen.from_mesh(path, up_axis="w")


def test_scanned_mine_asset_loads():
    path = worldgen.SCANNED_MINE_PATH
    assert path.is_file() and path.stat().st_size < 3_000_000
    with path.open("rb") as f:
        head = f.read(200)
    assert head.startswith(b"ply") and b"binary" in head
    w = worldgen.scanned_mine(voxel_size_m=0.3)
    extent = w.bounds_max - w.bounds_min
    assert extent[2] < min(extent[0], extent[1])        # loaded upright, in metres
    assert 20.0 < extent[0] < 200.0
    assert 500.0 < w.free_volume_m3 < 5000.0
    assert w.start_problem(w.start) is None
    assert w.reachable_free(w.start).sum() > 0.9 * w.free.sum()


def test_write_scanned_mine_regenerates(tmp_path):
    path = worldgen.write_scanned_mine(tmp_path / "scan.ply", target_triangles=20_000)
    assert isinstance(path, Path) and path.stat().st_size < 1_000_000
    w = worldgen.scanned_mine(path=path, voxel_size_m=0.4)
    asset = worldgen.scanned_mine(voxel_size_m=0.4)
    assert w.free_volume_m3 == pytest.approx(asset.free_volume_m3, rel=0.1)
