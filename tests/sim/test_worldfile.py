"""Worlds from the files users bring (delve.sim.worldfile, geometry_io, freespace):
each format loads, closed inner surfaces keep the exact path, open and slab-and-wall
models and point clouds give the free volume expected.

Tolerances: a closed inner surface is exact to the voxel centres (2 %); a surface
built world loses at most one voxel layer at each surface it is bounded by (floor,
walls, the ceiling added at the model top); a point cloud with rock one voxel around
each point loses up to two more layers a surface (noise puts points in a second
voxel), so its free volume lies between the corridor shrunk by four voxels a side
and the corridor itself."""
from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest
import trimesh

from delve.sim import worldgen
from delve.sim.freespace import mesh_closure
from delve.sim.worldfile import from_file
from delve.sim.world_survey import survey, world_warnings

from .mine_models import (HEIGHT, LENGTH, WIDTH, closed_corridor, corridor_cloud, open_corridor, slab_and_wall,
                          turned, write_collada)

V = 0.2
FULL = LENGTH * WIDTH * HEIGHT


def within_surface_tolerance(world, layers: int = 1) -> None:
    """Free volume between the corridor shrunk by ``layers`` voxels at floor, walls and
    ceiling and the corridor itself (ends open: their length may grow by a voxel)."""
    shrunk = (WIDTH - 2 * layers * V) * (HEIGHT - 2 * layers * V) * LENGTH
    assert shrunk <= world.free_volume_m3 <= FULL * (1 + 2 * V / LENGTH), world.free_volume_m3


def test_a_closed_inner_surface_keeps_the_exact_path(tmp_path):
    path = tmp_path / "closed.ply"
    closed_corridor().export(path)
    w = from_file(path, voxel_size_m=V)
    assert w.source.free_space == "closed" and w.source.closure == "inner"
    assert w.free_volume_m3 == pytest.approx(FULL, rel=0.02)
    assert w.start_problem(w.start) is None
    assert not world_warnings(w, survey(w))


def test_the_scanned_mine_asset_loads_as_before():
    old = worldgen.scanned_mine(voxel_size_m=0.4)
    new = from_file(worldgen.SCANNED_MINE_PATH, scale=worldgen.SCANNED_MINE_SCALE,
                    up_axis=worldgen.SCANNED_MINE_UP_AXIS, voxel_size_m=0.4, name="scanned_mine")
    assert new.source.free_space == "closed"
    np.testing.assert_array_equal(new.free, old.free)
    np.testing.assert_array_equal(new.origin, old.origin)
    np.testing.assert_array_equal(new.start, old.start)
    np.testing.assert_array_equal(np.asarray(new.mesh.vertices), np.asarray(old.mesh.vertices))


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply", ".glb"])
def test_a_slab_and_wall_model_in_each_mesh_format(tmp_path, suffix):
    path = tmp_path / f"mine{suffix}"
    slab_and_wall().export(path)
    w = from_file(path, voxel_size_m=V, up_axis="z")
    assert w.source.free_space == "surface" and w.source.closure == "solids"
    assert w.source.ceiling_z == pytest.approx(HEIGHT) and w.source.ceiling_from == "model top"
    within_surface_tolerance(w)
    assert len(survey(w).significant_regions) == 1           # the walls' insides are rock, not regions
    messages = [x.message for x in world_warnings(w, survey(w))]
    assert any("encloses solids" in m for m in messages), messages


def test_an_open_mesh_is_built_from_its_surface(tmp_path):
    path = tmp_path / "sheets.obj"
    open_corridor().export(path)
    w = from_file(path, voxel_size_m=V)
    assert w.source.closure == "open" and w.source.boundary_edges > 0
    within_surface_tolerance(w)
    [warning] = [x for x in world_warnings(w, survey(w)) if x.key == "mesh"]
    assert "is open" in warning.message and "ceiling at the model top, z = 3.0 m" in warning.message


def test_a_ceiling_height_the_user_gives(tmp_path):
    path = tmp_path / "sheets.obj"
    open_corridor().export(path)
    w = from_file(path, voxel_size_m=V, ceiling_m=2.0)
    assert w.source.ceiling_from == "scenario"
    assert w.bounds_max[2] <= HEIGHT + V + 1e-9
    assert (WIDTH - 2 * V) * (2.0 - 2 * V) * LENGTH <= w.free_volume_m3 <= WIDTH * 2.0 * LENGTH * 1.05
    with pytest.raises(ValueError, match="ceiling_m -1 is not above the model's bottom"):
        from_file(path, voxel_size_m=V, ceiling_m=-1.0)


def test_a_closed_solid_block_is_rock(tmp_path):
    path = tmp_path / "block.stl"
    trimesh.creation.box((4, 4, 3)).export(path)
    assert mesh_closure(trimesh.load(path).vertices, trimesh.load(path).faces).kind == "solids"
    with pytest.raises(ValueError, match="gives no free space"):
        from_file(path, voxel_size_m=V)


def test_collada_up_axis_and_unit_are_honoured_and_up_axis_overrides(tmp_path):
    # drawn z up, in centimetres; the header says so
    cm = slab_and_wall()
    cm.apply_scale(100.0)
    path = write_collada(cm, tmp_path / "cm.dae", up="Z_UP", unit_m=0.01)
    w = from_file(path, voxel_size_m=V)
    assert (w.source.up_axis, w.source.up_axis_from, w.source.scale, w.source.scale_from) == ("z", "file", 0.01,
                                                                                              "file")
    within_surface_tolerance(w)
    # drawn y up (as the header says): the same world
    path = write_collada(turned(slab_and_wall(), "y"), tmp_path / "y.dae", up="Y_UP")
    assert from_file(path, voxel_size_m=V).free_volume_m3 == pytest.approx(w.free_volume_m3, rel=0.02)
    # no <up_axis> at all: Collada's default, y
    path = write_collada(turned(slab_and_wall(), "y"), tmp_path / "none.dae", up=None)
    assert from_file(path, voxel_size_m=V).source.up_axis == "y"


