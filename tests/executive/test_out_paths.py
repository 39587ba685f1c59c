"""Output paths are checked before any world is built (issue 15): --out of run and
render, --preview of world; one line naming the path, exit status 2."""
from pathlib import Path

import pytest

from delve import SCENARIOS_DIR, TREES_DIR
from delve.executive import cli
from delve.executive.cli import main

TREE = str(TREES_DIR / "frontier_explorer.yaml")
LONG = "x" * 300


@pytest.fixture
def no_world(monkeypatch):
    """Building a world fails the test: the checks must come first."""
    from delve.executive.scenario import Scenario

    def refuse(*args, **kwargs):
        raise AssertionError("the world was built before the output path was checked")

    monkeypatch.setattr(Scenario, "build_world", refuse)


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("out, expect", [("afile", "--out 'afile' is a file, not a folder"),
                                         ("afile/sub", "--out 'afile/sub' sits under the file 'afile'"),
                                         (LONG, "cannot write there (File name too long)")])
def test_run_out_checked_before_the_world(out, expect, tmp_path, monkeypatch, no_world, capsys):
    monkeypatch.chdir(tmp_path)
    Path("afile").write_text("")
    assert main(["run", str(SCENARIOS_DIR / "demo.yaml"), "--out", out, "--quiet"]) == 2
    assert expect in one_line(capsys)


def test_world_preview_checked_before_the_world(tmp_path, monkeypatch, no_world, capsys):
    monkeypatch.chdir(tmp_path)
    Path("afile").write_text("")
    assert main(["world", "demo", "--preview", "afile/top"]) == 2
    assert "--preview 'afile/top' sits under the file 'afile'" in one_line(capsys)


@pytest.mark.parametrize("out, expect", [("folder", "--out 'folder' is a folder, not a file"),
                                         ("afile/t.txt", "--out 'afile/t.txt' sits under the file 'afile'"),
                                         (LONG + ".txt", "cannot write there (File name too long)")])
def test_render_out_checked(out, expect, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("afile").write_text("")
    Path("folder").mkdir()
    assert main(["render", TREE, "--out", out]) == 2
    assert expect in one_line(capsys)


def test_render_out_in_a_new_folder_is_made(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["render", TREE, "--out", "new/t.txt"]) == 0
    assert Path("new/t.txt").read_text() and list(Path("new").iterdir()) == [Path("new/t.txt")]


def test_out_dir_probe_leaves_nothing(tmp_path):
    cli.check_out_dir(tmp_path / "a" / "b")
    assert list((tmp_path / "a" / "b").iterdir()) == []


@pytest.mark.parametrize("name, folder", [("demo", "demo"), ("../../escaped", "_.._escaped"), ("/tmp/x", "_tmp_x"),
                                          ("..", "run"), ("my run: 2", "my_run_2")])
def test_the_default_out_folder_is_one_folder_in_delve_out_whatever_the_name(name, folder):
    from delve.executive.outpaths import default_out

    assert default_out(name) == Path("delve-out") / folder
