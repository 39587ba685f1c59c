"""YAML reading that remembers where everything came from.

:func:`load_yaml` parses a file with a :class:`yaml.SafeLoader` subclass whose mappings
and sequences are :class:`YamlDict` / :class:`YamlList`: plain ``dict`` / ``list``
subclasses that also know their ``file``, their 1-based ``line``, the line of each key
(:meth:`YamlDict.key_line`) and of each item (:meth:`YamlList.item_line`), so that any
later check can raise a :class:`~delve.executive.errors.DelveError` that points at the
offending line. Syntax errors, missing files and duplicate keys are DelveErrors too.

The tree loader and the scenario loader both read YAML through this module.
"""
from __future__ import annotations

import os
from typing import Any

import yaml

from .errors import DelveError

__all__ = ["YamlDict", "YamlList", "line_of", "load_yaml", "loads_yaml", "plain"]


class YamlDict(dict):
    """A mapping read from YAML: a dict that knows its file and lines."""

    file: str | None
    line: int | None

    def __init__(self, *args: Any, file: str | None = None, line: int | None = None, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.file = file
        self.line = line
        self._key_lines: dict[Any, int] = {}

    def key_line(self, key: Any) -> int | None:
        """1-based line of ``key`` (falls back to the mapping's own line)."""
        return self._key_lines.get(key, self.line)


class YamlList(list):
    """A sequence read from YAML: a list that knows its file and lines."""

    file: str | None
    line: int | None

    def __init__(self, *args: Any, file: str | None = None, line: int | None = None):
        super().__init__(*args)
        self.file = file
        self.line = line
        self._item_lines: list[int] = []

    def item_line(self, index: int) -> int | None:
        """1-based line of item ``index`` (falls back to the sequence's own line)."""
        if 0 <= index < len(self._item_lines):
            return self._item_lines[index]
        return self.line


def line_of(value: Any, default: int | None = None) -> int | None:
    """Line of a YamlDict/YamlList, ``default`` for anything else."""
    line = getattr(value, "line", None)
    return line if isinstance(line, int) else default


def plain(value: Any) -> Any:
    """A deep copy of ``value`` made of plain dicts and lists (no line bookkeeping)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain(v) for v in value]
    return value


_MERGE_TAG = "tag:yaml.org,2002:merge"


class LineLoader(yaml.SafeLoader):
    """SafeLoader whose mappings and sequences remember file and line, and which
    rejects duplicate keys."""

    def __init__(self, stream: Any, file: str | None = None):
        super().__init__(stream)
        self.file = file

    def construct_located_mapping(self, node: yaml.MappingNode):
        data = YamlDict(file=self.file, line=node.start_mark.line + 1)
        yield data
        if not isinstance(node, yaml.MappingNode):
            raise yaml.constructor.ConstructorError(
                None, None, f"expected a mapping node, but found {node.id}", node.start_mark
            )
        explicit = [pair for pair in node.value if pair[0].tag != _MERGE_TAG]
        self.flatten_mapping(node)  # resolves '<<' merges; merged pairs come first
        n_merged = len(node.value) - len(explicit)
        seen: set[Any] = set()
        for index, (key_node, value_node) in enumerate(node.value):
            key = self.construct_object(key_node, deep=True)
            try:
                hash(key)
            except TypeError:
                raise DelveError(
                    f"unhashable mapping key {key!r}", self.file, key_node.start_mark.line + 1
                ) from None
            line = key_node.start_mark.line + 1
            if index >= n_merged:
                if key in seen:
                    raise DelveError(f"duplicate key {key!r} in mapping", self.file, line)
                seen.add(key)
            data[key] = self.construct_object(value_node, deep=False)
            data._key_lines[key] = line

    def construct_located_sequence(self, node: yaml.SequenceNode):
        data = YamlList(file=self.file, line=node.start_mark.line + 1)
        yield data
        data.extend(self.construct_object(child, deep=False) for child in node.value)
        data._item_lines = [child.start_mark.line + 1 for child in node.value]


LineLoader.add_constructor("tag:yaml.org,2002:map", LineLoader.construct_located_mapping)
LineLoader.add_constructor("tag:yaml.org,2002:seq", LineLoader.construct_located_sequence)


def _syntax_error(err: yaml.YAMLError, file: str | None) -> DelveError:
    problem_mark = getattr(err, "problem_mark", None)
    context_mark = getattr(err, "context_mark", None)
    mark = problem_mark or context_mark
    line = mark.line + 1 if mark is not None else None
    problem = getattr(err, "problem", None) or str(err)
    context = getattr(err, "context", None)
    text = f"YAML syntax error: {problem}"
    if context:
        text += f" ({context}"
        if context_mark is not None and context_mark.line + 1 != line:
            text += f" that starts on line {context_mark.line + 1}"
        text += ")"
    return DelveError(text, file, line)


def loads_yaml(text: str, file: str | None = None) -> Any:
    """Parse YAML ``text``; ``file`` is only used for locations in errors."""
    loader = LineLoader(text, file=file)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as err:
        raise _syntax_error(err, file) from None
    finally:
        loader.dispose()


def load_yaml(path: str | os.PathLike[str]) -> Any:
    """Read the YAML file at ``path``. Mappings and lists in the result are
    :class:`YamlDict` / :class:`YamlList` that know their file (``path`` as given)
    and lines.

    Raises:
        DelveError: the file is missing or unreadable, is not valid YAML, or has a
            mapping with a duplicate key.
    """
    file = os.fspath(path)
    try:
        with open(file, encoding="utf-8") as stream:
            text = stream.read()
    except FileNotFoundError:
        raise DelveError("file not found", file) from None
    except IsADirectoryError:
        raise DelveError("is a directory, not a YAML file", file) from None
    except UnicodeDecodeError as err:
        raise DelveError(f"not a UTF-8 text file ({err.reason})", file) from None
    except OSError as err:
        raise DelveError(f"cannot read file: {err.strerror}", file) from None
    return loads_yaml(text, file=file)
