"""delve.executive.render: svg / png / dot / txt dumps of a tree."""
from __future__ import annotations

import shutil
from pathlib import Path

import py_trees
import pydot
import pytest
from py_trees.common import Status
from delve.executive.errors import DelveError
from delve.executive.render import dot_graph, render_tree, text_tree
from delve.executive.tree_loader import load_tree
from delve.skills.base import AgentContext

TREES = Path(__file__).resolve().parent.parent / "data" / "trees"


class Clock:
    now_s = 0.0


@pytest.fixture(autouse=True)
def blackboard(clean_blackboard):
    """Every test here starts and ends with an empty blackboard."""


def timed_tree(ticks_at_s: tuple[float, ...]) -> py_trees.behaviour.Behaviour:
    """tests/data/trees/timed.yaml ticked at the sim times ``ticks_at_s``."""
    ctx = AgentContext(name="r1", namespace="/r1", clock=Clock(), log=lambda *a, **k: None)
    root = load_tree(TREES / "timed.yaml", ctx)
    for t in ticks_at_s:
        ctx.clock.now_s = t
        root.tick_once()
    return root


@pytest.fixture()
def ticked_tree():
    return timed_tree((0.0, 6.0))   # Timer and Timeout run; then the timeout fires, the note is set


@pytest.fixture()
def running_tree():
    return timed_tree((0.0,))   # Timer and Timeout run


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


def line_of(text: str, name: str) -> str:
    return next(line for line in text.splitlines() if name in line)


def test_a_stopped_tree_is_dumped_with_the_statuses_it_had(running_tree):
    before = {n.id: n.status for n in running_tree.iterate()}
    running_tree.stop(Status.INVALID)
    text = text_tree(running_tree, before)
    assert "[*]" in line_of(text, "Wait 10 s") and "[*]" in line_of(text, "Wait or give up")
    assert "[-]" in line_of(text_tree(running_tree), "Wait 10 s")
    assert all(n.status == Status.INVALID for n in running_tree.iterate())   # its own statuses are back


def test_the_graph_colours_each_ticked_node_by_its_status(running_tree, ticked_tree):
    def border(graph, name):
        (node,) = graph.get_node(name)
        return node.get("color")

    running = dot_graph(running_tree)
    assert border(running, "Wait 10 s") == "blue" and "RUNNING" in running.get("label")
    assert border(running, "Note timeout") is None   # not ticked
    ticked = dot_graph(ticked_tree)
    assert border(ticked, "Give up after 5 s") == "red3" and border(ticked, "Note timeout") == "forestgreen"
    before = {n.id: n.status for n in running_tree.iterate()}
    running_tree.stop(Status.INVALID)
    assert border(dot_graph(running_tree, before), "Wait 10 s") == "blue"
    stopped = dot_graph(running_tree)
    assert border(stopped, "Wait 10 s") is None and stopped.get("label") is None


def test_nodes_of_one_name_are_labelled_by_it_not_by_their_unique_graph_names():
    root = py_trees.composites.Sequence("Root", memory=True, children=[
        py_trees.behaviours.Success("Explore from here"), py_trees.behaviours.Success("Explore from here")])
    graph = dot_graph(root)
    labels = [n.get("label") for n in graph.get_nodes() if n.get_name().strip('"').startswith("Explore from here")]
    assert len(labels) == 2 and all(label.strip('"') == "Explore from here" for label in labels)


def test_dot_is_written_without_graphviz(ticked_tree, tmp_path):
    out = render_tree(ticked_tree, "dot", tmp_path / "sub" / "tree.dot")
    text = out.read_text()
    assert text.lstrip().startswith("digraph") and "Wait 10 s" in text


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz 'dot' is not installed")
@pytest.mark.parametrize("fmt, magic", [("svg", b"<svg"), ("png", b"\x89PNG")])
def test_graph_formats(ticked_tree, tmp_path, fmt, magic):
    out = render_tree(ticked_tree, fmt, tmp_path / f"tree.{fmt}")
    assert magic in out.read_bytes()[:400]


@pytest.mark.parametrize("fmt, mark", [("png", "M Steps"), ("svg", "\u24c2 Steps"), ("dot", "\u24c2 Steps")])
def test_a_png_marks_memory_in_ascii_the_other_formats_as_py_trees_does(tmp_path, monkeypatch, fmt, mark):
    """graphviz draws a PNG with the machine's fonts, which often lack py_trees' Ⓜ."""
    drawn = {}
    monkeypatch.setattr(pydot.Dot, "write", lambda graph, path, format: drawn.setdefault("label", graph.get_node(
        "Steps")[0].get("label")))
    steps = py_trees.composites.Sequence("Steps", memory=True, children=[py_trees.behaviours.Success("Step")])
    render_tree(steps, fmt, tmp_path / f"t.{fmt}")
    assert drawn["label"].strip('"').startswith(mark)


def test_unknown_format(ticked_tree, tmp_path):
    with pytest.raises(DelveError, match="unknown tree dump format 'pdf'"):
        render_tree(ticked_tree, "pdf", tmp_path / "tree.pdf")
