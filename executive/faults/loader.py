"""Reading a scenario's ``faults:`` list into :class:`Fault` objects.

Each entry names its ``kind``, its time ``at_s``, one target (``robot: NAME``,
``link: [A, B]`` or ``base_station: true``; a kind that only hits the base station
needs none), ``duration_s`` where the kind can end, and the kind's parameters. Every
mistake is one :class:`DelveError` at the key at fault.
"""
from __future__ import annotations

from typing import Any

from ..errors import DelveError, did_you_mean
from ..yamlio import YamlDict, YamlList, plain
from . import FAULT_KINDS
from .base import BASE_STATION, LINK, NEVER, REQUIRED, ROBOT, Fault, FaultContext, Target

#: Keys every entry may have; the rest are the kind's parameters.
COMMON_KEYS = ("at_s", "kind", "duration_s", ROBOT, LINK, BASE_STATION)
TARGET_WORDS = {ROBOT: "a robot", LINK: "a link", BASE_STATION: "the base station"}


def _world_name(ctx: FaultContext) -> str:
    from ..worlds import WORLD_BACKENDS

    return next((n for n, b in WORLD_BACKENDS.items() if b is ctx.backend), ctx.backend.__name__)


def _error(message: str, ctx: FaultContext, item: YamlDict, key: str | None = None) -> DelveError:
    """A one-line error at ``key`` of ``item`` (at the entry when ``key`` is None)."""
    return DelveError(message, ctx.path, item.key_line(key) if key is not None else item.line)


def _number(item: YamlDict, key: str, ctx: FaultContext, what: str, positive: bool) -> float:
    value = item[key]
    number = not isinstance(value, bool) and isinstance(value, (int, float))
    if not (number and (value > 0 if positive else value >= 0)):
        raise _error(f"fault: {key} must be {what}, got {value!r}", ctx, item, key)
    return float(value)


def _target(cls: type[Fault], item: YamlDict, ctx: FaultContext) -> Target:
    """The entry's one target, checked against what the kind may hit."""
    kind = cls.KIND
    given = [k for k in (ROBOT, LINK, BASE_STATION) if k in item]
    if len(given) > 1:
        raise _error(f"fault {kind!r}: give one target, {given[0]!r} or {given[1]!r}, not both", ctx, item,
                     given[1])
    if not given:
        if cls.TARGETS == (BASE_STATION,):
            return Target(BASE_STATION)
        wanted = " or ".join(repr(t) for t in cls.TARGETS)
        raise _error(f"fault {kind!r}: {wanted} is missing (whom it hits)", ctx, item)
    key = given[0]
    if key not in cls.TARGETS:
        can = ", ".join(TARGET_WORDS[t] for t in cls.TARGETS)
        raise _error(f"fault {kind!r} hits {can}, not {TARGET_WORDS[key]}", ctx, item, key)
    value = item[key]
    if key == ROBOT:
        if value not in ctx.robots:
            hint = did_you_mean(str(value), ctx.robots)
            raise _error(f"fault for unknown robot {value!r}{hint}", ctx, item, key)
        return Target(ROBOT, (value,))
    if key == BASE_STATION:
        if value is not True:
            raise _error(f"fault {kind!r}: write 'base_station: true', or name a robot or a link", ctx, item,
                         key)
        return Target(BASE_STATION)
    from ..worlds import BASE

    agents = [*ctx.robots, BASE]
    if not isinstance(value, list) or len(value) != 2 or not all(isinstance(v, str) for v in value):
        raise _error(f"fault {kind!r}: link must name two agents, e.g. [{agents[0]}, {BASE}]", ctx, item, key)
    for name in value:
        if name not in agents:
            raise _error(f"fault {kind!r}: link names unknown agent {name!r}{did_you_mean(name, agents)} "
                         f"(robots, or '{BASE}' for the base station)", ctx, item, key)
    if value[0] == value[1]:
        raise _error(f"fault {kind!r}: a link joins two different agents, not {value[0]!r} twice", ctx, item,
                     key)
    return Target(LINK, tuple(sorted(value)))


def _params(cls: type[Fault], item: YamlDict, ctx: FaultContext) -> dict[str, Any]:
    params = {}
    for key, value in item.items():
        if key in COMMON_KEYS:
            continue
        spec = cls.PARAMS.get(key)
        if spec is None:
            allowed = [*cls.PARAMS, "duration_s"] if cls.DURATION != NEVER else list(cls.PARAMS)
            has = f" (it has {', '.join(map(repr, cls.PARAMS))})" if cls.PARAMS else " (it has no parameters)"
            hint = did_you_mean(str(key), allowed) or has
            raise _error(f"fault {cls.KIND!r}: unknown parameter {key!r}{hint}", ctx, item, key)
        problem = spec.problem(value)
        if problem:
            raise _error(f"fault {cls.KIND!r}: {key} {problem}", ctx, item, key)
        params[key] = float(value) if spec.type is float and value is not None else plain(value)
    for key, spec in cls.PARAMS.items():
        if spec.required and key not in params:
            raise _error(f"fault {cls.KIND!r} needs {key!r} ({spec.doc})", ctx, item)
    return params


def load_fault(item: Any, line: int | None, ctx: FaultContext) -> Fault:
    """One entry of ``faults:`` as a :class:`Fault`."""
    if not isinstance(item, YamlDict):
        raise DelveError("faults: each fault must be a mapping (at_s, kind, robot, ...)", ctx.path, line)
    for key in ("at_s", "kind"):
        if key not in item:
            raise _error(f"fault: {key!r} is missing", ctx, item)
    kind = item["kind"]
    cls = FAULT_KINDS.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise _error(f"unknown fault kind {kind!r}{did_you_mean(str(kind), FAULT_KINDS)} "
                     f"(one of {', '.join(FAULT_KINDS)})", ctx, item, "kind")
    world = _world_name(ctx)
    if (cls.WORLDS is not None and world not in cls.WORLDS) or kind in ctx.backend.UNSUPPORTED_FAULTS:
        raise _error(f"a {kind!r} fault does not apply to this world ({world})", ctx, item, "kind")
    at_s = _number(item, "at_s", ctx, "a time >= 0", positive=False)
    target = _target(cls, item, ctx)
    duration = None
    if "duration_s" in item:
        if cls.DURATION == NEVER:
            raise _error(f"a {kind!r} fault does not end: remove duration_s", ctx, item, "duration_s")
        duration = _number(item, "duration_s", ctx, "a time > 0", positive=True)
    elif cls.DURATION == REQUIRED:
        raise _error(f"a {kind!r} fault needs duration_s", ctx, item)
    params = _params(cls, item, ctx)
    cls.check(item, target, ctx)
    return cls(at_s, target, duration, line=item.line, **params)


def load_faults(items: Any, ctx: FaultContext) -> list[Fault]:
    """A scenario's ``faults:`` list, checked, in order of time (entries at the same
    time in the file's order)."""
    if items is None:
        return []
    if not isinstance(items, YamlList):
        raise DelveError("faults: must be a list of faults", ctx.path, getattr(items, "line", None))
    faults = [load_fault(item, items.item_line(i), ctx) for i, item in enumerate(items)]
    return sorted(faults, key=lambda f: f.at_s)
