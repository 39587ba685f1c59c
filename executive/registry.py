"""The node types a YAML tree may name, and how each is built.

Every type has a YAML name, a kind (``composite``, ``decorator``, ``behaviour``,
``idiom`` or ``skill``), declared parameters (:class:`~delve.skills.base.Param`, units in
the names), how many children it takes, and a builder that turns checked parameters
and built children into a py_trees behaviour.

:func:`default_registry` offers py_trees' composites, decorators, behaviours and idioms,
delve's sim-clock ``Timer`` and ``Timeout`` (py_trees' wall-clock timers are not
reachable under any name), and every skill of :func:`delve.skills.all_skills`.

Blackboard key parameters (``key=True``) of py_trees' built-ins are resolved with
:func:`~delve.skills.base.resolve_key`, so each agent has its own namespace and subtree
includes can remap them; skills resolve their own keys the same way.

:func:`tree_schema` derives the JSON Schema of tree files from the registry; the
shipped copy is regenerated with ``python -m delve.executive.registry --write-schema``.
"""
from __future__ import annotations

import argparse
import inspect
import json
import math
import operator
import re
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

from py_trees import behaviours, common, composites, decorators, idioms
from py_trees.behaviour import Behaviour

from ..skills import all_skills
from ..skills.base import REQUIRED, AgentContext, Param, Skill, resolve_key
from ..skills.timing import Timeout as SimTimeout
from .errors import DelveError, did_you_mean
from .yamlio import YamlDict, YamlList, plain

__all__ = [
    "KINDS",
    "RESERVED_KEYS",
    "SCHEMA_PATH",
    "AnyParam",
    "Build",
    "NodeType",
    "Registry",
    "Site",
    "coerce_param",
    "default_registry",
    "tree_schema",
]

KINDS = ("composite", "decorator", "behaviour", "idiom", "skill")

#: Keys of a node that are not parameters.
RESERVED_KEYS = frozenset({"type", "name", "children", "child", "include", "remap"})

SCHEMA_PATH = Path(__file__).resolve().parent / "schema" / "tree.schema.json"
SCHEMA_COMMAND = "python -m delve.executive.registry --write-schema"

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


def coerce_param(spec: Param, value: Any) -> Any:
    """A checked value as a builder receives it: ints given for floats become floats,
    YAML mappings and lists become plain dicts and lists."""
    if spec.type is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return plain(value)


# --------------------------------------------------------------------------- building


@dataclass
class Site:
    """Where a node came from, to point errors at the right line."""

    file: str | None = None
    node: Mapping[str, Any] | None = None
    node_name: str | None = None
    line: int | None = None

    def line_of(self, key: str | None = None, index: int | None = None) -> int | None:
        """Line of ``key`` of the node (of its item ``index`` when the value is a list)."""
        if key is None or not isinstance(self.node, YamlDict):
            return self.line
        value = self.node.get(key)
        if index is not None and isinstance(value, YamlList):
            item = value[index] if index < len(value) else None
            if isinstance(item, YamlDict) and item.line is not None:
                return item.line
            return value.item_line(index)
        return self.node.key_line(key)

    def fail(self, message: str, key: str | None = None, index: int | None = None) -> NoReturn:
        raise DelveError(message, self.file, self.line_of(key, index), self.node_name)


@dataclass
class Build:
    """What a builder receives: the node's name, checked parameters (defaults filled),
    built children and named subtrees, the agent context and the key remap."""

    name: str
    params: dict[str, Any]
    children: list[Behaviour]
    ctx: AgentContext
    remap: dict[str, str] = field(default_factory=dict)
    subtrees: dict[str, Behaviour] = field(default_factory=dict)
    given: frozenset[str] = frozenset()
    site: Site = field(default_factory=Site)

    def key(self, name: str) -> str:
        """Blackboard variable ``name`` (maybe nested: ``battery.percentage``) resolved
        for this agent: remapped, then under the agent's namespace unless absolute."""
        if name in self.remap:
            return resolve_key(name, self.ctx.namespace, self.remap)
        head, dot, rest = name.partition(".")
        return resolve_key(head, self.ctx.namespace, self.remap) + dot + rest

    def fail(self, message: str, key: str | None = None, index: int | None = None) -> NoReturn:
        self.site.fail(message, key, index)


Builder = Callable[[Build], Behaviour]


