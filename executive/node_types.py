"""What a node type of a YAML tree is, and what its builder receives.

A node type has a YAML name, a kind (``composite``, ``decorator``, ``behaviour``,
``idiom`` or ``skill``), declared parameters (:class:`~delve.skills.base.Param`, units in
the names), how many children it takes, the blackboard keys it reads and writes (a
skill's ports), and a builder that turns a :class:`Build` (checked parameters, built
children, the agent context) into a py_trees behaviour.
:class:`~delve.executive.registry.Registry` holds them by name.
"""
from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, NoReturn

from py_trees.behaviour import Behaviour
from py_trees.ports import PortInformation

from ..skills.base import AgentContext, Param, port_key_param, resolve_key
from .errors import DelveError
from .yamlio import YamlDict, YamlList, plain

__all__ = ["KINDS", "RESERVED_KEYS", "Build", "Builder", "NodeType", "Site", "coerce_param", "first_paragraph",
           "type_names"]

KINDS = ("composite", "decorator", "behaviour", "idiom", "skill")

#: Keys of a node that are not parameters.
RESERVED_KEYS = frozenset({"type", "name", "children", "child", "include", "remap"})


def coerce_param(spec: Param, value: Any) -> Any:
    """A checked value as a builder receives it: ints given for floats become floats,
    YAML mappings and lists become plain dicts and lists."""
    if spec.type is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return plain(value)


@dataclass
class Site:
    """Where a node came from, to point errors at the right line."""

    file: str | None = None
    node: Mapping[str, Any] | None = None
    node_name: str | None = None
    line: int | None = None

    def line_of(self, key: str | None = None, index: int | None = None) -> int | None:
        """Line of ``key`` of the node (of its item ``index`` when the value is a list)."""
        if key is None or not isinstance(self.node, YamlDict):
            return self.line
        value = self.node.get(key)
        if index is not None and isinstance(value, YamlList):
            item = value[index] if index < len(value) else None
            if isinstance(item, YamlDict) and item.line is not None:
                return item.line
            return value.item_line(index)
        return self.node.key_line(key)

    def fail(self, message: str, key: str | None = None, index: int | None = None) -> NoReturn:
        raise DelveError(message, self.file, self.line_of(key, index), self.node_name)


@dataclass
class Build:
    """What a builder receives: the node's name, checked parameters (defaults filled),
    built children and named subtrees, the agent context and the key remap."""

    name: str
    params: dict[str, Any]
    children: list[Behaviour]
    ctx: AgentContext
    remap: dict[str, str] = field(default_factory=dict)
    subtrees: dict[str, Behaviour] = field(default_factory=dict)
    given: frozenset[str] = frozenset()
    site: Site = field(default_factory=Site)

    def key(self, name: str) -> str:
        """Blackboard variable ``name`` (maybe nested: ``battery.percentage``) resolved
        for this agent: remapped, then under the agent's namespace unless absolute."""
        if name in self.remap:
            return resolve_key(name, self.ctx.namespace, self.remap)
        head, dot, rest = name.partition(".")
        return resolve_key(head, self.ctx.namespace, self.remap) + dot + rest

    def fail(self, message: str, key: str | None = None, index: int | None = None) -> NoReturn:
        self.site.fail(message, key, index)


Builder = Callable[[Build], Behaviour]


@dataclass(frozen=True)
class NodeType:
    """A node type that YAML trees name by ``type``.

    ``arity`` is how many children it takes: ``none`` (a leaf), ``one`` (``child``, or
    ``children`` with one element) or ``many`` (``children``, at least one).
    ``subtrees`` names extra single-node slots (EternalGuard's ``condition``).
    ``reads`` and ``writes`` are the blackboard keys it reads and writes, by port name
    (a skill's ``INPUT_PORTS`` and ``OUTPUT_PORTS``; see :meth:`port_key`).
    """

    name: str
    kind: str
    build: Builder
    params: Mapping[str, Param] = field(default_factory=dict)
    doc: str = ""
    arity: str = "none"
    subtrees: Mapping[str, str] = field(default_factory=dict)
    cls: type | None = None
    reads: Mapping[str, PortInformation] = field(default_factory=dict)
    writes: Mapping[str, PortInformation] = field(default_factory=dict)

    def port_key(self, port: str, info: PortInformation) -> tuple[str | None, str | None]:
        """The key of a port as a tree names it when no parameter is given (None: no
        key by default), and the parameter that names it instead (None: the key is the
        port's name)."""
        param = port_key_param(info)
        if param is None:
            return port, None
        spec = self.params.get(param)
        return (spec.default if spec is not None and not spec.required else None), param

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"node type {self.name!r}: unknown kind {self.kind!r}")
        if self.arity not in ("none", "one", "many"):
            raise ValueError(f"node type {self.name!r}: unknown arity {self.arity!r}")
        clash = (set(self.params) | set(self.subtrees)) & RESERVED_KEYS
        if clash or set(self.params) & set(self.subtrees):
            raise ValueError(f"node type {self.name!r}: parameter names {sorted(clash)} are reserved")


def type_names(data_type: Any) -> list[str]:
    """A port's ``data_type`` as names: ``float | None`` -> ``["float", "null"]``;
    ``[]`` for any value."""
    if data_type is Any or data_type is object:
        return []
    if isinstance(data_type, types.UnionType) or typing.get_origin(data_type) is typing.Union:
        return [n for arg in typing.get_args(data_type) for n in type_names(arg)]
    if data_type is type(None) or data_type is None:
        return ["null"]
    return [getattr(data_type, "__name__", str(data_type))]


def first_paragraph(obj: Any) -> str:
    """The first paragraph of ``obj``'s docstring on one line (a node type's short doc)."""
    doc = inspect.getdoc(obj) or ""
    return " ".join(doc.split("\n\n")[0].split())
