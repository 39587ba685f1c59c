"""Fuzz: hostile trees and scenarios load or give delve's one-line error, nothing else.

Two properties, checked with hypothesis:

- trees generated from the node registry (every node type, its declared parameters)
  with hostile values (NaN, huge integers, control characters, nested lists and
  mappings, YAML 1.1 traps like ``1e3``, includes of files outside the tree's folder);
- the shipped trees and scenarios with random bytes spliced in (YAML punctuation,
  NUL, invalid UTF-8, byte-order marks, line breaks);
- a COPS network file with hostile values in place of valid ones.

Loading either succeeds or raises :class:`DelveError`, never anything else; its
message is one line, has no traceback, and quotes no long run of the file.
1000 generated trees, 700 spliced files and 300 network files take some 15 s of CPU
(20-40 s on a shared machine).
"""
from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import py_trees
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from delve import SCENARIOS_DIR, TREES_DIR
from delve.executive.errors import DelveError
from delve.executive.registry import default_registry
from delve.executive.scenario import load_scenario
from delve.executive.tree_loader import check_tree
from delve.executive.worlds.graph_sources import load_network_world

#: A value no message may quote in full (messages cut values to a few dozen characters).
CANARY = "canary-" + "q" * 93
REGISTRY = default_registry()
TYPE_NAMES = sorted(nt.name for nt in REGISTRY)
FUZZ = settings(deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.sampled_from([0, -1, 2**63, 10**400, -(10**400)]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["1e3", "1.5e-3", ".inf", "~", "", " ", "/", "success", "sucess", "running", "==",
                     "legged", "navigator", CANARY, "a" * 3000, "\x1b[31mred", "../../../../etc/passwd"]),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8) | st.integers(), inner,
                                                                max_size=4),
    max_leaves=8,
)
INCLUDES = st.sampled_from(["/etc/passwd", "../../../../etc/passwd", "/dev/zero", "/proc/self/environ", ".",
                            "", "missing.yaml", "leaf.yaml", "scenario.yaml", CANARY])


def plausible(spec) -> st.SearchStrategy:
    """Values a parameter's declaration allows (mostly), so that generated trees get
    past the first check and reach the builders."""
    if spec.choices:
        return st.sampled_from(spec.choices)
    low = spec.minimum if spec.minimum is not None else spec.exclusive_minimum
    if spec.type is float:
        return st.floats(min_value=low if low is not None else -1e3, max_value=spec.maximum or 1e3)
    if spec.type is int:
        return st.integers(min_value=int(low) if low is not None else -5, max_value=int(spec.maximum or 50))
    if spec.type is bool:
        return st.booleans()
    if spec.type is str:
        return st.sampled_from(["goal", "/team/x", "a.b", "home_pose", "x"]) if spec.key else st.text(max_size=8)
    return VALUES


@st.composite
def tree_nodes(draw, depth: int = 0):
    """A node of a random registered type; each parameter left out, given its
    default, or given a hostile value; children and subtrees to depth 2."""
    if draw(st.integers(0, 9)) == 0:
        node = {"include": draw(INCLUDES | VALUES)}
        if draw(st.booleans()):
            node["remap"] = draw(VALUES)
        return node
    node_type = REGISTRY[draw(st.sampled_from(TYPE_NAMES))]
    node = {"type": node_type.name}
    if draw(st.booleans()):
        node["name"] = draw(st.text(max_size=10) | st.just(CANARY) | VALUES)
    for param, spec in node_type.params.items():
        choice = draw(st.integers(0, 9))
        if choice == 0 or (choice < 3 and not spec.required):
            if not spec.required:
                node[param] = spec.default
        elif choice < 8:
            node[param] = draw(plausible(spec))
        else:
            node[param] = draw(VALUES)
    if node_type.arity != "none":
        if depth < 2:
            children = draw(st.lists(tree_nodes(depth + 1), min_size=1, max_size=2))
        else:
            children = [{"type": "Success"}]
        if node_type.arity == "one" and draw(st.booleans()):
            node["child"] = children[0]
        else:
            node["children"] = children
    for slot in node_type.subtrees:
        node[slot] = draw(tree_nodes(depth + 1)) if depth < 2 else {"type": "Success"}
    if draw(st.integers(0, 5)) == 0:
        node[draw(st.text(min_size=1, max_size=10) | st.just(CANARY))] = draw(VALUES)
    return node


