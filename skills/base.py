"""What every skill shares: parameter specs, the agent context and the Skill base class.

A skill is a py_trees behaviour that a YAML tree names by ``type``. It declares its
parameters in ``PARAMS`` (name -> :class:`Param`, units in the names: ``timeout_s``);
the executive's loader checks a YAML node against them before it constructs the skill
with the checked, defaulted values as keyword arguments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Protocol

import py_trees

from .robot import Robot


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


#: Default of a parameter that a YAML node must give.
REQUIRED: Any = _Required()


@dataclass(frozen=True)
class Param:
    """A declared parameter of a behaviour: type, default, bounds and meaning.

    ``type`` is one of ``float``, ``int``, ``bool``, ``str``, ``list``, ``dict`` (an
    ``int`` is accepted where a ``float`` is asked). ``key=True`` marks a blackboard
    key name, which subtree includes remap and agents prefix with their namespace.
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

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def problem(self, value: Any) -> str | None:
        """Return why ``value`` is not acceptable, or None when it is."""
        if value is None:
            return None if self.nullable else "must not be null"
        if self.type is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                return f"must be a number, not {type(value).__name__} {value!r}"
            if math.isnan(value):
                return "must be a number, not NaN"
            if math.isinf(value) and self.maximum is not None:
                return "must be finite"
        elif self.type is int:
            if isinstance(value, bool) or not isinstance(value, int):
                return f"must be an integer, not {type(value).__name__} {value!r}"
        elif not isinstance(value, self.type) or (self.type is not bool and isinstance(value, bool)):
            return f"must be of type {self.type.__name__}, not {type(value).__name__} {value!r}"
        if self.minimum is not None and value < self.minimum:
            return f"must be >= {self.minimum}, got {value}"
        if self.exclusive_minimum is not None and value <= self.exclusive_minimum:
            return f"must be > {self.exclusive_minimum}, got {value}"
        if self.maximum is not None and value > self.maximum:
            return f"must be <= {self.maximum}, got {value}"
        if self.choices is not None and value not in self.choices:
            return f"must be one of {', '.join(map(repr, self.choices))}, got {value!r}"
        return None


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

    Subclasses declare ``PARAMS`` and read them from ``self.p`` (a dict). They reach
    the blackboard through :meth:`key`, which applies remapping and the namespace.
    """

    PARAMS: ClassVar[dict[str, Param]] = {}

    def __init__(self, name: str, ctx: AgentContext, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name)
        self.ctx = ctx
        self.remap = dict(remap or {})
        self.p: dict[str, Any] = {k: spec.default for k, spec in self.PARAMS.items() if not spec.required}
        self.p.update(params)
        self.bb = self.attach_blackboard_client(name=name)

    def key(self, key: str, access: py_trees.common.Access = py_trees.common.Access.WRITE) -> str:
        """Register ``key`` for this behaviour and return its full name."""
        full = resolve_key(key, self.ctx.namespace, self.remap)
        self.bb.register_key(key=full, access=access)
        return full

    def get(self, full_key: str, default: Any = None) -> Any:
        """Read a registered key, ``default`` when it was never written."""
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
