"""delve.executive.render: svg / png / dot / txt dumps of a tree."""
from __future__ import annotations

import shutil
from pathlib import Path

import py_trees
import pytest
from delve.executive.errors import DelveError
from delve.executive.render import render_tree, text_tree
from delve.executive.tree_loader import load_tree
from delve.skills.base import AgentContext

TREES = Path(__file__).resolve().parent.parent / "data" / "trees"


class Clock:
    now_s = 0.0


@pytest.fixture()
def ticked_tree():
    py_trees.blackboard.Blackboard.clear()
    ctx = AgentContext(name="r1", namespace="/r1", clock=Clock(), log=lambda *a, **k: None)
    root = load_tree(TREES / "timed.yaml", ctx)
    root.tick_once()  # Timer and Timeout run
    ctx.clock.now_s = 6.0
    root.tick_once()  # the timeout fires; the selector falls back to the note
    yield root
    py_trees.blackboard.Blackboard.clear()


def test_txt_shows_every_node_with_its_final_status(ticked_tree, tmp_path):
    out = render_tree(ticked_tree, "txt", tmp_path / "tree.txt")
    text = out.read_text(encoding="utf-8")
    assert "\x1b[" not in text
    lines = text.splitlines()
    assert lines[0].startswith("# status:")
    by_name = {name: next(line for line in lines if name in line) for name in
               ("Wait or give up", "Give up after 5 s", "Wait 10 s", "Note timeout")}
    assert "[\u2713]" in by_name["Wait or give up"]
    assert "[\u2715]" in by_name["Give up after 5 s"] and "timed out" in by_name["Give up after 5 s"]
    assert "[-]" in by_name["Wait 10 s"]
    assert "[\u2713]" in by_name["Note timeout"]
    assert text == text_tree(ticked_tree)


def test_dot_is_written_without_graphviz(ticked_tree, tmp_path):
    out = render_tree(ticked_tree, "dot", tmp_path / "sub" / "tree.dot")
    text = out.read_text()
    assert text.lstrip().startswith("digraph") and "Wait 10 s" in text


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz 'dot' is not installed")
@pytest.mark.parametrize("fmt, magic", [("svg", b"<svg"), ("png", b"\x89PNG")])
def test_graph_formats(ticked_tree, tmp_path, fmt, magic):
    out = render_tree(ticked_tree, fmt, tmp_path / f"tree.{fmt}")
    assert magic in out.read_bytes()[:400]


def test_unknown_format(ticked_tree, tmp_path):
    with pytest.raises(DelveError, match="unknown tree dump format 'pdf'"):
        render_tree(ticked_tree, "pdf", tmp_path / "tree.pdf")
