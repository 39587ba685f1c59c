"""The command line: exit status 0 for a successful mission, 1 for a failed one."""
import json

import pytest
from delve.executive.cli import main

from .conftest import DATA


def test_run_exit_status_and_outputs(tmp_path, capsys):
    assert main(["run", str(DATA / "small_tunnel.yaml"), "--out", str(tmp_path / "ok"), "--quiet"]) == 0
    assert json.loads((tmp_path / "ok" / "report.json").read_text())["succeeded"]
    assert main(["run", str(DATA / "small_tunnel.yaml"), "--out", str(tmp_path / "short"), "--quiet",
                 "--duration-s", "20"]) == 1
    report = json.loads((tmp_path / "short" / "report.json").read_text())
    assert not report["succeeded"] and report["sim_time_s"] <= 20.0 + 1e-6
    assert "FAILED" in capsys.readouterr().out


def test_render_writes_each_format(tmp_path):
    tree = DATA.parent.parent.parent / "trees" / "frontier_explorer.yaml"
    for fmt in ("txt", "dot", "svg"):
        out = tmp_path / f"t.{fmt}"
        assert main(["render", str(tree), "--format", fmt, "--out", str(out)]) == 0
        assert out.stat().st_size > 0


def test_render_takes_the_format_from_out_and_never_overwrites_the_tree(tmp_path, capsys):
    tree = DATA.parent.parent.parent / "trees" / "frontier_explorer.yaml"
    assert main(["render", str(tree), "--out", str(tmp_path / "t.svg")]) == 0
    assert b"<svg" in (tmp_path / "t.svg").read_bytes()[:400]
    assert main(["render", str(tree), "--out", str(tmp_path / "u.svg"), "--format", "txt"]) == 2
    assert "has the suffix of svg, not of --format txt" in capsys.readouterr().err
    copy = tmp_path / "tree.txt"
    copy.write_text(tree.read_text())
    assert main(["render", str(copy), "--include-path", str(tree.parent)]) == 2
    assert "would overwrite the tree file itself" in capsys.readouterr().err
    assert copy.read_text() == tree.read_text() and not (tmp_path / "u.svg").exists()


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.startswith("delve ")


def test_validate_prints_the_world_warnings_and_start_errors(tmp_path, capsys):
    from delve import TREES_DIR

    from ..sim.mine_models import slab_and_wall, write_collada

    write_collada(slab_and_wall(dead_end=True), tmp_path / "drift.dae", up="Y_UP")
    text = ("name: drift\nseed: 1\nduration_s: 30\nworld:\n  mesh: drift.dae\n  up_axis: z\n  voxel_size_m: 0.2\n"
            f"robots:\n  - name: anymal\n    platform: legged\n    tree: {TREES_DIR}/frontier_explorer.yaml\n"
            "    start: {start}\n")
    good, bad = tmp_path / "good.yaml", tmp_path / "bad.yaml"
    good.write_text(text.format(start=[2.0, 0.0, 0.5]))
    bad.write_text(text.format(start=[2.0, 2.1, 1.0]))  # in the wall
    assert main(["validate", str(good)]) == 0
    out, err = capsys.readouterr()
    assert out == f"ok: {good}\n"
    assert err.startswith(f"warning: {good}:5: the mesh encloses solids, not passages") and err.count("\n") == 1
    assert main(["validate", str(bad), str(good)]) == 2
    out, err = capsys.readouterr()
    assert out == f"ok: {good}\n"
    assert f"{bad}:12: robot 'anymal': start pose [2.0, 2.1, 1.0] is inside rock (nearest free floor: [" in err


def test_render_formats_are_the_renderer_s():
    from delve.executive.cli import RENDER_FORMATS
    from delve.executive.render import FORMATS

    assert set(RENDER_FORMATS) == set(FORMATS)
