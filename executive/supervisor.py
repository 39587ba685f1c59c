"""The supervisor script of a scenario: timed commands to named robots.

Commands are checked when the scenario is loaded (unknown commands and arguments
with a did-you-mean, robots that do not exist, breadcrumb drops by robots that
carry none, impossible values) and sent at their time from the base station over
the radio, so a robot out of range receives them only when the link returns.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..skills.operator import COMMANDS
from ..skills.base import short_repr
from .errors import DelveError, did_you_mean
from .yamlio import YamlDict, YamlList, plain

RESERVED = ("at_s", "robot", "command")


@dataclass(frozen=True)
class Command:
    """One line of a supervisor script."""

    at_s: float
    robot: str
    command: str
    args: dict[str, Any] = field(default_factory=dict)


def _point(value: Any) -> bool:
    return isinstance(value, list) and len(value) == 3 and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)


def load_supervisor(items: Any, path: Path, robots: dict[str, int]) -> list[Command]:
    """Check a scenario's ``supervisor`` list; ``robots`` maps names to breadcrumbs carried."""
    if items is None:
        return []
    if not isinstance(items, YamlList):
        raise DelveError("supervisor: must be a list of commands", path, getattr(items, "line", None))
    out = []
    for i, item in enumerate(items):
        line = items.item_line(i)
        if not isinstance(item, YamlDict):
            raise DelveError("supervisor: each command must be a mapping", path, line)
        for key in ("at_s", "robot", "command"):
            if key not in item:
                raise DelveError(f"supervisor command: {key!r} is missing", path, line)
        at = item["at_s"]
        if isinstance(at, bool) or not isinstance(at, (int, float)) or not at >= 0:
            raise DelveError(f"supervisor command: at_s must be a time >= 0, got {short_repr(at)}", path,
                             item.key_line("at_s"))
        robot, name = item["robot"], item["command"]
        if robot not in robots:
            raise DelveError(f"supervisor command to unknown robot {short_repr(robot)}"
                             f"{did_you_mean(str(robot), robots)}",
                             path, item.key_line("robot"))
        if name not in COMMANDS:
            raise DelveError(f"unknown supervisor command {short_repr(name)}{did_you_mean(str(name), COMMANDS)}", path,
                             item.key_line("command"))
        spec = COMMANDS[name]
        args = {k: v for k, v in item.items() if k not in RESERVED}
        for key in args:
            if key not in spec:
                raise DelveError(f"command {name!r} has no argument {short_repr(key)}{did_you_mean(str(key), spec)}",
                                 path, item.key_line(key))
        for key, param in spec.items():
            if key not in args and param.required:
                raise DelveError(f"command {name!r} needs {key!r} ({param.doc})", path, line)
            value = args.get(key, param.default)
            problem = param.problem(value)
            if problem is None and param.type is list and value is not None and not _point(value):
                problem = "must be a point [x, y, z]"
            if problem:
                raise DelveError(f"command {name!r}: {key} {problem}", path, item.key_line(key) if key in args else line)
        if name == "drop_breadcrumb" and robots[robot] == 0:
            raise DelveError(f"robot {short_repr(robot)} carries no breadcrumbs to drop (set its 'breadcrumbs')", path,
                             line)
        if name == "set_bbox" and any(lo > hi for lo, hi in zip(args["min"], args["max"])):
            raise DelveError("command 'set_bbox': min must not exceed max", path, line)
        out.append(Command(float(at), robot, name, plain(args)))
    return sorted(out, key=lambda c: c.at_s)
