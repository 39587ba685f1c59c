"""What every skill shares: parameter specs, the agent context and the Skill base class.

A skill is a py_trees behaviour that a YAML tree names by ``type``. It declares its
parameters in ``PARAMS`` (name -> :class:`Param`, units in the names: ``timeout_s``);
the executive's loader checks a YAML node against them before it constructs the skill
with the checked, defaulted values as keyword arguments. It declares the blackboard
keys it reads and writes in ``INPUT_PORTS`` and ``OUTPUT_PORTS`` (name ->
:class:`py_trees.ports.PortInformation`), from which :class:`Skill` registers each key
with its access, and from which the node reference and the tree schema list them.
"""

from __future__ import annotations

import copy
import math
import re
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Protocol

import py_trees
import yaml
from py_trees.common import Access
from py_trees.ports import PortInformation

from .robot import Robot


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


#: Default of a parameter that a YAML node must give.
REQUIRED: Any = _Required()


#: An error message quotes at most this many characters of a user's value.
SHOWN_CHARS = 40
_NUMBER_LIKE = re.compile(r"[-+]?(?:[0-9][0-9_]*)?(?:\.[0-9_]*)?(?:[eE][-+]?[0-9]+)?")


def short_repr(value: Any, limit: int = SHOWN_CHARS) -> str:
    """``repr(value)`` cut to about ``limit`` characters (``...`` marks the cut), so
    that an error message never quotes more of a file than the offending value's start."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 3 * limit:
        return f"<an integer of {len(str(abs(value)))} digits>" if value.bit_length() < 12000 else "<a huge integer>"
    text = repr(value)
    if len(text) <= limit:
        return text
    end = text[0] if isinstance(value, str) and text[0] in "'\"" else ""
    return text[:limit] + "..." + end


def yaml_number_hint(value: Any, integer: bool = False) -> str:
    """For a string that reads as a number, what to write instead: YAML 1.1 reads
    ``1e3`` as a string (its floats need a dot and a signed exponent: ``1.0e+3``), and
    a quoted number is a string; '' for any other value."""
    if not isinstance(value, str) or not _NUMBER_LIKE.fullmatch(value.strip()) or not any(c.isdigit() for c in value):
        return ""
    text = value.strip()
    try:
        number = float(text)
    except ValueError:
        return ""
    if not math.isfinite(number) or (number == 0 and re.search(r"[1-9]", text.lower().partition("e")[0])):
        return ""  # beyond a float's range
    if isinstance(yaml.safe_load(text), (int, float)):
        return " (a number in quotes is a string: write it without quotes)"
    forms = []
    if number.is_integer() and abs(number) < 1e15:
        forms.append(str(int(number)))
    elif integer:
        return ""
    elif 1e-4 <= abs(number) < 1e15:
        forms.append(repr(number))
    if not integer:
        digits = next(p for p in range(17) if float(f"{number:.{p}e}") == number or p == 16)
        mantissa, exponent = f"{number:.{max(digits, 1)}e}".split("e")
        forms.append(f"{mantissa}e{'+' if int(exponent) >= 0 else '-'}{abs(int(exponent))}")
    return f" (YAML reads {short_repr(text)[1:-1]} as a string: write {' or '.join(forms)})"


def _fits_float(value: int) -> bool:
    try:
        float(value)
    except OverflowError:
        return False
    return True


#: A blackboard key as a tree names it: names of letters, digits and _ joined by '/'
#: (a leading '/' makes it shared by all agents) or '.' (an attribute of a key).
KEY_PATTERN = re.compile(r"/?[A-Za-z0-9_]+(?:[/.][A-Za-z0-9_]+)*")
KEY_RULE = "names of letters, digits and _ joined by '/', or '.' for an attribute"


def _type_name(value: Any) -> str:
    """The plain type name of a YAML value: a list or mapping read with its lines
    (the loader's subclasses) is a ``list`` or ``dict``."""
    for plain in (bool, int, float, str, list, dict):
        if isinstance(value, plain):
            return plain.__name__
    return type(value).__name__


# delve keeps its own Param for a node's YAML parameters: py_trees' PortInformation
# (type, required, description, default) has no bounds, choices, null-ability or key
# marking, and the tree loader needs those to check a YAML node (with its file and
# line) before the behaviour is built, and the schema needs them for its bounds. Ports
# declare blackboard keys only (Skill.INPUT_PORTS / OUTPUT_PORTS).
@dataclass(frozen=True)
class Param:
    """A declared parameter of a behaviour: type, default, bounds and meaning.

    ``type`` is one of ``float``, ``int``, ``bool``, ``str``, ``list``, ``dict`` (an
    ``int`` is accepted where a ``float`` is asked). ``key=True`` marks a blackboard
    key name, which subtree includes remap and agents prefix with their namespace
    (a port declared with :class:`ParamNamedPort` says which key it names).
    """

    type: type
    default: Any = REQUIRED
    doc: str = ""
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: float | None = None
    choices: tuple[Any, ...] | None = None
    key: bool = False
    nullable: bool = False
    #: For a list: how many items it must have, and their type (``float``: finite
    #: numbers; ``str``, ...), or None for any.
    length: int | None = None
    items: type | None = None

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def problem(self, value: Any) -> str | None:
        """Return why ``value`` is not acceptable, or None when it is."""
        if value is None:
            return None if self.nullable else "must not be null"
        shown = f"{_type_name(value)} {short_repr(value)}"
        if self.type is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                return f"must be a number, not {shown}{yaml_number_hint(value)}"
            if isinstance(value, int) and not _fits_float(value):
                return f"must be a number within +-1.8e308, not {shown}"
            if math.isnan(value):
                return "must be a number, not NaN"
            if math.isinf(value):  # no duration, distance or rate of a tree is endless
                return f"must be a finite number, not {value}"
        elif self.type is int:
            if isinstance(value, bool) or not isinstance(value, int):
                return f"must be an integer, not {shown}{yaml_number_hint(value, integer=True)}"
        elif not isinstance(value, self.type) or (self.type is not bool and isinstance(value, bool)):
            return f"must be of type {self.type.__name__}, not {shown}"
        if self.key and isinstance(value, str) and not KEY_PATTERN.fullmatch(value):
            return f"must be a blackboard key ({KEY_RULE}), not {short_repr(value)}"
        if self.type is list:
            return self._list_problem(value)
        if self.minimum is not None and value < self.minimum:
            return f"must be >= {self.minimum}, got {short_repr(value)}"
        if self.exclusive_minimum is not None and value <= self.exclusive_minimum:
            return f"must be > {self.exclusive_minimum}, got {short_repr(value)}"
        if self.maximum is not None and value > self.maximum:
            return f"must be <= {self.maximum}, got {short_repr(value)}"
        if self.choices is not None and value not in self.choices:
            return f"must be one of {', '.join(map(repr, self.choices))}, got {short_repr(value)}"
        return None


    def _list_problem(self, value: list) -> str | None:
        if self.length is not None and len(value) != self.length:
            what = f"{self.length} numbers" if self.items is float else f"{self.length} items"
            return f"must be a list of {what}, not {len(value)}: {short_repr(value)}"
        if self.items is float:
            for i, item in enumerate(value):
                if isinstance(item, bool) or not isinstance(item, (int, float)):
                    return (f"item {i} must be a number, not {_type_name(item)} {short_repr(item)}"
                            f"{yaml_number_hint(item)}")
                if isinstance(item, int) and not _fits_float(item):
                    return f"item {i} must be a number within +-1.8e308, not {short_repr(item)}"
                if not math.isfinite(item):
                    return f"item {i} must be a finite number, not {item}"
        elif self.items is not None:
            for i, item in enumerate(value):
                if not isinstance(item, self.items) or isinstance(item, bool) and self.items is not bool:
                    return f"item {i} must be of type {self.items.__name__}, not {short_repr(item)}"
        return None


@dataclass(frozen=True)
class ParamNamedPort(PortInformation):
    """A port whose blackboard key a YAML parameter names: the key is the value of
    ``key_param`` (a ``Param(str, ..., key=True)`` of the skill), not the port's name;
    a null value means the skill uses no key there. Remapping and the namespace apply
    to that value as to any key."""

    key_param: str = ""

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.key_param:
            raise ValueError("ParamNamedPort needs key_param, the parameter that names the key")


def port_key_param(port: PortInformation) -> str | None:
    """The parameter that names ``port``'s key, or None when the key is the port's name."""
    return port.key_param if isinstance(port, ParamNamedPort) else None


class Clock(Protocol):
    """The simulation clock (or, on a robot, the mission clock)."""

    @property
    def now_s(self) -> float: ...


EventLog = Callable[..., None]
"""``log(event, **fields)`` appends one event to the run's log."""


@dataclass
class AgentContext:
    """What a skill may reach: its agent's name, blackboard namespace, clock, robot and log.

    ``robot`` is None for the base station. ``services`` holds agent-wide helpers a
    later skill may need (for example a message outbox) by name.
    """

    name: str
    namespace: str
    clock: Clock
    log: EventLog
    robot: Robot | None = None
    params: dict[str, Any] = field(default_factory=dict)
    services: dict[str, Any] = field(default_factory=dict)


#: ``ctx.services`` key of the agent's :class:`Mailbox`.
MAILBOX = "mailbox"
#: Messages a mailbox keeps of one kind that no behaviour takes (the oldest go first).
MAILBOX_LIMIT = 1000


class Mailbox:
    """An agent's delivered messages sorted by kind, so that several behaviours can
    each take their own: the radio's ``receive()`` hands every message out once, and
    a behaviour that took them all would lose the others' messages. Each
    :meth:`take` first moves what the radio delivered since into per-kind queues."""

    def __init__(self, radio: Any):
        self.radio = radio
        self.queues: dict[str, deque[Any]] = {}
        #: Kinds that some behaviour takes by name (see :meth:`take_unclaimed`).
        self.claimed: set[str] = set()

    def claim(self, kind: str) -> None:
        """Say, when a behaviour is built, that it takes messages of ``kind``."""
        self.claimed.add(kind)

    def take(self, kind: str) -> list[Any]:
        """The messages of ``kind`` delivered and not yet taken, oldest first."""
        self._sort()
        queue = self.queues.get(kind)
        out = list(queue) if queue else []
        if queue:
            queue.clear()
        return out

    def take_unclaimed(self) -> list[Any]:
        """The messages of every kind no behaviour claimed, in kind order then oldest
        first (for a behaviour that logs what nobody else handles)."""
        self._sort()
        return [msg for kind in sorted(self.queues) if kind not in self.claimed for msg in self.take(kind)]

    def _sort(self) -> None:
        for msg in self.radio.receive():
            self.queues.setdefault(msg.kind, deque(maxlen=MAILBOX_LIMIT)).append(msg)


def mailbox(ctx: AgentContext, radio: Any) -> Mailbox:
    """The agent's :class:`Mailbox` on ``radio`` (created on first use, in ``ctx.services``)."""
    box = ctx.services.get(MAILBOX)
    if box is None or box.radio is not radio:
        box = ctx.services[MAILBOX] = Mailbox(radio)
    return box


def resolve_key(key: str, namespace: str, remap: dict[str, str] | None = None) -> str:
    """Blackboard key as registered: remapped by subtree includes, then put under the
    agent's namespace unless it is absolute (starts with ``/``)."""
    if remap:
        key = remap.get(key, key)
    if key.startswith("/"):
        return key
    return f"{namespace.rstrip('/')}/{key}"


class Skill(py_trees.behaviour.Behaviour):
    """Base of delve's behaviours: holds the agent context and checked parameters.

    Subclasses declare ``PARAMS`` and read them from ``self.p`` (a dict). They declare
    the blackboard keys they read in ``INPUT_PORTS`` and those they write in
    ``OUTPUT_PORTS`` (port name -> py_trees' :class:`~py_trees.ports.PortInformation`;
    the port's name is the key, or, for a :class:`ParamNamedPort`, the value of the
    parameter that names the key). A key both read and written is declared in both.

    At construction every declared key is resolved (include remaps, then the agent's
    namespace) and registered on the skill's blackboard client: inputs for READ,
    outputs for WRITE (which also reads). py_trees' client then refuses a write to an
    input and any access to an undeclared key. Skills use :meth:`read` and
    :meth:`write` by port name; ``self.keys`` holds the full keys by port name.
    """

    PARAMS: ClassVar[dict[str, Param]] = {}
    INPUT_PORTS: ClassVar[dict[str, PortInformation]] = {}
    OUTPUT_PORTS: ClassVar[dict[str, PortInformation]] = {}
    #: The agent whose tree the skill belongs in: ``"robot"`` (it needs one), ``"base"``
    #: (it reads the base station's services) or None (either); a scenario that puts it
    #: in the other kind's tree is refused when it is loaded.
    AGENT: ClassVar[str | None] = "robot"

    # The declarations are py_trees' own (PortInformation in INPUT_PORTS/OUTPUT_PORTS),
    # but the keys are not wired through PortsMixin.setup_ports: a port nobody remaps
    # gets a key of its own node there (namespace/name_uuid/port), while delve's skills
    # share agent-wide keys (/anymal/goal, written by one node, read by another) named
    # by YAML parameters and include remaps; get_input() raises on a stored None and
    # _set_output(None) fails its type check, while delve writes None to mean "cleared"
    # (goto_failure, the operator's keys); and a key both read and written would have to
    # be two ports with different names. So Skill registers the keys itself.

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name)
        self.ctx = ctx
        self.remap = dict(remap or {})
        self.p: dict[str, Any] = {k: spec.default for k, spec in self.PARAMS.items() if not spec.required}
        self.p.update(params)
        self.bb = self.attach_blackboard_client(name=name)
        self.keys: dict[str, str] = {}
        for port in {**self.INPUT_PORTS, **self.OUTPUT_PORTS}:
            key = self.port_key(port)
            if key is None:
                continue
            self.keys[port] = resolve_key(key, self.ctx.namespace, self.remap)
            access = Access.WRITE if port in self.OUTPUT_PORTS else Access.READ
            self.bb.register_key(key=self.keys[port], access=access)

    def port_key(self, port: str) -> str | None:
        """The key of ``port`` as the tree names it (before remap and namespace): the
        port's name, or the value of the parameter that names it (None: no key)."""
        info = self.INPUT_PORTS.get(port) or self.OUTPUT_PORTS[port]
        param = port_key_param(info)
        return port if param is None else self.p.get(param) or None

    def read(self, port: str, default: Any = None) -> Any:
        """The value of input ``port``; ``default`` (else the port's declared
        ``default_value``) when the key was never written or no key is named."""
        if port not in self.INPUT_PORTS:
            raise KeyError(f"{type(self).__name__} declares no input port {port!r} (INPUT_PORTS)")
        if default is None:
            default = copy.deepcopy(self.INPUT_PORTS[port].default_value)
        full = self.keys.get(port)
        return default if full is None else self.get(full, default)

    def write(self, port: str, value: Any) -> None:
        """Write ``value`` to output ``port``."""
        if port not in self.OUTPUT_PORTS:
            raise KeyError(f"{type(self).__name__} declares no output port {port!r} (OUTPUT_PORTS)")
        self.bb.set(self.keys[port], value)

    def get(self, full_key: str, default: Any = None) -> Any:
        """Read a registered key (full name), ``default`` when it was never written."""
        try:
            return self.bb.get(full_key)
        except KeyError:
            return default

    def follow(self, path: Any) -> None:
        """Command the robot along ``path`` and remember that this behaviour did."""
        self.robot.follow_path(path)
        self._command_id = self.robot.command_id

    def stop_own_motion(self) -> None:
        """Stop the robot if it still follows this behaviour's last command (a
        behaviour stopped because another took over must not cancel the newcomer's
        command, which py_trees issues before it stops the old one)."""
        if self.ctx.robot is not None and getattr(self, "_command_id", None) == self.robot.command_id:
            self.robot.stop()

    def event(self, event: str, **fields: Any) -> None:

        """Log an event of this behaviour with the agent's name and the sim time."""
        self.ctx.log(event, agent=self.ctx.name, node=self.name, **fields)

    @property
    def robot(self) -> Robot:
        if self.ctx.robot is None:
            raise RuntimeError(f"{type(self).__name__} needs a robot; agent {self.ctx.name} has none")
        return self.ctx.robot
