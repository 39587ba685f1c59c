"""py_trees' built-ins as node types: composites, decorators, behaviours and idioms.

Each entry of :data:`BUILTINS` names a py_trees class (or idiom) under its py_trees
name, declares its parameters (units in the names) and builds it from a checked YAML
node. delve's sim-clock ``Timeout`` takes the place of py_trees' wall-clock one (and the
sim-clock ``Timer`` is a skill), so py_trees' wall-clock timers are reachable under no
name.

Blackboard key parameters (``key=True``) are resolved with :meth:`Build.key
<delve.executive.node_types.Build.key>`, so each agent has its own namespace and subtree
includes can remap them.
"""
from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from py_trees import behaviours, common, composites, decorators, idioms
from py_trees.behaviour import Behaviour

from ..skills.base import REQUIRED, Param, short_repr
from ..skills.timing import Timeout as SimTimeout
from .errors import did_you_mean
from .node_types import Build, Builder, NodeType, first_paragraph

__all__ = ["BEHAVIOURS", "BUILTINS", "COMPOSITES", "DECORATORS", "IDIOMS", "AnyParam"]

OPERATORS: dict[str, Callable[[Any, Any], bool]] = {
    "==": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}
LOGICAL_OPERATORS: dict[str, Callable[[bool, bool], bool]] = {
    "and": operator.and_,
    "or": operator.or_,
    "xor": operator.xor,
}
STATUSES = {
    "success": common.Status.SUCCESS,
    "failure": common.Status.FAILURE,
    "running": common.Status.RUNNING,
}
ONESHOT_POLICIES = {
    "on_completion": common.OneShotPolicy.ON_COMPLETION,
    "on_successful_completion": common.OneShotPolicy.ON_SUCCESSFUL_COMPLETION,
}
PARALLEL_POLICIES = ("success_on_all", "success_on_one", "success_on_selected")


@dataclass(frozen=True)
class AnyParam(Param):
    """A parameter that takes a value of any YAML type (a blackboard value)."""

    type: type = object

    def problem(self, value: Any) -> str | None:
        if value is None and not self.nullable:
            return "must not be null"
        if isinstance(value, float) and math.isnan(value):
            return "must not be NaN"
        return None


# --------------------------------------------------------------------------- helpers


def _slug(text: str) -> str:
    return re.sub(r"[^0-9a-z_]+", "_", text.lower()).strip("_") or "task"


_KEY = "blackboard variable (a.b for an attribute); under the agent's namespace unless it starts with '/', remapped by includes"
_COMPARISON_KEYS = {"variable_name", "value", "operator"}


def _comparison(b: Build, param: str, index: int, item: Any) -> common.ComparisonExpression:
    """A ``{variable_name, value, operator}`` mapping as a py_trees ComparisonExpression."""
    if not isinstance(item, dict):
        b.fail(f"'{param}' item {index + 1} must be a mapping with variable_name, value, operator", param, index)
    unknown = [key for key in item if key not in _COMPARISON_KEYS]
    if unknown:
        b.fail(
            f"unknown key {short_repr(unknown[0])} in '{param}' item {index + 1}"
            f"{did_you_mean(str(unknown[0]), _COMPARISON_KEYS)}",
            param,
            index,
        )
    for needed in ("variable_name", "value"):
        if needed not in item:
            b.fail(f"'{param}' item {index + 1} needs '{needed}'", param, index)
    var = item["variable_name"]
    if not isinstance(var, str) or not var:
        b.fail(f"'{param}' item {index + 1}: variable_name must be a non-empty string", param, index)
    op = item.get("operator", "==")
    if not isinstance(op, str) or op not in OPERATORS:
        b.fail(
            f"'{param}' item {index + 1}: operator must be one of {', '.join(map(repr, OPERATORS))}, "
            f"got {short_repr(op)}",
            param,
            index,
        )
    return common.ComparisonExpression(variable=b.key(var), value=item["value"], operator=OPERATORS[op])


def _comparisons(b: Build, param: str) -> list[common.ComparisonExpression]:
    return [_comparison(b, param, i, item) for i, item in enumerate(b.params[param])]


def _status_list(b: Build, param: str) -> list[common.Status]:
    out = []
    for i, item in enumerate(b.params[param]):
        if not isinstance(item, str) or item not in STATUSES:
            b.fail(f"'{param}' item {i + 1} must be one of {', '.join(map(repr, STATUSES))}, got {short_repr(item)}",
                   param, i)
        out.append(STATUSES[item])
    return out


