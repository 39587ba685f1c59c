"""delve.executive.tree_loader: YAML trees, includes, remaps, and the malformed corpus."""
from __future__ import annotations

import os
import re
from pathlib import Path

import py_trees
import pytest
from delve.executive.builtin_nodes import BUILTINS
from delve.executive.errors import DelveError
from delve.executive.registry import Registry, skill_types
from delve.executive.tree_loader import build_tree, check_tree, compose_remap, load_tree
from delve.skills.base import REQUIRED, AgentContext, Param, ParamNamedPort, Skill
from py_trees.common import Status

DATA = Path(__file__).resolve().parent.parent / "data"
TREES = DATA / "trees"
MALFORMED = sorted((DATA / "malformed").glob("*.yaml"))


class Clock:
    def __init__(self, now_s: float = 0.0):
        self.now_s = now_s


def make_ctx(namespace="/r1", clock=None):
    return AgentContext(name=namespace.strip("/"), namespace=namespace, clock=clock or Clock(), log=lambda *a, **k: None)


@pytest.fixture(autouse=True)
def clean_blackboard():
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()


def storage():
    return py_trees.blackboard.Blackboard.storage


def write(tmp_path, name, text):
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# --------------------------------------------------------------------------- malformed corpus


def header(path: Path) -> dict[str, str]:
    out = {}
    for line in path.read_text().splitlines():
        m = re.match(r"# (expect|line|file): (.*)$", line)
        if not m:
            break
        out[m.group(1)] = m.group(2)
    return out


def test_corpus_is_complete():
    assert len(MALFORMED) >= 14
    for path in MALFORMED:
        h = header(path)
        assert path.read_text().startswith("# expect: "), path
        assert "expect" in h and "line" in h, path


@pytest.mark.parametrize("path", MALFORMED, ids=lambda p: p.stem)
def test_malformed_tree_is_reported_with_file_and_line(path):
    h = header(path)
    with pytest.raises(DelveError) as info:
        check_tree(path)
    err = info.value
    assert type(err) is DelveError
    text = str(err)
    assert h["expect"] in text
    assert "\n" not in text
    m = re.match(r"^(.+?):(\d+): ", text)
    assert m, text
    assert Path(m.group(1)).name == h.get("file", path.name)
    assert int(m.group(2)) == int(h["line"]) == err.line


# --------------------------------------------------------------------------- includes and remaps


def test_compose_remap():
    assert compose_remap({"a": "b"}, None) == {"a": "b"}
    assert compose_remap({"a": "b"}, {"b": "c"}) == {"a": "c", "b": "c"}
    assert compose_remap({"a": "b"}, {"a": "z"}) == {"a": "b"}
    assert compose_remap(None, {"x": "y"}) == {"x": "y"}
    assert compose_remap({"a": "/abs"}, {"/abs": "nope"}) == {"a": "nope", "/abs": "nope"}


def test_include_with_remap_writes_the_remapped_key():
    root = load_tree(TREES / "include_remap.yaml", make_ctx("/r1"))
    assert [c.name for c in root.children] == ["Write home", "Mid"]
    root.tick_once()
    assert root.status == Status.SUCCESS
    assert storage()["/r1/home_pose"] == [1.0, 2.0, 0.5]  # goal -> home_pose
    assert storage()["/r1/base_pose"] == [1.0, 2.0, 0.5]  # goal -> target -> base_pose (nested)
    assert "/r1/goal" not in storage() and "/r1/target" not in storage()


def test_load_tree_remap_applies_to_the_whole_tree():
    root = load_tree(TREES / "include_remap.yaml", make_ctx("/r1"), remap={"home_pose": "/team/home"})
    root.tick_once()
    assert storage()["/team/home"] == [1.0, 2.0, 0.5]
    assert "/r1/home_pose" not in storage()


def test_two_agents_do_not_share_keys():
    r1 = load_tree(TREES / "namespaced.yaml", make_ctx("/r1"))
    r2 = load_tree(TREES / "namespaced.yaml", make_ctx("/r2"))
    client = py_trees.blackboard.Client(name="test")
    client.register_key("/r1/go", access=py_trees.common.Access.WRITE)
    client.set("/r1/go", True)
    r1.tick_once()
    r2.tick_once()
    assert r1.status == Status.SUCCESS and r2.status == Status.FAILURE
    assert storage()["/r1/result"] == "done"
    assert "/r2/result" not in storage() and "/result" not in storage()


def test_same_subtree_included_twice_is_not_a_cycle(tmp_path):
    write(tmp_path, "sub/leaf.yaml", "type: SetBlackboardVariable\nvariable_name: v\nvariable_value: 1\n")
    path = write(
        tmp_path,
        "root.yaml",
        "type: Sequence\nchildren:\n"
        "  - {include: sub/leaf.yaml, remap: {v: a}}\n"
        "  - {include: sub/leaf.yaml, remap: {v: b}}\n",
    )
    root = load_tree(path, make_ctx("/r1"))
    root.tick_once()
    assert storage()["/r1/a"] == 1 and storage()["/r1/b"] == 1


def test_includes_resolve_relative_to_the_including_file(tmp_path, monkeypatch):
    write(tmp_path, "a/b/leaf.yaml", "type: Success\n")
    write(tmp_path, "a/mid.yaml", "include: b/leaf.yaml\nname: Leaf\n")
    path = write(tmp_path, "root.yaml", "type: Inverter\nchild: {include: a/mid.yaml}\n")
    monkeypatch.chdir(tmp_path / "a")
    root = load_tree(os.path.relpath(path), make_ctx())
    assert root.decorated.name == "Leaf"


