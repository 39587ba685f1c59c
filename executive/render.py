"""Tree dumps: a behaviour tree as an svg/png/dot graph or a text tree with statuses.

:func:`render_tree` is a pure function of the tree and its arguments (no printing,
no working-directory files); the command line and the mission runner call it.
"""
from __future__ import annotations

import os
import re
import uuid
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

import pydot
import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status, VisibilityLevel

from .errors import DelveError

__all__ = ["FORMATS", "dot_graph", "render_tree", "text_tree"]

#: Formats :func:`render_tree` writes, and the pydot format behind each graph one.
FORMATS = {"svg": "svg", "png": "png", "dot": "raw", "txt": None}

_ANSI = re.compile(r"\x1b\[[0-9;]*m")

STATUS_LEGEND = "status: \u2713 SUCCESS  \u2715 FAILURE  * RUNNING  - INVALID (not ticked, or stopped)"
#: The border of a node in a graph dump, by status (INVALID: py_trees' own).
STATUS_COLOURS = {Status.SUCCESS: "forestgreen", Status.FAILURE: "red3", Status.RUNNING: "blue"}
GRAPH_LEGEND = "border: green SUCCESS, red FAILURE, blue RUNNING, thin INVALID (not ticked, or stopped)"

Statuses = Mapping[uuid.UUID, Status]


@contextmanager
def _showing(root: Behaviour, statuses: Statuses | None) -> Iterator[None]:
    """Give the nodes the ``statuses`` (by node id) while py_trees' display reads them
    (a stopped tree's are all INVALID), then put their own back."""
    nodes = list(root.iterate()) if statuses else []
    own = [n.status for n in nodes]
    for n in nodes:
        n.status = statuses.get(n.id, n.status)  # type: ignore[union-attr]
    try:
        yield
    finally:
        for n, status in zip(nodes, own):
            n.status = status


def text_tree(root: Behaviour, statuses: Statuses | None = None) -> str:
    """The tree as text (``py_trees.display.unicode_tree`` with ``show_status``): one
    line per node with its status (or the one ``statuses`` gives) and feedback message,
    under a legend of the status symbols; terminal colour codes are removed."""
    with _showing(root, statuses):
        body = py_trees.display.unicode_tree(root, show_status=True)
    return f"# {STATUS_LEGEND}\n{_ANSI.sub('', body)}"


def _shown_children(node: Behaviour) -> list[Behaviour]:
    """The children ``py_trees.display.dot_tree`` draws at its default visibility."""
    return node.children if VisibilityLevel.DETAIL < node.blackbox_level else []


def _dot_names(root: Behaviour) -> Iterator[tuple[Behaviour, str]]:
    """Each node ``py_trees.display.dot_tree`` draws and its name in the graph: the node's
    name with ``*`` added until it is unique, depth first (dot_tree's own naming, which
    it does not return)."""
    names: set[str] = {root.name}
    yield root, root.name
    stack = [iter(_shown_children(root))]
    while stack:
        child = next(stack[-1], None)
        if child is None:
            stack.pop()
            continue
        name = child.name
        while name in names:
            name += "*"
        names.add(name)
        yield child, name
        stack.append(iter(_shown_children(child)))


def dot_graph(root: Behaviour, statuses: Statuses | None = None) -> pydot.Dot:
    """``py_trees.display.dot_tree`` of the tree, each ticked node's border coloured by
    its status (or the one ``statuses`` gives), with a legend. A node whose name another
    has too is labelled by its own name (dot_tree labels it by its unique graph name, the
    name with ``*`` added)."""
    graph = py_trees.display.dot_tree(root)
    ticked = False
    with _showing(root, statuses):
        for node, name in _dot_names(root):
            colour = STATUS_COLOURS.get(node.status)
            # pydot's own name for it (a ':' starts a port); 'node', 'graph' and 'edge' name
            # the graph's defaults there, not a node.
            found = [] if name in ("node", "graph", "edge") else graph.get_node(pydot.Node(name).get_name())
            label = found[0].get("label") if found else None
            if name != node.name and isinstance(label, str):
                found[0].set("label", label.replace(name, node.name, 1))
            if colour and found:
                found[0].set("color", colour)
                found[0].set("penwidth", "3")
                ticked = True
    if ticked:
        graph.set("label", GRAPH_LEGEND)
        graph.set("labelloc", "t")
        graph.set("fontsize", "10")
    return graph


def _ascii_memory_mark(graph: pydot.Dot) -> None:
    """Label composites with memory by py_trees' ASCII mark ("M") instead of its Ⓜ
    (U+24C2): graphviz draws a PNG with the machine's fonts, which often lack it (DejaVu
    has none) and show a box there; an SVG is drawn with the viewer's fonts."""
    memory = py_trees.display.unicode_symbols["memory"]
    for node in graph.get_nodes():
        label = node.get("label")
        if isinstance(label, str) and memory in label:
            node.set("label", label.replace(memory, py_trees.display.ascii_symbols["memory"]))


def render_tree(root: Behaviour, fmt: str, out_path: str | os.PathLike[str],
                statuses: Statuses | None = None) -> Path:
    """Write the tree under ``root`` to ``out_path`` as ``fmt`` and return the path.

    ``fmt`` is ``svg``, ``png`` or ``dot`` (:func:`dot_graph` drawn by graphviz) or
    ``txt`` (:func:`text_tree`). Both show each node's current status, or the one
    ``statuses`` gives (by node id: a stopped tree's statuses of before), so a dump taken
    at the end of a run shows the final statuses.

    Raises:
        DelveError: an unknown format, or graphviz's ``dot`` missing for svg/png.
    """
    if fmt not in FORMATS:
        raise DelveError(f"unknown tree dump format {fmt!r} (one of {', '.join(FORMATS)})")
    out = Path(out_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "txt":
        out.write_text(text_tree(root, statuses), encoding="utf-8")
        return out
    graph = dot_graph(root, statuses)
    if fmt == "png":
        _ascii_memory_mark(graph)
    try:
        graph.write(str(out), format=FORMATS[fmt])
    except FileNotFoundError as err:
        raise DelveError(
            f"cannot write {fmt}: graphviz's 'dot' program is not installed ({err})", out
        ) from None
    return out