# --------------------------------------------------------------------------- composites


def _sequence(b: Build) -> Behaviour:
    return composites.Sequence(name=b.name, memory=b.params["memory"], children=b.children)


def _selector(b: Build) -> Behaviour:
    return composites.Selector(name=b.name, memory=b.params["memory"], children=b.children)


def _parallel(b: Build) -> Behaviour:
    policy_name = b.params["policy"]
    selected = b.params["selected"]
    if policy_name != "success_on_selected" and "selected" in b.given:
        b.fail(f"'selected' needs policy success_on_selected, not {policy_name}", "selected")
    if policy_name == "success_on_one":
        if "synchronise" in b.given:
            b.fail("'synchronise' has no effect with policy success_on_one", "synchronise")
        policy: common.ParallelPolicy.Base = common.ParallelPolicy.SuccessOnOne()
    elif policy_name == "success_on_all":
        policy = common.ParallelPolicy.SuccessOnAll(synchronise=b.params["synchronise"])
    else:
        if not selected:
            b.fail("policy success_on_selected needs 'selected': a list of child names", "policy")
        by_name: dict[str, Behaviour] = {}
        for child in b.children:
            if child.name in by_name and child.name in selected:
                b.fail(f"two children are named {short_repr(child.name)}; 'selected' cannot tell them apart",
                       "selected")
            by_name[child.name] = child
        chosen = []
        for i, child_name in enumerate(selected):
            if not isinstance(child_name, str) or child_name not in by_name:
                b.fail(
                    f"'selected' names no child {short_repr(child_name)}{did_you_mean(str(child_name), by_name)}",
                    "selected",
                    i,
                )
            chosen.append(by_name[child_name])
        policy = common.ParallelPolicy.SuccessOnSelected(children=chosen, synchronise=b.params["synchronise"])
    return composites.Parallel(name=b.name, policy=policy, children=b.children)


COMPOSITES = [
    NodeType(
        "Sequence",
        "composite",
        _sequence,
        {"memory": Param(bool, True, doc="resume from the running child (true) or restart from the first every tick")},
        "Tick children in order: FAILURE or RUNNING at the first child that does so, SUCCESS when all succeed.",
        "many",
        cls=composites.Sequence,
    ),
    NodeType(
        "Selector",
        "composite",
        _selector,
        {"memory": Param(bool, False, doc="resume from the running child (true) or re-check higher priorities every tick")},
        "Tick children in priority order: SUCCESS or RUNNING at the first child that does so, FAILURE when all fail.",
        "many",
        cls=composites.Selector,
    ),
    NodeType(
        "Parallel",
        "composite",
        _parallel,
        {
            "policy": Param(str, "success_on_all", doc="when the parallel succeeds", choices=PARALLEL_POLICIES),
            "synchronise": Param(
                bool, True, doc="skip children that succeeded until the policy is met (success_on_all/selected)"
            ),
            "selected": Param(list, [], doc="names of the children that must succeed (policy success_on_selected)"),
        },
        "Tick every child every tick: FAILURE as soon as one fails, SUCCESS when the policy is met, else RUNNING.",
        "many",
        cls=composites.Parallel,
    ),
]


# --------------------------------------------------------------------------- decorators


def _simple_decorator(cls: type) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name, child=b.children[0])

    return build


def _retry(b: Build) -> Behaviour:
    return decorators.Retry(name=b.name, child=b.children[0], num_failures=b.params["num_failures"])


def _repeat(b: Build) -> Behaviour:
    if b.params["num_success"] == 0:
        b.fail("parameter 'num_success' must be >= 1, or -1 to repeat forever; got 0", "num_success")
    return decorators.Repeat(name=b.name, child=b.children[0], num_success=b.params["num_success"])


def _timeout(b: Build) -> Behaviour:
    return SimTimeout(name=b.name, child=b.children[0], ctx=b.ctx, duration_s=b.params["duration_s"])


def _oneshot_decorator(b: Build) -> Behaviour:
    return decorators.OneShot(name=b.name, child=b.children[0], policy=ONESHOT_POLICIES[b.params["policy"]])


def _subtree_condition(subtree: Behaviour) -> Callable[[], common.Status]:
    """A condition that ticks ``subtree`` once and reports its status; a subtree left
    RUNNING is stopped, so each check starts afresh."""

    def condition() -> common.Status:
        for _ in subtree.tick():
            pass
        status = subtree.status
        if status == common.Status.RUNNING:
            subtree.stop(common.Status.INVALID)
        return status

    return condition


