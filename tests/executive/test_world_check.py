"""A world looked at before a run: the voxel backend's description and starts, and
`delve world` / the first lines of `delve run`, on a small Collada slab-and-wall
corridor whose header says Y_UP while it is drawn z up (as Gazebo models often are)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh

from delve import SCENARIOS_DIR, TREES_DIR
from delve.executive.cli import main
from delve.executive.errors import DelveError
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario
from delve.executive.worlds import GraphBackend, VoxelBackend

from ..sim.mine_models import HEIGHT, LENGTH, WIDTH, slab_and_wall, write_collada

SCENARIO = """name: drift
seed: 1
duration_s: 30
world:
  mesh: {mesh}
{up}  voxel_size_m: 0.2
robots:
  - name: anymal
    platform: legged
    tree: {trees}/frontier_explorer.yaml
    start: {start}
  - name: obelix
    platform: aerial
    tree: {trees}/aerial_explorer.yaml
"""


def scenario(tmp_path: Path, start=(2.0, 0.0, 0.5), up: str | None = "z", mesh: str = "drift.dae") -> Path:
    """A scenario on the corridor; its world key is on line 4, the mesh on line 5,
    up_axis (when given) on line 6, the first robot's start on line 12 (11 without up_axis)."""
    if not (tmp_path / "drift.dae").exists():
        write_collada(slab_and_wall(dead_end=True), tmp_path / "drift.dae", up="Y_UP")
    path = tmp_path / "drift.yaml"
    path.write_text(SCENARIO.format(mesh=mesh, up=f"  up_axis: {up}\n" if up else "", trees=TREES_DIR,
                                    start=list(start)))
    return path


def test_a_legged_start_above_the_floor_lands_on_it_and_the_report_says_where(tmp_path):
    sc = load_scenario(scenario(tmp_path))
    mission = Mission(sc)
    start = mission.backend.starts["anymal"]
    assert start[:2].tolist() == [2.0, 0.0] and 0.0 <= start[2] <= 0.2
    assert mission.robots["anymal"].position[2] == pytest.approx(start[2] + 0.5)
    figures = mission.backend.robot_figures("anymal", {})
    assert figures == {"start": [2.0, 0.0, round(float(start[2]), 3)], "moving_s": 0.0}
    assert "start" in mission.backend.robot_figures("obelix", {})


def test_the_description_names_the_world_and_each_start(tmp_path):
    sc = load_scenario(scenario(tmp_path))
    world = sc.build_world()
    d = VoxelBackend.describe(sc, world)
    text = "\n".join(d.lines)
    assert text.startswith("world drift: drift.dae (Collada), up axis z from the scenario, scale 1 by default\n"
                           "  built     a mesh of closed solids: rock where its surface passes, a ceiling at "
                           "z = 3.0 m (the model top), free space the floored regions below")
    assert "  free      " in text and "1 region(s), the largest 100% of the free volume" in text
    assert "anymal (legged): on the floor at [2, 0, 0." in text and "moved 0." in text
    assert "obelix (aerial): at [" in text and "near the world's start" in text
    assert not d.errors and set(d.starts) == {"anymal", "obelix"}
    assert d.warnings == [f"{sc.path}:5: the mesh encloses solids, not passages (its faces turn outwards, as a "
                          f"Gazebo model of boxes): free space was built from its surface: rock where it passes, "
                          f"a ceiling at the model top, z = {HEIGHT:.1f} m, the floored regions under it"]
    lo = (WIDTH - 0.4) * (HEIGHT - 0.4) * LENGTH
    assert lo <= world.free_volume_m3 <= WIDTH * HEIGHT * LENGTH


def test_a_start_in_rock_is_an_error_with_file_line_and_the_nearest_free_floor(tmp_path):
    sc = load_scenario(scenario(tmp_path, start=(2.0, 2.1, 1.0)))         # in the wall
    with pytest.raises(DelveError) as err:
        Mission(sc)
    assert str(err.value).startswith(f"{sc.path}:12: robot 'anymal': start pose [2.0, 2.1, 1.0] is inside rock "
                                     f"(nearest free floor: [")
    d = VoxelBackend.describe(sc, sc.build_world())
    [error] = d.errors
    assert error.line == 12 and "inside rock (nearest free floor: [" in error.message


