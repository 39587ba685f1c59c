"""The fault seam: one small class per kind of fault a scenario can inject.

A fault kind declares whom it targets (a robot, a radio link between two agents, the
base station), whether it can end (``duration_s``), its own parameters (``PARAMS``,
checked when the scenario is loaded) and the world backends it applies to. The
mission runner calls :meth:`Fault.start` at ``at_s``, :meth:`Fault.step` at every
step while the fault lasts and :meth:`Fault.end` at ``at_s + duration_s``; it never
asks which kind it has.

A new kind subclasses :class:`Fault` and calls
:func:`delve.executive.faults.register_fault` (see docs/extending.md).
"""
from __future__ import annotations

from abc import ABC, abstractmethod

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...skills.base import Param

if TYPE_CHECKING:
    from pathlib import Path

    from ..runner import Mission
    from ..scenario import RobotSpec
    from ..worlds import WorldBackend
    from ..yamlio import YamlDict

#: What a fault may target (the YAML key that names it).
ROBOT, LINK, BASE_STATION = "robot", "link", "base_station"
#: Whether a kind takes ``duration_s``.
REQUIRED, OPTIONAL, NEVER = "required", "optional", "never"


@dataclass(frozen=True)
class Target:
    """Whom a fault hits: ``kind`` is ``robot`` (``names``: the robot), ``link``
    (the two agents, ``base`` for the base station, sorted) or ``base_station``."""

    kind: str
    names: tuple[str, ...] = ()

    @property
    def robot(self) -> str | None:
        return self.names[0] if self.kind == ROBOT else None

    def fields(self) -> dict[str, Any]:
        """The target as event fields (``robot``, ``link`` or ``base_station``)."""
        if self.kind == ROBOT:
            return {"robot": self.names[0]}
        if self.kind == LINK:
            return {"link": list(self.names)}
        return {"base_station": True}

    def __str__(self) -> str:
        return {ROBOT: lambda: self.names[0], LINK: lambda: " <-> ".join(self.names),
                BASE_STATION: lambda: "base station"}[self.kind]()


@dataclass(frozen=True)
class FaultContext:
    """What a kind may check its YAML entry against when the scenario is loaded."""

    path: "Path"
    robots: dict[str, "RobotSpec"]
    tree_types: dict[str, set[type]]
    backend: type["WorldBackend"]
    has_base_tree: bool


class Fault(ABC):
    """One fault of a scenario: a kind, a time, a target, maybe an end, parameters.

    Subclasses set ``KIND`` (the name a scenario gives), ``TARGETS`` (any of
    ``robot``, ``link``, ``base_station``), ``DURATION`` (``required``, ``optional``
    or ``never``), ``PARAMS`` and, when the kind needs a particular world, ``WORLDS``
    (names of registered world backends). Their docstring's first line is the kind's
    line in the docs.
    """

    KIND: ClassVar[str] = ""
    TARGETS: ClassVar[tuple[str, ...]] = (ROBOT,)
    DURATION: ClassVar[str] = NEVER
    PARAMS: ClassVar[dict[str, Param]] = {}
    #: World backends (registered names) the kind applies to; None: every world.
    WORLDS: ClassVar[tuple[str, ...] | None] = None

    def __init__(self, at_s: float, target: Target, duration_s: float | None = None, line: int | None = None,
                 **params: Any):
        self.at_s = float(at_s)
        self.target = target
        self.duration_s = None if duration_s is None else float(duration_s)
        self.line = line
        self.p: dict[str, Any] = {k: spec.default for k, spec in self.PARAMS.items() if not spec.required}
        self.p.update(params)

    # ---- the scenario ---------------------------------------------------------------
    @classmethod
    def check(cls, item: "YamlDict", target: Target, ctx: FaultContext) -> None:
        """Kind-specific checks of a YAML entry beyond targets, duration and
        parameters; raise a :class:`~delve.executive.errors.DelveError` at the key."""

    @property
    def robot(self) -> str | None:
        """The robot the fault targets (None for a link or the base station)."""
        return self.target.robot

    @property
    def end_s(self) -> float | None:
        """When the fault ends, or None when it does not."""
        return None if self.duration_s is None else self.at_s + self.duration_s

    def fields(self) -> dict[str, Any]:
        """The fault as event fields: kind, target, duration, parameters."""
        return {"kind": self.KIND, **self.target.fields(),
                **({"duration_s": self.duration_s} if self.duration_s is not None else {}), **self.p}

    # ---- the mission ----------------------------------------------------------------
    @abstractmethod
    def start(self, mission: "Mission") -> dict[str, Any]:
        """Inject the fault at ``at_s``; returns extra fields for its ``fault`` event."""

    def step(self, mission: "Mission", now_s: float) -> None:
        """Called at every step while the fault lasts (after :meth:`start`, until
        :meth:`end`, or to the end of the run for a fault without an end)."""

    def end(self, mission: "Mission") -> dict[str, Any]:
        """End the fault at ``at_s + duration_s``; returns extra fields for its
        ``fault_end`` event."""
        return {}

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(at_s={self.at_s}, target={self.target}, "
                f"duration_s={self.duration_s}, {self.p})")