def _eternal_guard(b: Build) -> Behaviour:
    guard = decorators.EternalGuard(
        name=b.name, child=b.children[0], condition=_subtree_condition(b.subtrees["condition"])
    )
    guard.condition_subtree = b.subtrees["condition"]
    return guard


def _status_to_blackboard(b: Build) -> Behaviour:
    return decorators.StatusToBlackboard(
        name=b.name, child=b.children[0], variable_name=b.key(b.params["variable_name"])
    )


def _condition(b: Build) -> Behaviour:
    return decorators.Condition(name=b.name, child=b.children[0], status=STATUSES[b.params["status"]])


def _for_each(b: Build) -> Behaviour:
    node = decorators.ForEach(
        name=b.name, child=b.children[0], source_key=b.key(b.params["source_key"]), target_key=b.key(b.params["target_key"])
    )
    node.blackboards.append(node.blackboard)  # py_trees makes the client without attaching it
    return node


def _decorator(name: str, build: Builder, cls: type, params: Mapping[str, Param] | None = None, doc: str = "", **kw: Any) -> NodeType:
    return NodeType(name, "decorator", build, params or {}, doc or first_paragraph(cls), "one", cls=cls, **kw)


def _x_is_y_doc(name: str) -> str:
    x, y = (part.upper() for part in name.split("Is"))
    return f"Return {y} when the child returns {x}; reflect its other statuses."


_X_IS_Y = [
    decorators.FailureIsRunning,
    decorators.FailureIsSuccess,
    decorators.RunningIsFailure,
    decorators.RunningIsSuccess,
    decorators.SuccessIsFailure,
    decorators.SuccessIsRunning,
]

DECORATORS = [
    _decorator("Inverter", _simple_decorator(decorators.Inverter), decorators.Inverter,
               doc="Flip the child's SUCCESS and FAILURE; RUNNING passes through."),
    _decorator("PassThrough", _simple_decorator(decorators.PassThrough), decorators.PassThrough,
               doc="Reflect the child's status unchanged (for debugging and visualisation)."),
    _decorator("Count", _simple_decorator(decorators.Count), decorators.Count,
               doc="Reflect the child's status while counting its ticks, successes, failures and interrupts."),
    *[
        _decorator(cls.__name__, _simple_decorator(cls), cls, doc=_x_is_y_doc(cls.__name__))
        for cls in _X_IS_Y
    ],
    _decorator(
        "Retry", _retry, decorators.Retry,
        {"num_failures": Param(int, REQUIRED, doc="failures allowed before the decorator fails", minimum=1)},
        "Turn the child's FAILURE into RUNNING (a retry) until it has failed num_failures times.",
    ),
    _decorator(
        "Repeat", _repeat, decorators.Repeat,
        {"num_success": Param(int, REQUIRED, doc="successes to repeat for; -1 repeats forever", minimum=-1)},
        "Turn the child's SUCCESS into RUNNING (a repeat) until it has succeeded num_success times; FAILURE fails.",
    ),
    _decorator(
        "Timeout", _timeout, SimTimeout,
        {"duration_s": Param(float, REQUIRED, doc="sim time the child may stay RUNNING, in seconds", minimum=0.0)},
        "Fail and stop the child when it has been RUNNING for duration_s of simulation time.",
    ),
    _decorator(
        "OneShot", _oneshot_decorator, decorators.OneShot,
        {"policy": Param(str, "on_successful_completion", doc="which finish is final: any (on_completion) or SUCCESS only",
                         choices=tuple(ONESHOT_POLICIES))},
        "Tick the child to completion once; afterwards return its final status without ticking it.",
    ),
    _decorator(
        "EternalGuard", _eternal_guard, decorators.EternalGuard, {},
        "Tick the 'condition' subtree before every tick of the child; when it fails, stop the child and fail.",
        subtrees={"condition": "subtree ticked before every tick of the child; FAILURE stops the child "
                               "(SUCCESS or RUNNING let it run)"},
    ),
    _decorator(
        "StatusToBlackboard", _status_to_blackboard, decorators.StatusToBlackboard,
        {"variable_name": Param(str, REQUIRED, doc=f"where to write the child's status; {_KEY}", key=True)},
        "Write the child's status to a blackboard variable and reflect it.",
    ),
    _decorator(
        "Condition", _condition, decorators.Condition,
        {"status": Param(str, "success", doc="child status to wait for", choices=tuple(STATUSES))},
        "RUNNING until the child returns the given status, then SUCCESS; never FAILURE.",
    ),
    _decorator(
        "ForEach", _for_each, decorators.ForEach,
        {
            "source_key": Param(str, REQUIRED, doc=f"list to iterate over; {_KEY}", key=True),
            "target_key": Param(str, REQUIRED, doc=f"where each item is written; {_KEY}", key=True),
        },
        "Run the child once for each item of a blackboard list, writing the item to target_key first.",
    ),
]