def test_delve_world_prints_the_world_and_draws_it(tmp_path, capsys):
    path = scenario(tmp_path)
    assert main(["world", str(path), "--preview", str(tmp_path / "look")]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("world drift: drift.dae (Collada)")
    assert f"wrote {tmp_path / 'look' / 'top.png'}\nwrote {tmp_path / 'look' / 'side.png'}" in out
    assert (tmp_path / "look" / "top.png").stat().st_size > 10_000
    assert err.count("\n") == 1 and err.startswith("warning: ") and "encloses solids" in err


def test_the_description_names_the_seed_the_world_was_made_with(tmp_path, capsys):
    path = tmp_path / "gen.yaml"
    path.write_text("name: gen\nseed: 7\nduration_s: 10\nworld: {generator: tunnel_network, total_length_m: 60, loops: 0}\n"
                    f"robots:\n  - {{name: anymal, platform: legged, tree: {TREES_DIR}/frontier_explorer.yaml}}\n")
    assert main(["world", str(path)]) == 0
    assert capsys.readouterr().out.startswith("world gen: generator tunnel_network (seed 7, total_length_m 60, loops 0)")
    assert main(["world", str(path), "--seed", "5"]) == 0
    assert capsys.readouterr().out.startswith("world gen: generator tunnel_network (seed 5, total_length_m 60, loops 0)")


def test_delve_world_warns_about_the_header_s_up_axis(tmp_path, capsys):
    # the drift runs along y, 20 m: read y up, it stands 20 m tall
    drift = slab_and_wall(length=20.0, dead_end=True)
    drift.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 0, 1]))
    write_collada(drift, tmp_path / "standing.dae", up="Y_UP")
    path = scenario(tmp_path, start=(0.5, 2.0, 5.0), up=None, mesh="standing.dae")
    assert main(["world", str(path)]) == 2
    out, err = capsys.readouterr()
    assert "up axis y from the file's header" in out
    lines = err.splitlines()
    assert lines[0].startswith(f"warning: {path}:5: the world is 20 m tall but ")
    assert "<up_axis>Y_UP</up_axis>" in lines[0] and "the flattest reading is up_axis: z" in lines[0]
    assert lines[-1].startswith(f"{path}:11: robot 'anymal': start pose [0.5, 2.0, 5.0] is ")


def test_delve_run_prints_the_summary_first_and_quiet_keeps_only_warnings(tmp_path, capsys):
    path = scenario(tmp_path)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--duration-s", "2", "--quiet"]) in (0, 1)
    out, err = capsys.readouterr()
    assert not out.startswith("world ") and "encloses solids" in err
    main(["run", str(path), "--out", str(tmp_path / "out"), "--duration-s", "2"])
    out, _ = capsys.readouterr()
    assert out.startswith("world drift: drift.dae (Collada)")
    bad = scenario(tmp_path, start=(2.0, 2.1, 1.0))
    assert main(["run", str(bad), "--out", str(tmp_path / "bad"), "--quiet"]) == 2
    _, err = capsys.readouterr()
    assert "inside rock (nearest free floor" in err and not (tmp_path / "bad" / "report.json").exists()


def test_a_graph_world_describes_itself_too():
    sc = load_scenario(SCENARIOS_DIR / "cops_tunnel.yaml")
    d = GraphBackend.describe(sc, sc.build_world())
    assert d.lines[0].startswith("world cops_tunnel: a graph of ")
    assert "r1 (legged): at location 's0'" in "\n".join(d.lines)
    assert not d.errors and not d.warnings
    with pytest.raises(DelveError, match="draws no preview"):
        GraphBackend.preview(sc, sc.build_world(), Path("unused"))


def test_a_default_aerial_start_keeps_its_radius_and_a_voxel_from_rock(tmp_path):
    """Seed 1 of this mine has rock 0.65 m from the second default start (1.2 m along x):
    an aerial robot hovering there found rock inside its box on its own map and never
    planned; it now takes the next default start that is clear. A legged robot keeps
    the second one."""
    from delve.executive.worlds.voxel_check import place_starts
    from delve.sim.start_landing import clearance_m

    def starts(platform: str) -> tuple[Any, list[np.ndarray]]:
        path = tmp_path / f"{platform}.yaml"
        robots = "".join(f"  - {{name: r{i}, platform: {platform}, tree: {TREES_DIR / 'frontier_explorer.yaml'}}}\n"
                         for i in (1, 2))
        path.write_text("name: s\nseed: 1\nworld: {generator: tunnel_network, total_length_m: 120, loops: 1, "
                        f"voxel_size_m: 0.4}}\nrobots:\n{robots}")
        scenario = load_scenario(path)
        world = scenario.build_world()
        placed = place_starts(scenario, world)
        assert all(p.error is None and not p.landing.warnings for p in placed)
        return world, [p.landing.start for p in placed]

    world, aerial = starts("aerial")
    second = np.asarray(world.start) + [1.2, 0.0, 0.0]
    assert clearance_m(world, second + [0.0, 0.0, 1.0], 2.0) < 0.8
    assert not np.allclose(aerial[1], second) and not np.allclose(aerial[1], aerial[0])
    assert clearance_m(world, aerial[1] + [0.0, 0.0, 1.0], 2.0) >= 0.8
    _, legged = starts("legged")
    np.testing.assert_allclose(legged[1][:2], second[:2])


def test_a_default_start_is_never_where_a_robot_was_given_its_start(tmp_path):
    from delve.executive.worlds.voxel_check import place_starts

    path = tmp_path / "s.yaml"
    tree = TREES_DIR / "frontier_explorer.yaml"
    path.write_text("name: s\nseed: 1\nworld: {generator: tunnel_network, total_length_m: 120, loops: 1}\n"
                    "robots:\n"
                    f"  - {{name: a, platform: legged, tree: {tree}, start: [1.2, 0.0, 0.0]}}\n"
                    f"  - {{name: b, platform: legged, tree: {tree}}}\n")
    scenario = load_scenario(path)
    world = scenario.build_world()
    a, b = (p.landing.start for p in place_starts(scenario, world))
    assert np.hypot(*(a - b)[:2]) >= 1.0   # b's own place (1.2 m along x) is a's start: it takes the next