@dataclass(frozen=True)
class NodeType:
    """A node type that YAML trees name by ``type``.

    ``arity`` is how many children it takes: ``none`` (a leaf), ``one`` (``child``, or
    ``children`` with one element) or ``many`` (``children``, at least one).
    ``subtrees`` names extra single-node slots (EternalGuard's ``condition``).
    """

    name: str
    kind: str
    build: Builder
    params: Mapping[str, Param] = field(default_factory=dict)
    doc: str = ""
    arity: str = "none"
    subtrees: Mapping[str, str] = field(default_factory=dict)
    cls: type | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"node type {self.name!r}: unknown kind {self.kind!r}")
        if self.arity not in ("none", "one", "many"):
            raise ValueError(f"node type {self.name!r}: unknown arity {self.arity!r}")
        clash = (set(self.params) | set(self.subtrees)) & RESERVED_KEYS
        if clash or set(self.params) & set(self.subtrees):
            raise ValueError(f"node type {self.name!r}: parameter names {sorted(clash)} are reserved")


class Registry:
    """Node types by YAML name."""

    def __init__(self, types: Iterable[NodeType] = ()):
        self._types: dict[str, NodeType] = {}
        for t in types:
            self.add(t)

    def add(self, node_type: NodeType) -> None:
        if node_type.name in self._types:
            old = self._types[node_type.name]
            raise ValueError(
                f"node type {node_type.name!r} is registered twice ({old.kind} {old.cls} and "
                f"{node_type.kind} {node_type.cls}); give one a different TYPE_NAME"
            )
        self._types[node_type.name] = node_type

    def get(self, name: str) -> NodeType | None:
        return self._types.get(name)

    def __getitem__(self, name: str) -> NodeType:
        return self._types[name]

    def __contains__(self, name: object) -> bool:
        return name in self._types

    def __iter__(self) -> Iterator[NodeType]:
        return iter(self._types.values())

    def __len__(self) -> int:
        return len(self._types)

    def names(self, kind: str | None = None) -> list[str]:
        """Sorted YAML names, of one kind if given."""
        return sorted(n for n, t in self._types.items() if kind is None or t.kind == kind)

    def suggest(self, name: str) -> str:
        """`` (did you mean 'X'?)`` for an unknown name, or ''."""
        return did_you_mean(name, self._types)


# --------------------------------------------------------------------------- helpers


def _first_paragraph(obj: Any) -> str:
    doc = inspect.getdoc(obj) or ""
    return " ".join(doc.split("\n\n")[0].split())


def _slug(text: str) -> str:
    return re.sub(r"[^0-9a-z_]+", "_", text.lower()).strip("_") or "task"


_KEY = "blackboard variable (a.b for an attribute); under the agent's namespace unless it starts with '/', remapped by includes"
_COMPARISON_KEYS = {"variable_name", "value", "operator"}


