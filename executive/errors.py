"""The one exception a user's mistake raises anywhere in the executive.

A :class:`DelveError` names the file, the line and (when known) the node, and prints
as one line, ready for a terminal, with no traceback::

    trees/x.yaml:12: unknown behaviour type 'Explor' (did you mean 'Explore'?)
    trees/x.yaml:30: parameter 'timeout_s' must be >= 0.0, got -3 [node 'Go home']
"""
from __future__ import annotations

import difflib
import os
import re
import warnings
from collections.abc import Iterable
from pathlib import Path

from ..skills.base import short_repr


def display_path(path: str | os.PathLike[str]) -> str:
    """``path`` as a user should read it: relative to the working directory when it
    lies below it, otherwise as given."""
    text = os.fspath(path)
    if os.path.isabs(text):
        try:
            rel = os.path.relpath(text)
        except ValueError:  # another drive on Windows
            return text
        if not rel.startswith(os.pardir):
            return rel
    return text


def clip_message(text: object, limit: int = 160) -> str:
    """Words from elsewhere (a builder's or a reader's exception, which may quote a
    user's value) made fit for one line: whitespace folded, every run of 40 or more
    characters without a space cut to 40, the whole cut to ``limit``."""
    words = re.sub(r"\S{41,}", lambda m: m.group()[:37] + "...", " ".join(str(text).split()))
    return words if len(words) <= limit else words[:limit] + "..."


def did_you_mean(word: str, candidates: Iterable[str]) -> str:
    """`` (did you mean 'X'?)`` for the closest candidate, or an empty string."""
    pool = list(candidates)
    folded = {c.casefold(): c for c in pool}
    if word.casefold() in folded:
        return f" (did you mean {folded[word.casefold()]!r}?)"
    close = difflib.get_close_matches(word, pool, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


class DelveError(Exception):
    """A user's mistake: a message with the file, line and node it concerns.

    Attributes:
        message: what is wrong, without the location
        file: path of the file as given (shown relative to the working directory
            when it lies below it), or None
        line: 1-based line in ``file``, or None
        node: name of the tree node concerned, or None
    """

    def __init__(
        self,
        message: str,
        file: str | os.PathLike[str] | None = None,
        line: int | None = None,
        node: str | None = None,
    ):
        super().__init__(message)
        self.message = message
        self.file = os.fspath(file) if file is not None else None
        self.line = line
        self.node = node

    def __str__(self) -> str:
        where = ""
        if self.file is not None:
            where = display_path(self.file)
            if self.line is not None:
                where += f":{self.line}"
            where += ": "
        suffix = f" [node {short_repr(self.node)}]" if self.node else ""
        return f"{where}{self.message}{suffix}"

    def __reduce__(self):  # keep file/line/node across pickling (multiprocessing)
        return (type(self), (self.message, self.file, self.line, self.node))

    @property
    def path(self) -> Path | None:
        """``file`` as a Path, or None."""
        return Path(self.file) if self.file is not None else None


class DelveDeprecation(UserWarning):
    """A file uses a form that still works but will go; the message names the file,
    the line and what to write instead. Shown every time (each place warns once)."""


warnings.simplefilter("always", DelveDeprecation)


class DelveWarning(UserWarning):
    """A file asks for something that will not happen as written (a supervisor
    command timed after the end of the run, say); the run goes on. The message
    starts with the file and the line of the key at fault; the CLI prints it as one
    ``warning:`` line."""


warnings.simplefilter("always", DelveWarning)
