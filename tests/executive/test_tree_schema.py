"""delve.executive.tree_schema: the JSON Schema of tree files, and its shipped copy."""
from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml
from delve.executive import tree_schema as ts
from delve.executive.registry import default_registry
from delve.executive.tree_schema import tree_schema

import delve

DATA = Path(__file__).resolve().parent.parent / "data"
SCHEMA_FILE = ts.SCHEMA_PATH


def test_shipped_schema_equals_the_generated_one():
    shipped = json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    generated = json.loads(ts.schema_text())
    assert shipped == generated, (
        f"{SCHEMA_FILE} is out of date with the node registry; regenerate it with "
        f"`{ts.SCHEMA_COMMAND}`"
    )


def test_schema_is_valid_draft_2020_12():
    jsonschema.Draft202012Validator.check_schema(tree_schema())


def tree_files():
    files = sorted((DATA / "trees").rglob("*.yaml"))
    files += sorted(delve.TREES_DIR.rglob("*.yaml")) if delve.TREES_DIR.is_dir() else []
    return files


@pytest.mark.parametrize("path", tree_files(), ids=lambda p: str(p.name))
def test_tree_files_validate_against_the_schema(path):
    validator = jsonschema.Draft202012Validator(tree_schema())
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(yaml.safe_load(path.read_text()))]
    assert errors == []


@pytest.mark.parametrize(
    "tree, fragment",
    [
        ({"type": "Sequense", "children": [{"type": "Success"}]}, "Sequense"),
        ({"type": "Timer", "duration_s": -1}, "minimum"),
        ({"type": "Timer"}, "duration_s"),
        ({"type": "Timer", "duration_s": 1, "typo": 2}, "typo"),
        ({"type": "Inverter", "children": [{"type": "Success"}, {"type": "Failure"}]}, "too long"),
        ({"type": "Inverter"}, "child"),
        ({"type": "Sequence", "children": []}, "non-empty"),
        ({"type": "CheckBlackboardVariableValue", "variable_name": "a", "value": 1, "operator": "=>"}, "=>"),
        ({"include": "x.yaml", "remap": {"a": 3}}, "3"),
    ],
)
def test_schema_rejects_mistakes(tree, fragment):
    validator = jsonschema.Draft202012Validator(tree_schema())
    messages = [e.message for e in validator.iter_errors(tree)]
    messages += [c.message for e in validator.iter_errors(tree) for c in e.context or []]
    assert messages, f"schema accepted {tree}"
    assert any(fragment in m for m in messages) or fragment in json.dumps([str(e) for e in validator.iter_errors(tree)])


def test_schema_records_units_and_descriptions():
    defs = tree_schema()["$defs"]
    timer = defs["type.Timer"]["properties"]["duration_s"]
    assert timer["type"] == "number" and timer["minimum"] == 0.0 and "seconds" in timer["description"]
    assert defs["type.Sequence"]["properties"]["memory"]["default"] is True
    assert set(defs["typed_node"]["properties"]["type"]["enum"]) == set(default_registry().names())



def test_each_skill_lists_the_blackboard_keys_it_reads_and_writes():
    defs = tree_schema()["$defs"]
    goto = defs["type.GoTo"]["x-blackboard"]
    assert goto["reads"] == [{"key": "goal", "keyParameter": "goal_key", "type": "array", "required": False,
                              "description": goto["reads"][0]["description"]}]
    assert [(w["key"], w["type"]) for w in goto["writes"]] == [("goto_failure", ["string", "null"]),
                                                               ("goto_path_length_m", "number")]
    for t in default_registry():
        if t.kind != "skill":
            continue
        listed = defs[f"type.{t.name}"].get("x-blackboard", {"reads": [], "writes": []})
        assert len(listed["reads"]) == len(t.reads) and len(listed["writes"]) == len(t.writes), t.name
    # A key's type is left out where the value is a Python object (the COPS state).
    assert "type" not in defs["type.COPS"]["x-blackboard"]["reads"][0]
