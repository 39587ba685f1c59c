"""delve.executive.node_docs: the node reference, and the shipped docs/nodes.md."""
from __future__ import annotations

from pathlib import Path

from delve.executive import node_docs
from delve.executive.registry import default_registry

#: docs/nodes.md of this source tree (it is not package data).
DOCS_FILE = Path(__file__).resolve().parents[2] / "docs" / "nodes.md"


def test_shipped_node_reference_equals_the_generated_one():
    shipped = DOCS_FILE.read_text(encoding="utf-8")
    assert shipped == node_docs.reference_markdown(), (
        "docs/nodes.md is out of date; regenerate it with `make docs`"
    )


def test_every_node_type_is_described_with_its_parameters():
    registry = default_registry()
    reference, listing = node_docs.reference_markdown(registry), node_docs.describe(registry)
    for node_type in registry:
        assert f"### {node_type.name}\n" in reference
        assert f"{node_type.name} [{node_type.kind}]" in listing
        for pname in node_type.params:
            assert f"| `{pname}` |" in reference


def test_every_skill_lists_the_keys_it_reads_and_writes():
    reference = node_docs.reference_markdown()
    for node_type in default_registry():
        section = reference.split(f"### {node_type.name}\n", 1)[1].split("\n### ", 1)[0]
        assert ("Reads from the blackboard:" in section) == bool(node_type.reads), node_type.name
        assert ("Writes to the blackboard:" in section) == bool(node_type.writes), node_type.name
        for port, info in {**node_type.reads, **node_type.writes}.items():
            key, param = node_type.port_key(port, info)
            assert (f"`{key}`" if key is not None else f"`{param}`") in section, (node_type.name, port)
            assert info.description in section


def test_a_key_named_by_a_parameter_says_which():
    goto = node_docs.reference_markdown().split("### GoTo\n", 1)[1].split("\n### ", 1)[0]
    assert "| `goal` (named by `goal_key`) | list | no |" in goto
    assert "| `goto_failure` | str or null |" in goto