# --------------------------------------------------------------------------- behaviours


def _plain_behaviour(cls: type) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name)

    return build


def _every_n(cls: type) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name, n=b.params["n"])

    return build


def _tick_counter(b: Build) -> Behaviour:
    return behaviours.TickCounter(
        name=b.name, duration=b.params["duration_ticks"], completion_status=STATUSES[b.params["completion_status"]]
    )


def _status_queue(b: Build) -> Behaviour:
    queue = _status_list(b, "queue")
    if not queue:
        b.fail("'queue' must name at least one status", "queue")
    eventually = b.params["eventually"]
    return behaviours.StatusQueue(name=b.name, queue=queue, eventually=None if eventually is None else STATUSES[eventually])


def _variable_behaviour(cls: type) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name, variable_name=b.key(b.params["variable_name"]))

    return build


def _check_value(cls: type) -> Builder:
    def build(b: Build) -> Behaviour:
        check = common.ComparisonExpression(
            variable=b.key(b.params["variable_name"]), value=b.params["value"], operator=OPERATORS[b.params["operator"]]
        )
        return cls(name=b.name, check=check)

    return build


def _check_values(b: Build) -> Behaviour:
    checks = _comparisons(b, "checks")
    if len(checks) < 2:
        b.fail("'checks' needs at least two comparisons", "checks")
    namespace = b.params["namespace"]
    return behaviours.CheckBlackboardVariableValues(
        name=b.name,
        checks=checks,
        operator=LOGICAL_OPERATORS[b.params["logical_operator"]],
        namespace=None if namespace is None else b.key(namespace),
    )


def _compare(b: Build) -> Behaviour:
    return behaviours.CompareBlackboardVariables(
        name=b.name,
        var1_key=b.key(b.params["var1_key"]),
        var2_key=b.key(b.params["var2_key"]),
        operator=OPERATORS[b.params["operator"]],
    )


def _set_variable(b: Build) -> Behaviour:
    return behaviours.SetBlackboardVariable(
        name=b.name,
        variable_name=b.key(b.params["variable_name"]),
        variable_value=b.params["variable_value"],
        overwrite=b.params["overwrite"],
    )


def _unset_variable(b: Build) -> Behaviour:
    return behaviours.UnsetBlackboardVariable(name=b.name, key=b.key(b.params["key"]))


def _behaviour(name: str, build: Builder, cls: type, params: Mapping[str, Param] | None = None, doc: str = "") -> NodeType:
    return NodeType(name, "behaviour", build, params or {}, doc or first_paragraph(cls), "none", cls=cls)


_OPERATOR = Param(str, "==", doc="comparison: variable OPERATOR value", choices=tuple(OPERATORS))
_COMPARISON_DOC = "comparisons, each a mapping {variable_name, value, operator (default ==)}"
_CHECK_VALUE_PARAMS = {
    "variable_name": Param(str, REQUIRED, doc=_KEY, key=True),
    "value": AnyParam(default=REQUIRED, nullable=True, doc="value to compare the variable with (null: unset)"),
    "operator": _OPERATOR,
}

