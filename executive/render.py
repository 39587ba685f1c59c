"""Tree dumps: a behaviour tree as an svg/png/dot graph or a text tree with statuses.

:func:`render_tree` is a pure function of the tree and its arguments (no printing,
no working-directory files); the command line and the mission runner call it.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import py_trees
from py_trees.behaviour import Behaviour

from .errors import DelveError

__all__ = ["FORMATS", "render_tree", "text_tree"]

#: Formats :func:`render_tree` writes, and the pydot format behind each graph one.
FORMATS = {"svg": "svg", "png": "png", "dot": "raw", "txt": None}

_ANSI = re.compile(r"\x1b\[[0-9;]*m")

STATUS_LEGEND = "status: \u2713 SUCCESS  \u2715 FAILURE  * RUNNING  - INVALID (not ticked, or stopped)"


def text_tree(root: Behaviour) -> str:
    """The tree as text (``py_trees.display.unicode_tree`` with ``show_status``): one
    line per node with its status and feedback message, under a legend of the status
    symbols; terminal colour codes are removed."""
    body = py_trees.display.unicode_tree(root, show_status=True)
    return f"# {STATUS_LEGEND}\n{_ANSI.sub('', body)}"


def render_tree(root: Behaviour, fmt: str, out_path: str | os.PathLike[str]) -> Path:
    """Write the tree under ``root`` to ``out_path`` as ``fmt`` and return the path.

    ``fmt`` is ``svg``, ``png`` or ``dot`` (``py_trees.display.dot_tree`` drawn by
    graphviz) or ``txt`` (:func:`text_tree`, showing each node's current status, so a
    dump taken at the end of a run shows the final statuses).

    Raises:
        DelveError: an unknown format, or graphviz's ``dot`` missing for svg/png.
    """
    if fmt not in FORMATS:
        raise DelveError(f"unknown tree dump format {fmt!r} (one of {', '.join(FORMATS)})")
    out = Path(out_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "txt":
        out.write_text(text_tree(root), encoding="utf-8")
        return out
    graph = py_trees.display.dot_tree(root)
    try:
        graph.write(str(out), format=FORMATS[fmt])
    except FileNotFoundError as err:
        raise DelveError(
            f"cannot write {fmt}: graphviz's 'dot' program is not installed ({err})", out
        ) from None
    return out
