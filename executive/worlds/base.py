"""The world backend seam: what the mission runner asks of a kind of world.

A backend builds its world from a scenario's ``world:`` mapping, makes the robots
and the radio, senses each step, measures coverage and adds its figures and its map
to the outputs. The runner holds one backend and never asks which kind it is.

A backend registers itself with :func:`delve.executive.worlds.register_world`; a
scenario's ``world:`` mapping picks the first backend that :meth:`claims` it.
"""
from __future__ import annotations

import inspect
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

import numpy as np

from ...skills.base import short_repr
from ..errors import DelveError, did_you_mean
from ..yamlio import YamlDict

if TYPE_CHECKING:
    from ...skills.base import AgentContext
    from ...sim.clock import SimClock
    from ..runner import Mission
    from ..scenario import Scenario

#: The base station's agent and radio name.
BASE = "base"


@dataclass(frozen=True)
class Coverage:
    """Explored fractions at one moment: the team's, the base station's, each robot's."""

    team: float
    base: float
    robots: dict[str, float]


@dataclass(frozen=True)
class TeamNetwork:
    """The mobility-communication network a team starts on (for planned
    communication): each robot's ``NetworkView``, each robot's start location, the
    base station's location and the topology known at the start."""

    views: dict[str, Any]
    team: dict[str, str]
    base_location: str
    initial_topology: dict[str, Any]


@dataclass
class WorldDescription:
    """What ``delve world`` prints and ``delve run`` prints first: ``lines`` (the
    world's figures and where each start lands), ``warnings`` (one line each, with
    the file and line of the key at fault), ``errors`` (what stops a run: a start in
    rock, say) and ``starts`` (robot name -> the ground point it starts on)."""

    lines: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    errors: list[DelveError] = field(default_factory=list)
    starts: dict[str, list[float]] = field(default_factory=dict)


class WorldBackend(ABC):
    """One kind of world, made runnable for one mission.

    An instance holds ``world``, ``robots`` (name -> robot implementing the robot
    interface, plus ``step``, ``park``, ``jam`` and ``kill``), ``radio`` (its
    ``endpoints``, ``update()`` and ``linked(a, b)``) and ``base_position``.
    """

    #: The ``world:`` keys that make a scenario's world this backend's.
    KEYS: ClassVar[tuple[str, ...]] = ()
    #: What the coverage plot's fraction counts.
    COVERAGE_LABEL: ClassVar[str] = "fraction explored"
    #: Fault kinds this world cannot inject (``faults:`` in a scenario; a fault kind
    #: may also name the worlds it applies to, ``Fault.WORLDS``).
    UNSUPPORTED_FAULTS: ClassVar[tuple[str, ...]] = ()
    #: Whether a scenario on this world may hide artifacts (``artifacts:``).
    ARTIFACTS: ClassVar[bool] = False

    world: Any
    robots: dict[str, Any]
    radio: Any
    base_position: np.ndarray

    # ---- scenario time ------------------------------------------------------------
    @classmethod
    @abstractmethod
    def claims(cls, world: Mapping[str, Any]) -> bool:
        """Whether a scenario's ``world:`` mapping describes a world of this kind."""

    @classmethod
    @abstractmethod
    def generators(cls) -> dict[str, Any]:
        """The world generators of this kind by name (their keyword parameters are
        the ``world:`` keys a scenario may give with them)."""

    @classmethod
    def check(cls, doc: YamlDict, path: Path, has_base_tree: bool) -> None:
        """Check what the scenario ``doc`` asks of this world (its ``world:``
        parameters, ``radio:`` keys, base station); a :class:`DelveError` if wrong."""
        world = doc["world"]
        if "generator" in world:
            params = inspect.signature(cls.generators()[world["generator"]]).parameters
            only_keys(world, ("generator", *params), "world: unknown parameter", path)

    @classmethod
    @abstractmethod
    def build_world(cls, scenario: "Scenario", seed: int) -> Any:
        """Generate or load the world; a :class:`DelveError` when its parameters are
        wrong. A generator without its own ``seed`` takes ``seed``."""

    @classmethod
    def describe(cls, scenario: "Scenario", world: Any) -> WorldDescription:
        """The world's figures, where each start lands, and what looks wrong (without
        making robots). The default names the kind of world only."""
        return WorldDescription(lines=[f"world {scenario.name}: a {cls.__name__} world"])

    @classmethod
    def preview(cls, scenario: "Scenario", world: Any, out: Path) -> list[Path]:
        """Write pictures of the world (a top-down and a side view, with the starts)
        into the folder ``out``; the files written."""
        raise DelveError(f"this world ({cls.__name__}) draws no preview")

    # ---- a mission ----------------------------------------------------------------
    @abstractmethod
    def __init__(self, scenario: "Scenario", world: Any, seed: int, clock: "SimClock"):
        """Make the radio, the robots of ``scenario`` and the base station's radio."""

    @abstractmethod
    def base_services(self) -> dict[str, Any]:
        """The base station agent's services: at least its ``radio``."""

    def sense(self, now_s: float) -> None:
        """Run the robots' sensors that are due at ``now_s``."""

    @abstractmethod
    def coverage(self, explored_at_base: set[str]) -> Coverage:
        """Explored fractions now. ``explored_at_base``: locations the team strategy
        says the base station knows to be explored (worlds of locations count them)."""

    def network(self, contexts: dict[str, AgentContext], cell_m: float) -> TeamNetwork:
        """The team's start on a mobility-communication network (for planned
        communication): ``contexts`` are the robots' agent contexts, ``cell_m`` the
        size of a location where the world must cut its space into locations. Worlds
        that cannot give one raise a :class:`DelveError`."""
        raise DelveError(f"this world ({type(self).__name__}) has no mobility-communication network")

    def figures(self, mission: "Mission") -> dict[str, Any]:
        """The report's figures of this world (before the team strategy's)."""
        return {}

    def robot_figures(self, name: str, lost: "Mapping[str, str]") -> dict[str, Any]:
        """The report's extra figures of robot ``name`` (``lost``: the robots lost and why)."""
        return {}

    def map_undelivered(self, name: str) -> int | None:
        """Voxels robot ``name`` mapped that the base station's map does not hold;
        None on worlds without maps."""
        return None

    @abstractmethod
    def plot_map(self, mission: "Mission", path: Path) -> None:
        """Write the top-down map of the run to ``path`` (PNG)."""


def only_keys(mapping: YamlDict, allowed: tuple[str, ...], what: str, path: Path) -> None:
    """A :class:`DelveError` at the first key of ``mapping`` not in ``allowed``."""
    for key in mapping:
        if key not in allowed:
            raise DelveError(f"{what} {short_repr(key)}{did_you_mean(str(key), allowed)}", path, mapping.key_line(key))