BEHAVIOURS = [
    _behaviour("Success", _plain_behaviour(behaviours.Success), behaviours.Success, doc="Always SUCCESS."),
    _behaviour("Failure", _plain_behaviour(behaviours.Failure), behaviours.Failure, doc="Always FAILURE."),
    _behaviour("Running", _plain_behaviour(behaviours.Running), behaviours.Running, doc="Always RUNNING."),
    _behaviour("Dummy", _plain_behaviour(behaviours.Dummy), behaviours.Dummy,
               doc="Crash test dummy: always RUNNING, a placeholder for a behaviour still to write."),
    _behaviour(
        "SuccessEveryN", _every_n(behaviours.SuccessEveryN), behaviours.SuccessEveryN,
        {"n": Param(int, REQUIRED, doc="succeed on every n-th tick (a count of ticks)", minimum=1)},
        "SUCCESS on every n-th tick, FAILURE on the others.",
    ),
    _behaviour(
        "Periodic", _every_n(behaviours.Periodic), behaviours.Periodic,
        {"n": Param(int, REQUIRED, doc="ticks spent in each status (a count of ticks)", minimum=1)},
        "Cycle RUNNING, SUCCESS, FAILURE, n ticks each.",
    ),
    _behaviour(
        "TickCounter", _tick_counter, behaviours.TickCounter,
        {
            "duration_ticks": Param(int, REQUIRED, doc="ticks to stay RUNNING", minimum=0),
            "completion_status": Param(str, "success", doc="status after duration_ticks",
                                       choices=("success", "failure")),
        },
        "RUNNING for duration_ticks ticks after entry, then completion_status.",
    ),
    _behaviour(
        "StatusQueue", _status_queue, behaviours.StatusQueue,
        {
            "queue": Param(list, REQUIRED, doc="statuses to return in turn: success, failure, running"),
            "eventually": Param(str, None, doc="status once the queue is used up; null cycles the queue",
                                choices=tuple(STATUSES), nullable=True),
        },
        "Return the statuses of a queue in turn, then 'eventually' (or the queue again).",
    ),
    _behaviour(
        "BlackboardToStatus", _variable_behaviour(behaviours.BlackboardToStatus), behaviours.BlackboardToStatus,
        {"variable_name": Param(str, REQUIRED, doc=f"variable holding a status (see StatusToBlackboard); {_KEY}", key=True)},
        "Return the status stored in a blackboard variable by StatusToBlackboard.",
    ),
    _behaviour(
        "CheckBlackboardVariableExists", _variable_behaviour(behaviours.CheckBlackboardVariableExists),
        behaviours.CheckBlackboardVariableExists,
        {"variable_name": Param(str, REQUIRED, doc=_KEY, key=True)},
        "SUCCESS if the variable exists on the blackboard, FAILURE otherwise.",
    ),
    _behaviour(
        "WaitForBlackboardVariable", _variable_behaviour(behaviours.WaitForBlackboardVariable),
        behaviours.WaitForBlackboardVariable,
        {"variable_name": Param(str, REQUIRED, doc=_KEY, key=True)},
        "RUNNING until the variable exists on the blackboard, then SUCCESS.",
    ),
    _behaviour(
        "CheckBlackboardVariableValue", _check_value(behaviours.CheckBlackboardVariableValue),
        behaviours.CheckBlackboardVariableValue,
        dict(_CHECK_VALUE_PARAMS),
        "SUCCESS if 'variable OPERATOR value' holds, FAILURE if not or if the variable is missing.",
    ),
    _behaviour(
        "WaitForBlackboardVariableValue", _check_value(behaviours.WaitForBlackboardVariableValue),
        behaviours.WaitForBlackboardVariableValue,
        dict(_CHECK_VALUE_PARAMS),
        "RUNNING until 'variable OPERATOR value' holds, then SUCCESS.",
    ),
    _behaviour(
        "CheckBlackboardVariableValues", _check_values, behaviours.CheckBlackboardVariableValues,
        {
            "checks": Param(list, REQUIRED, doc=f"two or more {_COMPARISON_DOC}"),
            "logical_operator": Param(str, "and", doc="how the results combine", choices=tuple(LOGICAL_OPERATORS)),
            "namespace": Param(str, None, doc=f"if set, each check's result is written under it (1, 2, ...); {_KEY}",
                               key=True, nullable=True),
        },
        "SUCCESS if the comparisons, combined with logical_operator, hold; FAILURE otherwise.",
    ),
    _behaviour(
        "CompareBlackboardVariables", _compare, behaviours.CompareBlackboardVariables,
        {
            "var1_key": Param(str, REQUIRED, doc=f"left-hand variable; {_KEY}", key=True),
            "var2_key": Param(str, REQUIRED, doc=f"right-hand variable; {_KEY}", key=True),
            "operator": _OPERATOR,
        },
        "SUCCESS if 'var1 OPERATOR var2' holds, FAILURE if not or if either is missing.",
    ),
    _behaviour(
        "SetBlackboardVariable", _set_variable, behaviours.SetBlackboardVariable,
        {
            "variable_name": Param(str, REQUIRED, doc=_KEY, key=True),
            "variable_value": AnyParam(default=REQUIRED, doc="value to write"),
            "overwrite": Param(bool, True, doc="overwrite an existing value (false: FAILURE if it exists)"),
        },
        "Write a value to a blackboard variable: SUCCESS, or FAILURE when it exists and overwrite is false.",
    ),
    _behaviour(
        "UnsetBlackboardVariable", _unset_variable, behaviours.UnsetBlackboardVariable,
        {"key": Param(str, REQUIRED, doc=_KEY, key=True)},
        "Remove a variable from the blackboard; always SUCCESS.",
    ),
]