def test_a_wrong_up_axis_in_the_header_warns_and_names_the_flat_axis(tmp_path):
    # a drift 40 m long along y with a dead end, drawn z up, in a file whose header says Y_UP
    drift = slab_and_wall(length=40.0, dead_end=True)
    drift.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 0, 1]))
    path = write_collada(drift, tmp_path / "drift.dae", up="Y_UP")
    w = from_file(path, voxel_size_m=V)
    assert w.source.up_axis == "y" and (w.bounds_max - w.bounds_min)[2] > 39.0
    [tall] = [x for x in world_warnings(w, survey(w)) if x.key == "up_axis"]
    assert "40 m tall" in tall.message and "<up_axis>Y_UP</up_axis>" in tall.message
    assert "the flattest reading is up_axis: z" in tall.message and "Gazebo" in tall.message
    fixed = from_file(path, voxel_size_m=V, up_axis="z")
    assert not [x for x in world_warnings(fixed, survey(fixed)) if x.key == "up_axis"]
    assert (WIDTH - 2 * V) * (HEIGHT - 2 * V) * 40.0 <= fixed.free_volume_m3 <= WIDTH * HEIGHT * 40.4
    # without the dead end nothing is floored on its side: the error says how it was read
    path = write_collada(slab_and_wall(length=40.0), tmp_path / "open.dae", up="X_UP")
    with pytest.raises(ValueError, match="gives no free space.*read with up axis x from the file's header"):
        from_file(path, voxel_size_m=V)


@pytest.mark.parametrize("suffix", [".npy", ".pcd", ".xyz", ".ply"])
def test_a_corridor_point_cloud(tmp_path, suffix):
    pts = corridor_cloud()
    path = tmp_path / f"corridor{suffix}"
    if suffix == ".npy":
        np.save(path, pts)
    else:
        o3d.io.write_point_cloud(str(path), o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts)))
    w = from_file(path, voxel_size_m=V)
    assert w.source.free_space == "points" and w.source.inflation_m == V
    within_surface_tolerance(w, layers=4)
    assert len(survey(w).significant_regions) == 1


def test_a_point_cloud_seen_from_scan_origins_and_a_trajectory(tmp_path):
    path = tmp_path / "corridor.npy"
    np.save(path, corridor_cloud())
    origins = [[x, 0.0, 1.5] for x in (1.0, 5.0, 9.0)]
    w = from_file(path, voxel_size_m=V, scan_origins=origins)
    assert w.source.free_space == "scans" and w.source.scan_origins == 3
    within_surface_tolerance(w, layers=4)
    # the same origins as a TUM trajectory in the cloud's frame (here turned: y up)
    np.save(path, corridor_cloud() @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]))   # z-up -> y-up
    traj = tmp_path / "poses.txt"
    traj.write_text("# t x y z qx qy qz qw\n" + "".join(f"{i} {x} 1.5 0.0 0 0 0 1\n"
                                                          for i, x in enumerate((1.0, 5.0, 9.0))))
    t = from_file(path, voxel_size_m=V, up_axis="y", trajectory=traj)
    assert t.source.scan_origins == 3
    assert t.free_volume_m3 == pytest.approx(w.free_volume_m3, rel=0.05)
    with pytest.raises(ValueError, match="no scan origin lies in free space"):
        from_file(path, voxel_size_m=V, up_axis="y", scan_origins=[[50.0, 50.0, 50.0]])


def test_a_gazebo_model_folder(tmp_path):
    model = tmp_path / "drift"
    (model / "meshes").mkdir(parents=True)
    write_collada(slab_and_wall(), model / "meshes" / "drift.dae", up="Y_UP")   # Gazebo ignores the header
    (model / "model.sdf").write_text("""<?xml version="1.0"?>
<sdf version="1.6"><model name="drift"><static>true</static>
  <link name="link"><pose>100 0 0 0 0 0</pose>
    <collision name="c"><geometry><mesh><uri>model://drift/meshes/drift.dae</uri><scale>1 1 1</scale></mesh>
    </geometry></collision></link></model></sdf>""")
    w = from_file(model, voxel_size_m=V)
    assert w.source.format == "Gazebo SDF" and w.source.up_axis == "z"
    assert w.bounds_min[0] == pytest.approx(100.0, abs=V)
    within_surface_tolerance(w)


@pytest.mark.parametrize("name, text, message", [
    ("x.las", "", "unknown kind '.las'"),
    ("x.npy", None, "a .npy world is an \\(N, 3\\) array"),
    ("x.xyz", "", "no points in it"),
    ("x.dae", "<COLLADA>", "cannot read Collada file 'x.dae': a broken file, or not a Collada file"),
    ("x.sdf", "<sdf><model>\n  <link name=x>", "cannot read SDF file 'x.sdf': not well-formed XML at line 2, column"),
    ("x.gltf", "not json: root:x:0:0", "cannot read glTF file 'x.gltf': a broken file, or not a glTF file"),
])
def test_unreadable_files_say_so(tmp_path, name, text, message):
    path = tmp_path / name
    if text is None:
        np.save(path, np.zeros((4, 2)))
    else:
        path.write_text(text)
    with pytest.raises(ValueError, match=message) as err:
        from_file(path)
    assert "root:x" not in str(err.value)   # nothing of the file is quoted
