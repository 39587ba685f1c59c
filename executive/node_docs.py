"""The node reference: every node type with its parameters, as text and as Markdown.

:func:`reference_markdown` is ``docs/nodes.md`` (written by :mod:`.generate`);
:func:`describe` is the plain listing that ``python -m delve.executive.generate --list``
prints.
"""
from __future__ import annotations

import inspect

from .node_types import KINDS
from .registry import Registry, default_registry

__all__ = ["describe", "reference_markdown"]


def describe(registry: Registry | None = None) -> str:
    """A plain-text listing of the node types, their parameters and docs."""
    registry = default_registry() if registry is None else registry
    lines = []
    for kind in KINDS:
        for name in registry.names(kind):
            t = registry[name]
            kids = {"none": "", "one": " (one child)", "many": " (children)"}[t.arity]
            lines.append(f"{name} [{kind}]{kids}: {t.doc}")
            for slot, doc in t.subtrees.items():
                lines.append(f"    {slot}: subtree -- {doc}")
            for pname, spec in t.params.items():
                default = "required" if spec.required else f"default {spec.default!r}"
                lines.append(f"    {pname}: {getattr(spec.type, '__name__', 'any')}, {default} -- {spec.doc}")
    return "\n".join(lines)



def reference_markdown(registry: Registry | None = None) -> str:
    """The node reference (docs/nodes.md): every node type with its parameters."""
    registry = default_registry() if registry is None else registry
    out = ["# Node reference", "",
           "Every node type a YAML tree can name. Generated from the registry by "
           "`make docs`; do not edit by hand.", ""]
    titles = {"composite": "Composites", "decorator": "Decorators", "behaviour": "Behaviours",
              "idiom": "Idioms", "skill": "Skills"}
    for kind in KINDS:
        out += [f"## {titles.get(kind, kind)}", ""]
        for name in registry.names(kind):
            t = registry[name]
            kids = {"none": "leaf", "one": "one child (`child`)", "many": "children (`children`)"}[t.arity]
            cls = t.cls if t.cls is not None and t.kind == "skill" else None
            doc = inspect.cleandoc(cls.__doc__ or "") if cls is not None else t.doc

            out += [f"### {name}", "", f"*{kind}, {kids}*", "", doc, ""]
            rows = [(slot, "subtree", "required", d) for slot, d in t.subtrees.items()]
            rows += [(p, getattr(s.type, "__name__", "any"), "required" if s.required else f"`{s.default!r}`", s.doc)
                     for p, s in t.params.items()]
            if rows:
                out += ["| parameter | type | default | meaning |", "|---|---|---|---|"]
                out += [f"| `{p}` | {ty} | {d} | {m} |" for p, ty, d, m in rows]
                out.append("")
    return "\n".join(out).rstrip() + "\n"