def _comparison(b: Build, param: str, index: int, item: Any) -> common.ComparisonExpression:
    """A ``{variable_name, value, operator}`` mapping as a py_trees ComparisonExpression."""
    if not isinstance(item, dict):
        b.fail(f"'{param}' item {index + 1} must be a mapping with variable_name, value, operator", param, index)
    unknown = sorted(set(item) - _COMPARISON_KEYS)
    if unknown:
        b.fail(
            f"unknown key {unknown[0]!r} in '{param}' item {index + 1}{did_you_mean(unknown[0], _COMPARISON_KEYS)}",
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
    if op not in OPERATORS:
        b.fail(
            f"'{param}' item {index + 1}: operator must be one of {', '.join(map(repr, OPERATORS))}, got {op!r}",
            param,
            index,
        )
    return common.ComparisonExpression(variable=b.key(var), value=item["value"], operator=OPERATORS[op])


def _comparisons(b: Build, param: str) -> list[common.ComparisonExpression]:
    return [_comparison(b, param, i, item) for i, item in enumerate(b.params[param])]


def _status_list(b: Build, param: str) -> list[common.Status]:
    out = []
    for i, item in enumerate(b.params[param]):
        if item not in STATUSES:
            b.fail(f"'{param}' item {i + 1} must be one of {', '.join(map(repr, STATUSES))}, got {item!r}", param, i)
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
                b.fail(f"two children are named {child.name!r}; 'selected' cannot tell them apart", "selected")
            by_name[child.name] = child
        chosen = []
        for i, child_name in enumerate(selected):
            if child_name not in by_name:
                b.fail(
                    f"'selected' names no child {child_name!r}{did_you_mean(str(child_name), by_name)}",
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
    return NodeType(name, "decorator", build, params or {}, doc or _first_paragraph(cls), "one", cls=cls, **kw)


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
    return NodeType(name, "behaviour", build, params or {}, doc or _first_paragraph(cls), "none", cls=cls)


_OPERATOR = Param(str, "==", doc="comparison: variable OPERATOR value", choices=tuple(OPERATORS))
_COMPARISON_DOC = "comparisons, each a mapping {variable_name, value, operator (default ==)}"

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
        {
            "variable_name": Param(str, REQUIRED, doc=_KEY, key=True),
            "value": AnyParam(default=REQUIRED, nullable=True, doc="value to compare the variable with (null: unset)"),
            "operator": _OPERATOR,
        },
        "SUCCESS if 'variable OPERATOR value' holds, FAILURE if not or if the variable is missing.",
    ),
    _behaviour(
        "WaitForBlackboardVariableValue", _check_value(behaviours.WaitForBlackboardVariableValue),
        behaviours.WaitForBlackboardVariableValue,
        {
            "variable_name": Param(str, REQUIRED, doc=_KEY, key=True),
            "value": AnyParam(default=REQUIRED, nullable=True, doc="value to compare the variable with (null: unset)"),
            "operator": _OPERATOR,
        },
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
            b.fail(f"children of pick_up_where_you_left_off need distinct names; {child.name!r} repeats", "children")
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


# --------------------------------------------------------------------------- skills


def _skill_builder(cls: type[Skill]) -> Builder:
    def build(b: Build) -> Behaviour:
        return cls(name=b.name, ctx=b.ctx, remap=b.remap, **b.params)

    return build


def skill_types(skills: Mapping[str, type[Skill]] | None = None) -> list[NodeType]:
    """Node types for ``skills`` (default: :func:`delve.skills.all_skills`)."""
    skills = all_skills() if skills is None else skills
    return [
        NodeType(name, "skill", _skill_builder(cls), dict(cls.PARAMS), _first_paragraph(cls), "none", cls=cls)
        for name, cls in sorted(skills.items())
    ]


_BUILTINS = [*COMPOSITES, *DECORATORS, *BEHAVIOURS, *IDIOMS]
_cache: tuple[tuple[tuple[str, type], ...], Registry] | None = None


def default_registry() -> Registry:
    """The registry of py_trees' built-ins, delve's sim-clock timers and every skill
    of :func:`delve.skills.all_skills` (rebuilt when the set of skills changes)."""
    global _cache
    skills = all_skills()
    signature = tuple(sorted(skills.items(), key=lambda item: item[0]))
    if _cache is None or _cache[0] != signature:
        _cache = (signature, Registry([*_BUILTINS, *skill_types(skills)]))
    return _cache[1]


# --------------------------------------------------------------------------- schema

_JSON_TYPES = {float: "number", int: "integer", bool: "boolean", str: "string", list: "array", dict: "object"}


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
    if spec.choices is not None:
        out["enum"] = [*spec.choices, *([None] if spec.nullable else [])]
    if not spec.required and _json_serialisable(spec.default):
        out["default"] = spec.default
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


def write_schema(path: Path = SCHEMA_PATH) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(schema_text(), encoding="utf-8")
    return path


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


DOCS_PATH = Path(__file__).resolve().parent.parent / "docs" / "nodes.md"


def reference_markdown(registry: Registry | None = None) -> str:
    """The node reference (docs/nodes.md): every node type with its parameters."""
    registry = default_registry() if registry is None else registry
    out = ["# Node reference", "",
           "Every node type a YAML tree can name. Generated from the registry by "
           "`python -m delve.executive.registry --write-docs`; do not edit by hand.", ""]
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m delve.executive.registry", description=__doc__.split("\n")[0])
    parser.add_argument("--write-schema", action="store_true", help=f"regenerate {SCHEMA_PATH.name}")
    parser.add_argument("--write-docs", action="store_true", help="regenerate docs/nodes.md")
    parser.add_argument("--list", action="store_true", help="list node types and their parameters")
    args = parser.parse_args(argv)
    if args.write_schema:
        print(f"wrote {write_schema()}")
    if args.write_docs:
        DOCS_PATH.parent.mkdir(parents=True, exist_ok=True)
        DOCS_PATH.write_text(reference_markdown(), encoding="utf-8")
        print(f"wrote {DOCS_PATH}")
    if args.list or not (args.write_schema or args.write_docs):
        print(describe())
    return 0



if __name__ == "__main__":
    sys.exit(main())
