"""The registry of node types: every name a YAML tree may give as ``type``.

:func:`default_registry` offers py_trees' composites, decorators, behaviours and idioms
(:mod:`.builtin_nodes`, with delve's sim-clock ``Timeout``) and every skill of
:func:`delve.skills.all_skills` under its ``TYPE_NAME`` (or class name); skills build
with their declared ``PARAMS`` and register the blackboard keys of their declared
``INPUT_PORTS`` and ``OUTPUT_PORTS`` themselves.

What a node type is lives in :mod:`.node_types`; the JSON Schema of tree files is
derived from the registry in :mod:`.tree_schema`, the node reference in
:mod:`.node_docs`. The node-type names (:class:`NodeType`, :class:`Build`, ...) are
re-exported here for importers of this module.
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from py_trees.behaviour import Behaviour

from ..skills import all_skills
from ..skills.base import Skill
from .builtin_nodes import BUILTINS
from .errors import DelveDeprecation, DelveError, did_you_mean
from .node_types import KINDS, RESERVED_KEYS, Build, Builder, NodeType, Site, coerce_param, first_paragraph

__all__ = [
    "KINDS",
    "RESERVED_KEYS",
    "Build",
    "NodeType",
    "Registry",
    "Site",
    "coerce_param",
    "default_registry",
    "skill_types",
]


class Registry:
    """Node types by YAML name."""

    def __init__(self, types: Iterable[NodeType] = ()):
        self._types: dict[str, NodeType] = {}
        for t in types:
            self.add(t)

    def add(self, node_type: NodeType) -> None:
        if node_type.name in self._types:
            old = self._types[node_type.name]
            raise ValueError(
                f"node type {node_type.name!r} is registered twice ({old.kind} {old.cls} and "
                f"{node_type.kind} {node_type.cls}); give one a different TYPE_NAME"
            )
        self._types[node_type.name] = node_type

    def get(self, name: str) -> NodeType | None:
        return self._types.get(name)

    def __getitem__(self, name: str) -> NodeType:
        return self._types[name]

    def __contains__(self, name: object) -> bool:
        return name in self._types

    def __iter__(self) -> Iterator[NodeType]:
        return iter(self._types.values())

    def __len__(self) -> int:
        return len(self._types)

    def names(self, kind: str | None = None) -> list[str]:
        """Sorted YAML names, of one kind if given."""
        return sorted(n for n, t in self._types.items() if kind is None or t.kind == kind)

    def suggest(self, name: str) -> str:
        """`` (did you mean 'X'?)`` for an unknown name, or ''."""
        return did_you_mean(name, self._types)


def _skill_builder(cls: type[Skill]) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name, ctx=b.ctx, remap=b.remap, **b.params)

    return build


_deprecations_told: set[tuple[str | None, int | None, str]] = set()


def _alias_builder(cls: type[Skill], alias: str, name: str, fixed: Mapping[str, Any]) -> Builder:
    """Builds ``cls`` with the parameters ``fixed`` on top, after telling (on stderr, once
    per place in a file) that ``alias`` is deprecated and what to write instead."""
    instead = ", ".join([f"type: {name}", *(f"{k}: {v}" for k, v in fixed.items())])

    def build(b: Build) -> Behaviour:
        if (b.site.file, b.site.line, alias) not in _deprecations_told:
            _deprecations_told.add((b.site.file, b.site.line, alias))
            notice = DelveError(f"type {alias!r} is deprecated: write {instead}", b.site.file, b.site.line)
            warnings.warn(DelveDeprecation(str(notice)), stacklevel=2)
        return cls(name=b.name, ctx=b.ctx, remap=b.remap, **{**b.params, **fixed})

    return build


def skill_types(skills: Mapping[str, type[Skill]] | None = None) -> list[NodeType]:
    """Node types for ``skills`` (default: :func:`delve.skills.all_skills`), and for the
    former names a skill class keeps in ``ALIASES`` (old name -> the parameters it
    stands for; built with a deprecation notice)."""
    skills = all_skills() if skills is None else skills
    types = []
    for name, cls in sorted(skills.items()):
        ports = {"reads": dict(cls.INPUT_PORTS), "writes": dict(cls.OUTPUT_PORTS)}
        types.append(NodeType(name, "skill", _skill_builder(cls), dict(cls.PARAMS), first_paragraph(cls), "none",
                              cls=cls, **ports))
        for alias, fixed in sorted(cls.__dict__.get("ALIASES", {}).items()):
            params = {k: v for k, v in cls.PARAMS.items() if k not in fixed}
            doc = f"Deprecated: write {name}" + "".join(f", {k}: {v}" for k, v in fixed.items()) + "."
            types.append(NodeType(alias, "skill", _alias_builder(cls, alias, name, fixed), params, doc, "none",
                                  **ports))
    return types


_cache: tuple[tuple[tuple[str, type], ...], Registry] | None = None


def default_registry() -> Registry:
    """The registry of py_trees' built-ins, delve's sim-clock timers and every skill
    of :func:`delve.skills.all_skills` (rebuilt when the set of skills changes)."""
    global _cache
    skills = all_skills()
    signature = tuple(sorted(skills.items(), key=lambda item: item[0]))
    if _cache is None or _cache[0] != signature:
        _cache = (signature, Registry([*BUILTINS, *skill_types(skills)]))
    return _cache[1]


