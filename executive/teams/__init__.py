"""Team strategies: one plug-in per team method, behind :class:`TeamStrategy`.

A scenario names its strategy (``team: {strategy: cops, ...}``); a new team method
is a module that subclasses :class:`TeamStrategy` and calls :func:`register_team`
(see docs/extending.md). The runner names no strategy.
"""
from __future__ import annotations

from .base import TeamStrategy
from .cohort import Cohort
from .cops import Cops
from .csiro import Csiro
from .independent import Independent

#: The registered strategies by the name a scenario gives.
TEAM_STRATEGIES: dict[str, type[TeamStrategy]] = {}
#: The strategy of a scenario without ``team:`` whose base tree implies none.
DEFAULT_STRATEGY = "independent"


def register_team(name: str, strategy: type[TeamStrategy]) -> None:
    """Make ``strategy`` available to scenarios as ``team: {strategy: name}``."""
    TEAM_STRATEGIES[name] = strategy


def implied_strategy(base_tree_types: set[type]) -> str | None:
    """The strategy a scenario from before ``team:`` meant, judged by the node types
    of its base station tree; None when no strategy claims them."""
    return next((n for n, s in TEAM_STRATEGIES.items() if s.implied_by(base_tree_types)), None)


def wall_clock_fields() -> tuple[str, ...]:
    """The report fields of all strategies that depend on the wall clock."""
    return tuple(f for s in TEAM_STRATEGIES.values() for f in s.WALL_CLOCK_FIELDS)


register_team("independent", Independent)
register_team("cops", Cops)
register_team("cohort", Cohort)
register_team("csiro", Csiro)

__all__ = ["DEFAULT_STRATEGY", "TEAM_STRATEGIES", "TeamStrategy", "implied_strategy", "register_team",
           "wall_clock_fields"]