def assert_one_clear_line(err: DelveError) -> None:
    text = str(err)
    assert "\n" not in text and "\r" not in text, text
    assert "Traceback" not in text
    assert CANARY[:50] not in text, text
    assert "a" * 60 not in text, text
    assert len(err.message) < 400, text


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A folder with a leaf tree and a scenario that the generated trees may include,
    and copies of the shipped trees and scenarios to splice into."""
    root = tmp_path_factory.mktemp("fuzz")
    (root / "leaf.yaml").write_text("type: Success\n")
    (root / "scenario.yaml").write_text("name: s\nworld: {generator: cave}\nrobots: []\n")
    shutil.copytree(TREES_DIR, root / "trees", ignore=shutil.ignore_patterns("__pycache__", "*.py"))
    shutil.copytree(SCENARIOS_DIR, root / "scenarios", ignore=shutil.ignore_patterns("__pycache__", "*.py"))
    return root


@pytest.fixture(autouse=True)
def quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # deprecations of former type names
        yield
    py_trees.blackboard.Blackboard.clear()


@settings(FUZZ, max_examples=1000)
@given(node=tree_nodes())
def test_generated_trees_load_or_give_one_line(workdir, node):
    path = workdir / "generated.yaml"
    path.write_text(yaml.safe_dump(node, allow_unicode=True))
    try:
        check_tree(path)
    except DelveError as err:
        assert_one_clear_line(err)


SHIPPED = sorted(p.relative_to(TREES_DIR.parent) for p in TREES_DIR.rglob("*.yaml")) + sorted(
    p.relative_to(SCENARIOS_DIR.parent) for p in SCENARIOS_DIR.glob("*.yaml"))
SPLICE = st.sampled_from([b":", b" ", b"-", b"\n", b"\t", b"[", b"]", b"{", b"}", b",", b"&a", b"*a", b"!", b"|",
                          b">", b"'", b'"', b"#", b"%", b"@", b"`", b"?", b"\x00", b"\xff", b"\xe9", b"\x1b",
                          b"\xef\xbb\xbf", b"\xff\xfe", b"1e3", b".nan", b"-.inf", b"9" * 400, b"type",
                          b"include: /etc/passwd\n", b"../", b"0", b"x"])
EDITS = st.lists(st.tuples(st.floats(0, 1), st.sampled_from(["insert", "delete", "replace"]),
                           st.lists(SPLICE, min_size=1, max_size=3).map(b"".join)), min_size=1, max_size=4)


def splice(data: bytes, edits: list[tuple[float, str, bytes]]) -> bytes:
    for where, how, chunk in edits:
        at = int(where * len(data))
        if how == "insert":
            data = data[:at] + chunk + data[at:]
        elif how == "delete":
            data = data[:at] + data[at + len(chunk):]
        else:
            data = data[:at] + chunk + data[at + len(chunk):]
    return data


@settings(FUZZ, max_examples=700)
@given(relative=st.sampled_from(SHIPPED), edits=EDITS)
def test_shipped_files_with_spliced_bytes_load_or_give_one_line(workdir, relative, edits):
    path = workdir / relative
    original = path.read_bytes()
    path.write_bytes(splice(original, edits))
    try:
        if relative.parts[0] == "scenarios":
            load_scenario(path)
        else:
            check_tree(path)
    except DelveError as err:
        assert_one_clear_line(err)
    finally:
        path.write_bytes(original)


NETWORK = {"base": "s0",
           "locations": [{"name": "s0", "pos": [0, 0]}, {"name": "s1", "pos": [50, 0]},
                         {"name": "s2", "pos": [50, 50, 3]}],
           "mobility": [["s0", "s1"], ["s1", "s2"]],
           "communication": [{"from": "s0", "to": "s1", "cost": 0.5}, ["s1", "s2"]]}


def places(value, where=()):
    """Every path into ``value`` (its keys and indices)."""
    yield where
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        yield from places(item, (*where, key))


@settings(FUZZ, max_examples=300)
@given(data=st.data())
def test_network_files_with_hostile_values_load_or_give_one_line(workdir, data):
    """A COPS scenario's network file with one to three values made hostile."""
    network = yaml.safe_load(yaml.safe_dump(NETWORK))
    targets = [p for p in places(network) if p]
    for where in data.draw(st.lists(st.sampled_from(targets), min_size=1, max_size=3)):
        parent = network
        try:
            for key in where[:-1]:
                parent = parent[key]
            parent[where[-1]] = data.draw(VALUES)
        except (KeyError, IndexError, TypeError):  # an earlier change removed the path
            pass
    path = workdir / "network.yaml"
    path.write_text(yaml.safe_dump(network, allow_unicode=True))
    try:
        load_network_world(path)
    except DelveError as err:
        assert_one_clear_line(err)
