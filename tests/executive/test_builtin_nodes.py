"""delve.executive.builtin_nodes: py_trees' composites, decorators, behaviours and idioms by YAML name."""
from __future__ import annotations

from pathlib import Path

import py_trees
import pytest
import yaml
from delve.executive.registry import default_registry
from delve.executive.tree_loader import build_tree, load_tree
from delve.skills.base import AgentContext
from delve.skills.timing import Timeout as SimTimeout
from delve.skills.timing import Timer as SimTimer
from py_trees.common import Status

DATA = Path(__file__).resolve().parent.parent / "data"


class Clock:
    def __init__(self, now_s: float = 0.0):
        self.now_s = now_s


@pytest.fixture(autouse=True)
def clean_blackboard():
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()


def make_ctx(namespace="/r1", clock=None, log=None):
    return AgentContext(name=namespace.strip("/"), namespace=namespace, clock=clock or Clock(), log=log or (lambda *a, **k: None))


EXPECTED = {
    "composite": {"Sequence", "Selector", "Parallel"},
    "decorator": {
        "Inverter", "Retry", "Repeat", "Timeout", "OneShot", "EternalGuard", "Count", "PassThrough",
        "StatusToBlackboard", "Condition", "FailureIsRunning", "FailureIsSuccess", "RunningIsFailure",
        "RunningIsSuccess", "SuccessIsFailure", "SuccessIsRunning", "ForEach",
    },
    "behaviour": {
        "Success", "Failure", "Running", "Dummy", "SuccessEveryN", "TickCounter", "Periodic", "StatusQueue",
        "CheckBlackboardVariableExists", "CheckBlackboardVariableValue", "CheckBlackboardVariableValues",
        "CompareBlackboardVariables", "SetBlackboardVariable", "UnsetBlackboardVariable",
        "WaitForBlackboardVariable", "WaitForBlackboardVariableValue", "BlackboardToStatus",
    },
    "idiom": {"either_or", "pick_up_where_you_left_off", "oneshot"},
}


@pytest.mark.parametrize("kind", sorted(EXPECTED))
def test_builtin_names_and_kinds(kind):
    assert set(default_registry().names(kind)) == EXPECTED[kind]


def test_wall_clock_timers_are_not_reachable():
    registry = default_registry()
    assert registry["Timer"].cls is SimTimer
    assert registry["Timeout"].cls is SimTimeout
    classes = {t.cls for t in registry}
    assert py_trees.timers.Timer not in classes
    assert py_trees.decorators.Timeout not in classes
    root = build_tree({"type": "Timeout", "duration_s": 2, "child": {"type": "Timer", "duration_s": 1}}, make_ctx())
    assert type(root) is SimTimeout and type(root.decorated) is SimTimer


def test_memory_defaults():
    seq = build_tree({"type": "Sequence", "children": [{"type": "Success"}]}, make_ctx())
    sel = build_tree({"type": "Selector", "children": [{"type": "Success"}]}, make_ctx())
    assert seq.memory is True and sel.memory is False
    seq = build_tree({"type": "Sequence", "memory": False, "children": [{"type": "Success"}]}, make_ctx())
    assert seq.memory is False


def test_key_params_are_namespaced_and_remapped():
    ctx = make_ctx("/r1")

    def key_of(variable_name, remap=None):
        node = build_tree({"type": "CheckBlackboardVariableExists", "variable_name": variable_name}, ctx, remap=remap)
        return node.variable_name

    assert key_of("battery") == "/r1/battery"
    assert key_of("/shared/battery") == "/shared/battery"
    assert key_of("pose.x") == "/r1/pose.x"
    assert key_of("battery", {"battery": "power"}) == "/r1/power"
    assert key_of("battery", {"battery": "/team/power"}) == "/team/power"
    assert key_of("pose.x", {"pose": "goal"}) == "/r1/goal.x"


def test_nested_variable_reads_an_attribute():
    ctx = make_ctx("/r1")
    bb = py_trees.blackboard.Client(name="test")
    bb.register_key("/r1/pose", access=py_trees.common.Access.WRITE)
    bb.set("/r1/pose", {"x": 1})
    node = build_tree(
        {"type": "CheckBlackboardVariableValue", "variable_name": "pose", "value": {"x": 1}}, ctx
    )
    node.tick_once()
    assert node.status == Status.SUCCESS


def test_every_builtin_appears_in_the_all_builtins_fixture():
    text = (DATA / "trees" / "all_builtins.yaml").read_text()
    used = set()

    def walk(node):
        if isinstance(node, dict):
            if "type" in node:
                used.add(node["type"])
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    walk(yaml.safe_load(text))
    builtins = {t.name for t in default_registry() if t.kind != "skill"}
    assert builtins - used == set()


def test_all_builtins_fixture_runs_to_success():
    root = load_tree(DATA / "trees" / "all_builtins.yaml", make_ctx("/r1"))
    for _ in range(20):
        root.tick_once()
        if root.status != Status.RUNNING:
            break
    assert root.status == Status.SUCCESS
    storage = py_trees.blackboard.Blackboard.storage
    assert all(k.startswith("/r1/") for k in storage), sorted(storage)


def test_eternal_guard_condition_subtree_stops_the_child():
    ctx = make_ctx("/r1")
    root = build_tree(
        {
            "type": "EternalGuard",
            "condition": {"type": "CheckBlackboardVariableValue", "variable_name": "ok", "value": True},
            "child": {"type": "Running", "name": "Work"},
        },
        ctx,
    )
    bb = py_trees.blackboard.Client(name="test")
    bb.register_key("/r1/ok", access=py_trees.common.Access.WRITE)
    bb.set("/r1/ok", True)
    root.tick_once()
    assert root.status == Status.RUNNING and root.decorated.status == Status.RUNNING
    bb.set("/r1/ok", False)
    root.tick_once()
    assert root.status == Status.FAILURE and root.decorated.status == Status.INVALID


def test_parallel_policies():
    ctx = make_ctx()
    children = [{"type": "Success", "name": "A"}, {"type": "Running", "name": "B"}]
    selected = build_tree({"type": "Parallel", "policy": "success_on_selected", "selected": ["A"], "children": children}, ctx)
    assert isinstance(selected.policy, py_trees.common.ParallelPolicy.SuccessOnSelected)
    assert [c.name for c in selected.policy.children] == ["A"]
    selected.tick_once()
    assert selected.status == Status.SUCCESS
    all_ = build_tree({"type": "Parallel", "synchronise": False, "children": children}, ctx)
    assert isinstance(all_.policy, py_trees.common.ParallelPolicy.SuccessOnAll) and not all_.policy.synchronise
    one = build_tree({"type": "Parallel", "policy": "success_on_one", "children": children}, ctx)
    assert isinstance(one.policy, py_trees.common.ParallelPolicy.SuccessOnOne)


def test_pick_up_where_you_left_off_flags_are_per_agent():
    spec = {"type": "pick_up_where_you_left_off", "children": [{"type": "Success", "name": "Scan"}]}
    for ns in ("/r1", "/r2"):
        build_tree(spec, make_ctx(ns)).tick_once()
    keys = set(py_trees.blackboard.Blackboard.metadata)
    assert {"/r1/scan_done", "/r2/scan_done"} <= keys
    assert "/scan_done" not in keys