def test_a_relative_include_not_beside_its_file_is_looked_for_in_the_include_path_then_the_shipped_trees(
        tmp_path):
    from delve import TREES_DIR

    mine = write(tmp_path, "mine/cohort_robot.yaml", (TREES_DIR / "cohort_robot.yaml").read_text())
    assert check_tree(mine)   # a shipped tree copied to edit still finds the shipped subtrees
    write(tmp_path, "lib/subtrees/watchdog.yaml", "type: Success\nname: My watchdog\n")
    names = {n.name for n in load_tree(mine, make_ctx(), include_path=[tmp_path / "lib"]).iterate()}
    assert "My watchdog" in names   # the --include-path folder before the shipped trees
    write(tmp_path, "mine/subtrees/watchdog.yaml", "type: Success\nname: Beside\n")
    names = {n.name for n in load_tree(mine, make_ctx(), include_path=[tmp_path / "lib"]).iterate()}
    assert "Beside" in names and "My watchdog" not in names   # beside the file first
    write(tmp_path, "mine/up.yaml", "type: Inverter\nchild: {include: ../subtrees/watchdog.yaml}\n")
    with pytest.raises(DelveError, match="outside the allowed folders"):
        check_tree(tmp_path / "mine" / "up.yaml")   # the search never leaves a folder


def test_errors_in_included_files_name_that_file(tmp_path):
    write(tmp_path, "sub.yaml", "type: Sequence\nchildren:\n  - type: Timer\n    duration_s: -2\n")
    path = write(tmp_path, "root.yaml", "type: Inverter\nchild:\n  include: sub.yaml\n")
    with pytest.raises(DelveError) as info:
        check_tree(path)
    assert Path(info.value.file).name == "sub.yaml" and info.value.line == 4


def test_build_tree_from_a_parsed_mapping(tmp_path):
    write(tmp_path, "leaf.yaml", "type: SetBlackboardVariable\nvariable_name: v\nvariable_value: 2\n")
    root = build_tree({"include": "leaf.yaml", "remap": {"v": "w"}}, make_ctx("/r3"), file=tmp_path / "inline.yaml")
    root.tick_once()
    assert storage()["/r3/w"] == 2


def test_name_defaults_to_type_and_can_be_set(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Selector\nchildren:\n  - type: Failure\n  - {type: Success, name: Fine}\n")
    root = load_tree(path, make_ctx())
    assert root.name == "Selector" and [c.name for c in root.children] == ["Failure", "Fine"]


def test_decorator_accepts_children_with_one_element(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Inverter\nchildren:\n  - type: Failure\n")
    root = load_tree(path, make_ctx())
    root.tick_once()
    assert root.status == Status.SUCCESS


def test_int_given_for_float_param_becomes_float(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Timer\nduration_s: 3\n")
    root = load_tree(path, make_ctx())
    assert root.p["duration_s"] == 3.0 and isinstance(root.p["duration_s"], float)


def test_check_tree_releases_its_blackboard_clients():
    before = len(py_trees.blackboard.Blackboard.clients)
    check_tree(TREES / "all_builtins.yaml")
    check_tree(TREES / "all_builtins.yaml")
    assert len(py_trees.blackboard.Blackboard.clients) == before


# --------------------------------------------------------------------------- skills


class Fragile(Skill):
    """A test skill whose constructor rejects some parameter values."""

    ABSTRACT = True  # keep it out of delve.skills.all_skills()
    PARAMS = {
        "range_m": Param(float, REQUIRED, doc="range, in metres", minimum=0.0),
        "target": Param(str, "target", doc="blackboard key", key=True),
    }
    OUTPUT_PORTS = {"target": ParamNamedPort(float, description="the range", key_param="target")}

    def __init__(self, name, ctx, remap=None, **params):
        super().__init__(name, ctx, remap, **params)
        if self.p["range_m"] > 100:
            raise ValueError("range_m beyond the sensor's 100 m")

    def update(self):
        self.write("target", self.p["range_m"])
        return Status.SUCCESS


def fragile_registry():
    return Registry([*BUILTINS, *skill_types({"Fragile": Fragile})])


def test_skill_is_built_with_checked_params_and_remap(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Sequence\nchildren:\n  - type: Fragile\n    range_m: 5\n")
    root = load_tree(path, make_ctx("/r1"), remap={"target": "range"}, registry=fragile_registry())
    skill = root.children[0]
    assert isinstance(skill, Fragile) and skill.p == {"range_m": 5.0, "target": "target"}
    root.tick_once()
    assert storage()["/r1/range"] == 5.0


def test_value_error_in_a_skill_constructor_is_a_delve_error(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Sequence\nchildren:\n  - type: Success\n  - type: Fragile\n    name: Far\n    range_m: 500\n")
    with pytest.raises(DelveError) as info:
        check_tree(path, registry=fragile_registry())
    assert info.value.line == 6 and info.value.node == "Far"  # the key the error names
    assert "range_m beyond the sensor's 100 m" in str(info.value)


def test_skill_param_checks(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Fragile\nrange_m: -1\n")
    with pytest.raises(DelveError, match=r"t.yaml:2: parameter 'range_m' must be >= 0.0, got -1 \[node 'Fragile'\]"):
        check_tree(path, registry=fragile_registry())
    path = write(tmp_path, "u.yaml", "type: Fragile\nrange_m: 1\ntarget: ' '\n")
    with pytest.raises(DelveError, match="must be a blackboard key"):
        check_tree(path, registry=fragile_registry())
