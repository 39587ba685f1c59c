"""YAML reading that remembers where everything came from.

:func:`load_yaml` parses a file with a :class:`yaml.SafeLoader` subclass whose mappings
and sequences are :class:`YamlDict` / :class:`YamlList`: plain ``dict`` / ``list``
subclasses that also know their ``file``, their 1-based ``line``, the line of each key
(:meth:`YamlDict.key_line`) and of each item (:meth:`YamlList.item_line`), so that any
later check can raise a :class:`~delve.executive.errors.DelveError` that points at the
offending line. Syntax errors, missing files and duplicate keys are DelveErrors too.

Hostile files get one line too, never a traceback or a hang, and no error quotes more
of a file than the offending value's first few dozen characters. The reader refuses:
files above :data:`MAX_FILE_BYTES`; text that is not UTF-8 (naming the encoding a
byte-order mark or NUL bytes tell, and the line where decoding failed); control
characters and NUL bytes; nesting deeper than :data:`MAX_NESTING_DEPTH`; documents
that expand to more than :data:`MAX_NODES` values, aliases counted at each use (alias
"bombs"); recursive aliases (``&a [1, *a]``); integers of thousands of digits.

The tree loader and the scenario loader both read YAML through this module.
"""
from __future__ import annotations

import codecs
import os
import re
import stat
from typing import Any

import yaml

from ..skills.base import short_repr
from .errors import DelveError

__all__ = ["MAX_FILE_BYTES", "MAX_NESTING_DEPTH", "MAX_NODES", "YamlDict", "YamlList", "decode", "line_of",
           "file_problem", "line_of_key_named", "load_yaml", "loads_yaml", "plain"]

#: Largest YAML file read, in bytes. The shipped trees and scenarios are under 4 kB;
#: the pure-Python parser reads about 100 kB a second on a busy machine.
MAX_FILE_BYTES = 1_000_000
#: Deepest nesting of mappings and lists in one file (the shipped files nest 16 deep).
MAX_NESTING_DEPTH = 100
#: Most values (mappings, lists, scalars) one file may expand to, an alias counted
#: with everything it stands for at each use (the shipped files have under 400).
MAX_NODES = 50_000
#: What YAML allows in a stream: tab, line breaks and printable characters (PyYAML's
#: reader set); anything else is reported with its line before parsing.
_NON_PRINTABLE = re.compile("[^\x09\x0A\x0D\x20-\x7E\x85\xA0-\uD7FF\uE000-\uFFFD\U00010000-\U0010FFFF]")
_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32 (little-endian)"), (codecs.BOM_UTF32_BE, "UTF-32 (big-endian)"),
         (codecs.BOM_UTF16_LE, "UTF-16 (little-endian)"), (codecs.BOM_UTF16_BE, "UTF-16 (big-endian)"))


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


def line_of_key_named(data: Any, text: str) -> int | None:
    """Line of the key of the mapping ``data``, or of a mapping inside it (the deepest
    first), that the message ``text`` names: a check made after reading (a world
    generator's, a planner's) then points at the key at fault, not at the mapping.
    None when ``text`` names no key."""
    words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", text))
    best: tuple[int, int | None] | None = None
    stack = [(data, 0)]
    while stack:
        mapping, depth = stack.pop()
        if not isinstance(mapping, YamlDict):
            continue
        for key, value in mapping.items():
            if isinstance(key, str) and key in words and key not in ("type", "name"):
                if best is None or depth > best[0]:
                    best = (depth, mapping.key_line(key))
            if isinstance(value, YamlDict):
                stack.append((value, depth + 1))
    return best[1] if best else None


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
        self._depth = 0
        self._nodes = 0
        self._aliased = False
        self._open: set[int] = set()  # id() of the start marks of collections being composed
        self._sizes: dict[int, int] = {}  # id(anchored node) -> values it stands for

    # Composing (events -> nodes) is where depth and aliases are checked: before the
    # recursive composer overflows the stack, and before any alias is expanded.
    def _count(self, n: int, mark: yaml.Mark, alias: bool = False) -> None:
        self._nodes += n
        self._aliased = self._aliased or alias
        if self._nodes > MAX_NODES:
            what = (f"aliases expand the document to more than {MAX_NODES} values (an alias bomb?)" if self._aliased
                    else f"the document holds more than {MAX_NODES} values: too many for a tree or scenario")
            raise DelveError(what, self.file, mark.line + 1)

    def compose_node(self, parent: Any, index: Any) -> yaml.Node:
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = self.anchors.get(event.anchor)
            if node is not None:
                if id(node.start_mark) in self._open:
                    raise DelveError(f"recursive alias *{short_repr(event.anchor)[1:-1]}: the anchor contains "
                                     "its own alias", self.file, event.start_mark.line + 1)
                self._count(self._sizes.get(id(node), 1), event.start_mark, alias=True)
            return super().compose_node(parent, index)
        before = self._nodes
        self._count(1, event.start_mark)
        if isinstance(event, yaml.ScalarEvent):
            node = super().compose_node(parent, index)
        else:
            if self._depth >= MAX_NESTING_DEPTH:
                raise DelveError(f"mappings and lists nest more than {MAX_NESTING_DEPTH} deep", self.file,
                                 event.start_mark.line + 1)
            self._depth += 1
            self._open.add(id(event.start_mark))
            try:
                node = super().compose_node(parent, index)
            finally:
                self._open.discard(id(event.start_mark))
                self._depth -= 1
        if getattr(event, "anchor", None) is not None:
            self._sizes[id(node)] = self._nodes - before
        return node

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except (ValueError, TypeError, OverflowError) as err:  # !!float abc, !!timestamp 2001-13-45, ...
            if "digits" in str(err):  # more than Python converts (sys.get_int_max_str_digits)
                raise DelveError("an integer of thousands of digits", self.file, node.start_mark.line + 1) from None
            tag = node.tag.rsplit(":", 1)[-1]
            raise DelveError(f"cannot read this value as {short_repr(tag)[1:-1]}: {_clip(err, 60)}", self.file,
                             node.start_mark.line + 1) from None

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
                    f"a mapping key must be a plain value, not {_kind(key)}", self.file, key_node.start_mark.line + 1
                ) from None
            line = key_node.start_mark.line + 1
            if index >= n_merged:
                if key in seen:
                    raise DelveError(f"duplicate key {short_repr(key)} in mapping", self.file, line)
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


