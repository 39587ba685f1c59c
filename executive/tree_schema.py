"""The JSON Schema of tree files, derived from the node registry.

:func:`tree_schema` gives the schema (draft 2020-12) of a tree file: a node is a typed
node (one definition per registered type, with its parameters, their units, bounds
and defaults, and its children) or an include. A skill's definition also lists the
blackboard keys it reads and writes (its declared ports) under ``x-blackboard``, an
annotation that validation ignores. The package ships it as
``schema/tree.schema.json`` (:data:`SCHEMA_PATH`), written by :mod:`.generate`.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from py_trees.ports import PortInformation

from ..skills.base import KEY_PATTERN, Param
from .node_types import NodeType, type_names
from .registry import Registry, default_registry

__all__ = ["SCHEMA_FILE_NAME", "SCHEMA_PATH", "param_schema", "schema_text", "tree_schema"]

SCHEMA_FILE_NAME = "tree.schema.json"
#: The shipped copy, package data next to this module.
SCHEMA_PATH = Path(__file__).resolve().parent / "schema" / SCHEMA_FILE_NAME
#: How the shipped copy is regenerated in a source tree (the file names it).
SCHEMA_COMMAND = "make docs"

_JSON_TYPES = {float: "number", int: "integer", bool: "boolean", str: "string", list: "array", dict: "object"}
_JSON_TYPE_NAMES = {t.__name__: j for t, j in _JSON_TYPES.items()} | {"null": "null"}


def _json_serialisable(value: Any) -> bool:
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        return False
    return True


def param_schema(spec: Param) -> dict[str, Any]:
    """JSON Schema of one parameter."""
    out: dict[str, Any] = {}
    json_type = _JSON_TYPES.get(spec.type)
    if json_type is not None:
        out["type"] = [json_type, "null"] if spec.nullable else json_type
    if spec.doc:
        out["description"] = spec.doc
    if spec.minimum is not None:
        out["minimum"] = spec.minimum
    if spec.exclusive_minimum is not None:
        out["exclusiveMinimum"] = spec.exclusive_minimum
    if spec.maximum is not None:
        out["maximum"] = spec.maximum
    if spec.length is not None:
        out["minItems"] = out["maxItems"] = spec.length
    if spec.items is not None and spec.items in _JSON_TYPES:
        out["items"] = {"type": _JSON_TYPES[spec.items]}
    if spec.key and spec.type is str:
        out["pattern"] = f"^{KEY_PATTERN.pattern}$"
    if spec.choices is not None:
        out["enum"] = [*spec.choices, *([None] if spec.nullable else [])]
    if not spec.required and _json_serialisable(spec.default):
        out["default"] = spec.default
    return out


def _port_schema(t: NodeType, port: str, info: PortInformation, read: bool) -> dict[str, Any]:
    """One blackboard key of ``t``: its key (when the tree names none other), the
    parameter that names it, its JSON type (none for a Python object), whether it is
    required (inputs) and its meaning."""
    key, param = t.port_key(port, info)
    out: dict[str, Any] = {"key": key}
    if param is not None:
        out["keyParameter"] = param
    names = type_names(info.data_type)
    if names and all(n in _JSON_TYPE_NAMES for n in names):
        json_types = [_JSON_TYPE_NAMES[n] for n in names]
        out["type"] = json_types[0] if len(json_types) == 1 else json_types
    if read:
        out["required"] = info.required
        if info.has_default and _json_serialisable(info.default_value):
            out["default"] = info.default_value
    if info.description:
        out["description"] = info.description
    return out


def _node_type_schema(t: NodeType) -> dict[str, Any]:
    props: dict[str, Any] = {
        "type": {"const": t.name},
        "name": {"type": "string", "minLength": 1, "description": "node name (default: the type)"},
    }
    for pname, spec in t.params.items():
        props[pname] = param_schema(spec)
    for slot, doc in t.subtrees.items():
        props[slot] = {"$ref": "#/$defs/node", "description": doc}
    required = ["type", *[p for p, s in t.params.items() if s.required], *t.subtrees]
    schema: dict[str, Any] = {"type": "object", "description": f"{t.kind}: {t.doc}" if t.doc else t.kind}
    if t.arity == "many":
        props["children"] = {"type": "array", "minItems": 1, "items": {"$ref": "#/$defs/node"}}
        required.append("children")
    elif t.arity == "one":
        props["child"] = {"$ref": "#/$defs/node"}
        props["children"] = {"type": "array", "minItems": 1, "maxItems": 1, "items": {"$ref": "#/$defs/node"}}
        schema["oneOf"] = [{"required": ["child"]}, {"required": ["children"]}]
    schema["properties"] = props
    schema["required"] = required
    schema["additionalProperties"] = False
    if t.reads or t.writes:
        schema["x-blackboard"] = {
            "reads": [_port_schema(t, p, info, read=True) for p, info in t.reads.items()],
            "writes": [_port_schema(t, p, info, read=False) for p, info in t.writes.items()],
        }
    return schema


def tree_schema(registry: Registry | None = None) -> dict[str, Any]:
    """JSON Schema (draft 2020-12) of a tree file, derived from ``registry``."""
    registry = default_registry() if registry is None else registry
    names = registry.names()
    defs: dict[str, Any] = {
        "node": {
            "description": "a tree node: a typed node, or an include of another tree file",
            "type": "object",
            "if": {"required": ["include"]},
            "then": {"$ref": "#/$defs/include"},
            "else": {"$ref": "#/$defs/typed_node"},
        },
        "include": {
            "type": "object",
            "description": "the root node of another tree file, its blackboard keys remapped",
            "properties": {
                "include": {"type": "string", "minLength": 1, "description": "path relative to this file"},
                "remap": {
                    "type": "object",
                    "description": "key in the included subtree -> key in this tree",
                    "additionalProperties": {"type": "string", "minLength": 1},
                },
                "name": {"type": "string", "minLength": 1, "description": "name of the included root"},
            },
            "required": ["include"],
            "additionalProperties": False,
        },
        "typed_node": {
            "type": "object",
            "required": ["type"],
            "properties": {"type": {"enum": names, "description": "node type"}},
            "allOf": [
                {"if": {"properties": {"type": {"const": n}}}, "then": {"$ref": f"#/$defs/type.{n}"}} for n in names
            ],
        },
    }
    for n in names:
        defs[f"type.{n}"] = _node_type_schema(registry[n])
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://delve.invalid/schema/tree.schema.json",
        "title": "delve behaviour tree",
        "description": f"A YAML behaviour tree of delve; the file's top-level mapping is the root node. "
        f"Generated from the node registry by `{SCHEMA_COMMAND}`.",
        "$ref": "#/$defs/node",
        "$defs": defs,
    }


def schema_text(registry: Registry | None = None) -> str:
    """The schema as the shipped file holds it."""
    return json.dumps(tree_schema(registry), indent=2, ensure_ascii=False) + "\n"


