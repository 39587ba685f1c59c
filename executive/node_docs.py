"""The node reference: every node type with its parameters and the blackboard keys it
reads and writes (a skill's declared ports), as text and as Markdown.

:func:`reference_markdown` is ``docs/nodes.md`` (written by :mod:`.generate`);
:func:`describe` is the plain listing that ``python -m delve.executive.generate --list``
prints.
"""
from __future__ import annotations

import inspect

from py_trees.ports import PortInformation

from .node_types import KINDS, NodeType, type_names
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
            for verb, ports in (("reads", t.reads), ("writes", t.writes)):
                for port, info in ports.items():
                    lines.append(f"    {verb} {_key_text(t, port, info, '')}: {_type_text(info)} -- "
                                 f"{info.description}")
    return "\n".join(lines)


def _type_text(info: PortInformation) -> str:
    return " or ".join(type_names(info.data_type)) or "any"


def _key_text(t: NodeType, port: str, info: PortInformation, quote: str = "`") -> str:
    """How the reference names a port's key: ``goal`` or ``goal`` (named by ``goal_key``)."""
    key, param = t.port_key(port, info)
    if param is None:
        return f"{quote}{key}{quote}"
    named = f"named by {quote}{param}{quote}"
    return f"{quote}{key}{quote} ({named})" if key is not None else f"the key {named}, if any"


def _ports_markdown(t: NodeType) -> list[str]:
    """The Reads and Writes tables of a node type (none without ports)."""
    out: list[str] = []
    if t.reads:
        out += ["Reads from the blackboard:", "", "| key | type | required | meaning |", "|---|---|---|---|"]
        for port, info in t.reads.items():
            need = "yes" if info.required else "no"
            if info.has_default:
                need += f", default `{info.default_value!r}`"
            out.append(f"| {_key_text(t, port, info)} | {_type_text(info)} | {need} | {info.description} |")
        out.append("")
    if t.writes:
        out += ["Writes to the blackboard:", "", "| key | type | meaning |", "|---|---|---|"]
        out += [f"| {_key_text(t, port, info)} | {_type_text(info)} | {info.description} |"
                for port, info in t.writes.items()]
        out.append("")
    return out



def reference_markdown(registry: Registry | None = None) -> str:
    """The node reference (docs/nodes.md): every node type with its parameters."""
    registry = default_registry() if registry is None else registry
    out = ["# Node reference", "",
           "Every node type a YAML tree can name. Generated from the registry by "
           "`make docs`; do not edit by hand.", "",
           "A skill lists the blackboard keys it reads and writes, as its ports declare them. A key "
           "is the agent's own (`goal` is `/anymal/goal` on robot `anymal`) unless it starts with `/`; "
           "an include's `remap` renames it, and so does the parameter named beside it.", ""]
    titles = {"composite": "Composites", "decorator": "Decorators", "behaviour": "Behaviours",
              "idiom": "Idioms", "skill": "Skills"}
    for kind in KINDS:
        out += [f"## {titles.get(kind, kind)}", ""]
        for name in registry.names(kind):
            t = registry[name]
            kids = {"none": "leaf", "one": "one child (`child`)", "many": "children (`children`)"}[t.arity]
            cls = t.cls if t.cls is not None and t.kind == "skill" else None
            doc = inspect.cleandoc(cls.__doc__ or "") if cls is not None else t.doc

            agent = {"robot": ", in a robot's tree", "base": ", in the base station's tree"}.get(
                getattr(cls, "AGENT", None), ", in any agent's tree" if cls is not None else "")
            out += [f"### {name}", "", f"*{kind}, {kids}{agent}*", "", doc, ""]
            rows = [(slot, "subtree", "required", d) for slot, d in t.subtrees.items()]
            rows += [(p, getattr(s.type, "__name__", "any"), "required" if s.required else f"`{s.default!r}`", s.doc)
                     for p, s in t.params.items()]
            if rows:
                out += ["| parameter | type | default | meaning |", "|---|---|---|---|"]
                out += [f"| `{p}` | {ty} | {d} | {m} |" for p, ty, d, m in rows]
                out.append("")
            out += _ports_markdown(t)
    return "\n".join(out).rstrip() + "\n"