# --------------------------------------------------------------------------- idioms


def _either_or(b: Build) -> Behaviour:
    conditions = _comparisons(b, "conditions")
    if len(conditions) != len(b.children):
        b.fail(
            f"either_or needs one condition per child: {len(conditions)} conditions, {len(b.children)} children",
            "conditions",
        )
    namespace = b.params["namespace"]
    if namespace is None:
        namespace = f"{_slug(b.name)}_conditions"
    return idioms.either_or(conditions=conditions, subtrees=b.children, name=b.name, namespace=b.key(namespace))


def _pick_up_where_you_left_off(b: Build) -> Behaviour:
    """py_trees.idioms.pick_up_where_you_left_off with the tasks' done flags in the
    agent's namespace (py_trees puts them at the blackboard's root, which agents share)."""
    flags: dict[str, str] = {}
    for child in b.children:
        flag = f"{_slug(child.name)}_done"
        if flag in flags.values():
            b.fail(f"children of pick_up_where_you_left_off need distinct names; {short_repr(child.name)} repeats",
                   "children")
        flags[child.name] = b.key(flag)
    root = composites.Sequence(name=b.name, memory=True)
    for task in b.children:
        flag = flags[task.name]
        guard = behaviours.CheckBlackboardVariableValue(
            name="Done?", check=common.ComparisonExpression(variable=flag, value=True, operator=operator.eq)
        )
        worker = composites.Sequence(name="Worker", memory=True)
        mark = behaviours.SetBlackboardVariable(
            name=f"Mark\n{flag.rsplit('/', 1)[-1]}", variable_name=flag, variable_value=True, overwrite=True
        )
        worker.add_children([task, mark])
        chooser = composites.Selector(name="Do or Don't", memory=False)
        chooser.add_children([guard, worker])
        root.add_child(chooser)
    for task in b.children:
        flag = flags[task.name]
        root.add_child(behaviours.UnsetBlackboardVariable(name=f"Clear\n{flag.rsplit('/', 1)[-1]}", key=flag))
    return root


def _oneshot_idiom(b: Build) -> Behaviour:
    variable = b.params["variable_name"]
    if variable is None:
        variable = f"{_slug(b.name)}_oneshot"
    return idioms.oneshot(
        behaviour=b.children[0], name=b.name, variable_name=b.key(variable), policy=ONESHOT_POLICIES[b.params["policy"]]
    )


IDIOMS = [
    NodeType(
        "either_or",
        "idiom",
        _either_or,
        {
            "conditions": Param(list, REQUIRED, doc=f"one per child: {_COMPARISON_DOC}; their results are XOR-ed"),
            "namespace": Param(str, None, doc=f"where the locked-in choice is kept (default: <name>_conditions); {_KEY}",
                               key=True, nullable=True),
        },
        "Run the child whose condition holds (the conditions are XOR-ed), first come first served, until it completes.",
        "many",
        cls=None,
    ),
    NodeType(
        "pick_up_where_you_left_off",
        "idiom",
        _pick_up_where_you_left_off,
        {},
        "A sequence of tasks that, when interrupted and re-entered, skips the tasks already done.",
        "many",
        cls=None,
    ),
    NodeType(
        "oneshot",
        "idiom",
        _oneshot_idiom,
        {
            "variable_name": Param(str, None, doc=f"flag recording completion (default: <name>_oneshot); {_KEY}",
                                   key=True, nullable=True),
            "policy": Param(str, "on_successful_completion", doc="which finish is final: any (on_completion) or SUCCESS only",
                            choices=tuple(ONESHOT_POLICIES)),
        },
        "Run the child through to completion once (a blackboard flag remembers); then return its final status.",
        "one",
        cls=None,
    ),
]


BUILTINS = [*COMPOSITES, *DECORATORS, *BEHAVIOURS, *IDIOMS]
