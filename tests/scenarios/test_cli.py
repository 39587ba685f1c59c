"""The command line: exit status 0 for a successful mission, 1 for a failed one."""
import json

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
