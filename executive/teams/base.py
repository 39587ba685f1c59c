"""The team strategy seam: how a team method plugs into a mission.

A strategy says which services the base station and the robots get, starts what it
needs once every agent exists, says when the mission is over and whether it
succeeded, and adds its figures to ``report.json``. A scenario picks one by name
(``team: {strategy: NAME, ...parameters}``); its parameters are declared in
``PARAMS`` and checked when the scenario is loaded.
"""
from __future__ import annotations

from abc import ABC
from typing import TYPE_CHECKING, Any, ClassVar

from py_trees.common import Status

from ...skills.base import Param
from ..worlds.height_bands import ALL_HEIGHTS, HeightBand

if TYPE_CHECKING:
    from ..agent import Agent
    from ..runner import Mission
    from ..scenario import Scenario


class TeamStrategy(ABC):
    """A team method. The default is every robot on its own: the mission is over when
    every robot's tree has finished, and it succeeded when each ended in SUCCESS
    (robots lost to a fault aside)."""

    #: The strategy's parameters (``team:`` keys besides ``strategy``).
    PARAMS: ClassVar[dict[str, Param]] = {}
    #: Report fields of this strategy that depend on the wall clock.
    WALL_CLOCK_FIELDS: ClassVar[tuple[str, ...]] = ()
    #: Events (besides every ``*_failed``) in which the strategy's behaviours say why
    #: they failed; the mission's outcome quotes them.
    FAILURE_EVENTS: ClassVar[tuple[str, ...]] = ()
    #: Whether the strategy needs a base station tree.
    NEEDS_BASE_TREE: ClassVar[bool] = False

    def __init__(self, **params: Any):
        self.params = {k: p.default for k, p in self.PARAMS.items() if not p.required} | params

    @classmethod
    def implied_by(cls, base_tree_types: set[type]) -> bool:
        """Whether a scenario without ``team:`` whose base station tree has nodes of
        ``base_tree_types`` meant this strategy (scenarios from before ``team:``)."""
        return False

    @classmethod
    def base_tree_problem(cls, base_tree_types: set[type]) -> str | None:
        """What the base station tree (nodes of ``base_tree_types``) lacks for this
        strategy, as one sentence; None when nothing."""
        return None

    @classmethod
    def check_world(cls, scenario: "Scenario", world: Any) -> None:
        """Check the strategy's parameters against the built world (its size, say); a
        :class:`~delve.executive.errors.DelveError` with the scenario's line if wrong."""

    def robot_services(self, name: str) -> dict[str, Any]:
        """Services of robot ``name``'s agent, given before its tree is built."""
        return {}

    def base_services(self) -> dict[str, Any]:
        """Services of the base station's agent, given before its tree is built."""
        return {}

    def start(self, mission: "Mission") -> None:
        """Called once every agent exists, before the first step."""

    def done(self, mission: "Mission") -> bool:
        """Whether the mission is over."""
        return all(a.finished for a in mission.robot_agents)

    def judged_agents(self, mission: "Mission") -> list["Agent"]:
        """The agents whose trees must end in SUCCESS: every robot's (robots lost to a
        fault or a flat battery aside)."""
        return mission.robot_agents

    def succeeded(self, mission: "Mission") -> bool:
        """Whether the team did its part (asked once it is over): every judged agent's
        tree ended in SUCCESS. The mission's verdict adds its own checks to this for
        every strategy (:mod:`delve.executive.outcome`)."""
        return all(a.root.status == Status.SUCCESS for a in self.judged_agents(mission))

    def restarted(self, mission: "Mission", name: str) -> None:
        """Agent ``name``'s tree was built afresh (a base-station restart): find again
        what the strategy holds of it."""

    def explored_at_base(self) -> set[str]:
        """The locations the base station knows to be explored (worlds of locations
        measure the base station's coverage by them)."""
        return set()

    def figures(self, mission: "Mission") -> dict[str, Any]:
        """This strategy's figures for ``report.json`` (deterministic ones)."""
        return {}

    def robot_figures(self, mission: "Mission", name: str) -> dict[str, Any]:
        """This strategy's figures of robot ``name``: by default what it mapped that
        never reached the base station's map (``map_voxels_undelivered``), on worlds
        with one."""
        voxels = mission.backend.map_undelivered(name)
        return {} if voxels is None else {"map_voxels_undelivered": voxels}

    def draw(self, ax: Any, mission: "Mission", band: HeightBand = ALL_HEIGHTS) -> None:
        """Draw what the strategy decided on the top-down ``map.png`` (matplotlib axes): what
        lies at the heights of ``band`` (one level's view on a world of several)."""

    def wall_clock_figures(self, mission: "Mission") -> dict[str, Any]:
        """This strategy's figures that depend on the wall clock (``WALL_CLOCK_FIELDS``)."""
        return {}