def _kind(value: Any) -> str:
    return "a mapping" if isinstance(value, dict) else "a list" if isinstance(value, list) else type(value).__name__


def _clip(text: str, limit: int = 80) -> str:
    """PyYAML's words about a problem, which may quote the file, cut to ``limit``."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[:limit] + "..."


def _syntax_error(err: yaml.YAMLError, file: str | None) -> DelveError:
    """One line for a PyYAML error: its problem and context, never the snippet of the
    file that ``str(err)`` prints."""
    problem_mark = getattr(err, "problem_mark", None)
    context_mark = getattr(err, "context_mark", None)
    mark = problem_mark or context_mark
    line = mark.line + 1 if mark is not None else None
    problem = getattr(err, "problem", None) or type(err).__name__
    context = getattr(err, "context", None)
    text = f"YAML syntax error: {_clip(problem)}"
    if context:
        text += f" ({_clip(context)}"
        if context_mark is not None and context_mark.line + 1 != line:
            text += f" that starts on line {context_mark.line + 1}"
        text += ")"
    return DelveError(text, file, line)


def _check_characters(text: str, file: str | None) -> None:
    """A DelveError at the first character YAML does not allow (a NUL byte, a control
    character), before PyYAML's reader reports it by offset."""
    bad = _NON_PRINTABLE.search(text)
    if bad is None:
        return
    char, line = bad.group(), text.count("\n", 0, bad.start()) + 1
    what, hint = f"control character U+{ord(char):04X}", ""
    if char == "\0":
        what, hint = "a NUL byte", " (is it a binary file?)"
    raise DelveError(f"{what}: YAML allows tabs, line breaks and printable characters only{hint}", file, line)


def loads_yaml(text: str, file: str | None = None) -> Any:
    """Parse YAML ``text``; ``file`` is only used for locations in errors."""
    _check_characters(text, file)
    loader = LineLoader(text, file=file)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as err:
        raise _syntax_error(err, file) from None
    finally:
        loader.dispose()


def decode(data: bytes, file: str | None = None) -> str:
    """The text of a YAML file's bytes: UTF-8 (a UTF-8 byte-order mark is dropped).
    A DelveError names the encoding that a byte-order mark or NUL bytes tell (UTF-16,
    UTF-32), or the line where UTF-8 decoding failed."""
    for bom, name in _BOMS:
        if data.startswith(bom):
            raise DelveError(f"the file is {name} text (it starts with a byte-order mark); save it as UTF-8", file, 1)
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]
    head = data[:4096]
    if b"\0" in head and len(head) >= 2:
        even, odd = head[0::2].count(0), head[1::2].count(0)
        if max(even, odd) > len(head) // 4:
            name = "UTF-16 (little-endian)" if odd > even else "UTF-16 (big-endian)"
            raise DelveError(f"the file looks like {name} text (NUL bytes between the letters); save it as UTF-8",
                             file, 1)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        column = err.start - (data.rfind(b"\n", 0, err.start) + 1) + 1
        byte = data[err.start]
        guess = ""
        try:
            data.decode("cp1252")
            guess = " (Latin-1 or Windows-1252?)"
        except UnicodeDecodeError:
            pass
        raise DelveError(f"not UTF-8 text: byte 0x{byte:02x} in column {column} cannot be decoded{guess}; "
                         "save the file as UTF-8", file, line) from None


def file_problem(path: str | os.PathLike[str]) -> str | None:
    """Why a file that a tree or scenario names cannot be read ("not found", "is a
    directory", ...), or None for a regular file. Names the system refuses (too long,
    a NUL byte in them) are a problem too, never an exception."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "not found"
    except (OSError, ValueError) as err:  # ENAMETOOLONG, ELOOP, EACCES; embedded NUL
        return f"cannot be used ({getattr(err, 'strerror', None) or 'a NUL byte in its name'})"
    if stat.S_ISDIR(mode):
        return "is a directory"
    return None if stat.S_ISREG(mode) else "is not a regular file"


def load_yaml(path: str | os.PathLike[str]) -> Any:
    """Read the YAML file at ``path``. Mappings and lists in the result are
    :class:`YamlDict` / :class:`YamlList` that know their file (``path`` as given)
    and lines.

    Raises:
        DelveError: the file is missing, unreadable, too large or not UTF-8, is not
            valid YAML, goes beyond the limits above, or has a mapping with a
            duplicate key.
    """
    file = os.fspath(path)
    try:
        if os.path.exists(file) and not os.path.isdir(file) and not stat.S_ISREG(os.stat(file).st_mode):
            raise DelveError("not a regular file (a device, pipe or socket)", file)
        with open(file, "rb") as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise DelveError("file not found", file) from None
    except IsADirectoryError:
        raise DelveError("is a directory, not a YAML file", file) from None
    except OSError as err:
        raise DelveError(f"cannot read file: {err.strerror}", file) from None
    if len(data) > MAX_FILE_BYTES:
        raise DelveError(f"file larger than {MAX_FILE_BYTES // 1_000_000} MB: too large for a tree or scenario",
                         file)
    return loads_yaml(decode(data, file), file=file)
