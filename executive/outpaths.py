"""Output paths checked before any work: ``delve run --out DIR``, ``delve world
--preview DIR`` and ``delve render --out FILE``.

A path that is a file where a folder is wanted (or a folder where a file is), that
sits under a file, or that cannot be written is one line naming it, exit status 2,
before a world is built or a simulation runs, never after a run has finished.
"""
from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path

from ..skills.base import short_repr
from .errors import DelveError

#: How much of an output path a message quotes.
_SHOWN_CHARS = 100


def _shown(path: Path) -> str:
    return short_repr(str(path), _SHOWN_CHARS)


def _under_a_file(path: Path) -> Path | None:
    """The nearest ancestor of ``path`` that exists and is no folder, or None."""
    for parent in path.parents:
        if parent.exists() or parent.is_symlink():
            return None if parent.is_dir() else parent
    return None


def _reason(err: OSError) -> str:
    return err.strerror or type(err).__name__


def check_out_dir(path: Path, option: str = "--out") -> None:
    """Make the folder ``path`` (and its parents) and write and remove a probe file
    in it; a DelveError naming ``option`` and the path when that cannot be done."""
    try:
        _check_out_dir(path, option)
    except OSError as err:
        raise DelveError(f"{option} {_shown(path)}: cannot write there ({_reason(err)})") from None


def check_out_file(path: Path, option: str = "--out") -> None:
    """Make the folder of the file ``path`` and check that the file can be written
    there (made and removed, or opened for appending when it exists); a DelveError naming ``option`` and the path when it cannot."""
    try:
        _check_out_file(path, option)
    except OSError as err:
        raise DelveError(f"{option} {_shown(path)}: cannot write there ({_reason(err)})") from None


def _check_out_dir(path: Path, option: str) -> None:
    if "\0" in str(path):
        raise DelveError(f"{option} {_shown(path)}: a path cannot hold a NUL byte")
    if path.exists() and not path.is_dir():
        raise DelveError(f"{option} {_shown(path)} is a file, not a folder")
    blocker = _under_a_file(path)
    if blocker is not None:
        raise DelveError(f"{option} {_shown(path)} sits under the file {_shown(blocker)}")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".delve-probe-"):
            pass
    except OSError as err:
        raise DelveError(f"{option} {_shown(path)}: cannot write there ({_reason(err)})") from None


def _check_out_file(path: Path, option: str) -> None:
    if "\0" in str(path):
        raise DelveError(f"{option} {_shown(path)}: a path cannot hold a NUL byte")
    if path.is_dir():
        raise DelveError(f"{option} {_shown(path)} is a folder, not a file")
    blocker = _under_a_file(path)
    if blocker is not None:
        raise DelveError(f"{option} {_shown(path)} sits under the file {_shown(blocker)}")
    folder = path.parent if str(path.parent) else Path(".")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if path.exists():
            if not os.access(path, os.W_OK):
                raise PermissionError(13, "Permission denied")
            with open(path, "ab"):
                pass
        else:  # the file itself, made and removed: its name may be what fails
            with open(path, "xb"):
                pass
            path.unlink()
    except OSError as err:
        raise DelveError(f"{option} {_shown(path)}: cannot write there ({_reason(err)})") from None


def default_out(name: str) -> Path:
    """``delve-out/<name>``, the output folder when none is given, with the name made one
    plain folder name: a scenario's or sweep's ``name:`` of ``../../x`` or ``/tmp/x``
    must not put the outputs elsewhere."""
    folder = re.sub(r"[^A-Za-z0-9_.-]+", "_", name).lstrip(".") or "run"
    return Path("delve-out") / folder
