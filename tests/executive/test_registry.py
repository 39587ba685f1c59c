"""delve.executive.registry: every node type by YAML name, skills included."""
from __future__ import annotations

import py_trees
import pytest
from delve.executive.node_types import NodeType
from delve.executive.registry import Registry, default_registry
from delve.skills import all_skills


def test_every_skill_is_registered_with_its_params():
    registry = default_registry()
    skills = all_skills()
    assert "Timer" in skills
    for name, cls in skills.items():
        node_type = registry[name]
        assert node_type.kind == "skill" and node_type.cls is cls
        assert dict(node_type.params) == dict(cls.PARAMS)
        assert node_type.arity == "none"


def test_params_have_units_docs_and_valid_defaults():
    for node_type in default_registry():
        for pname, spec in node_type.params.items():
            assert spec.doc, f"{node_type.name}.{pname} has no doc"
            if not spec.required:
                assert spec.problem(spec.default) is None, f"{node_type.name}.{pname} default is invalid"
    durations = [(t.name, p) for t in default_registry() for p in t.params if "duration" in p]
    assert all(p.endswith(("_s", "_ticks")) for _, p in durations), durations


def test_registry_rejects_duplicates():
    node = NodeType("X", "behaviour", lambda b: py_trees.behaviours.Success(b.name))
    with pytest.raises(ValueError, match="registered twice"):
        Registry([node, node])


def test_default_registry_is_cached():
    assert default_registry() is default_registry()



def test_a_former_skill_name_builds_the_new_form_and_says_so_once(tmp_path):
    from delve.executive.errors import DelveDeprecation, DelveError
    from delve.executive.tree_loader import check_context, load_tree
    from delve.skills.homing import Home

    alias = default_registry()["ReturnHome"]
    assert alias.kind == "skill" and "path_source" not in alias.params and "Deprecated" in alias.doc
    tree = tmp_path / "old.yaml"
    tree.write_text("type: Sequence\nchildren:\n  - type: ReturnHome\n    max_replans: 2\n")
    with pytest.warns(DelveDeprecation) as told:
        for _ in range(2):
            root = load_tree(tree, check_context())
            (node,) = root.children
            assert type(node) is Home and node.p["path_source"] == "navigator" and node.p["max_replans"] == 2
    notices = [str(w.message) for w in told if w.category is DelveDeprecation]
    assert len(notices) == 1
    assert "old.yaml:3: type 'ReturnHome' is deprecated: write type: Home, path_source: navigator" in notices[0]
    tree.write_text("type: ReturnHome\npath_source: gbplanner2\n")
    with pytest.raises(DelveError, match="path_source"):
        load_tree(tree, check_context())


@pytest.mark.parametrize("former, now", [("Explore", "ExploreGBPlanner2"),
                                         ("ExploreFrontiers", "ExploreNearestFrontier")])
def test_exploration_behaviours_are_named_by_their_planner_and_keep_their_former_names(tmp_path, former, now):
    from delve.executive.errors import DelveDeprecation
    from delve.executive.tree_loader import check_context, load_tree

    reg = default_registry()
    assert reg[now].cls is not None and "Deprecated" in reg[former].doc
    tree = tmp_path / "old.yaml"
    tree.write_text(f"type: {former}\n")
    with pytest.warns(DelveDeprecation, match=f"'{former}' is deprecated: write type: {now}"):
        node = load_tree(tree, check_context())
    assert type(node) is reg[now].cls
