"""Conditions on the part of the cycle an agent is in."""
from __future__ import annotations

from py_trees.common import Status

from .base import CopsSkill


class _PartCheck(CopsSkill):
    ABSTRACT = True
    PART = ""
    OUTPUT_PORTS = {}  # reads the state only

    def update(self) -> Status:
        return Status.SUCCESS if self.state.part == self.PART else Status.FAILURE


class IsExploring(_PartCheck):
    """Explore?: SUCCESS when the agent is in the exploration phase, else FAILURE."""

    TYPE_NAME = "Explore?"
    PART = "explore"


class FinishedPlan(_PartCheck):
    """Finished plan?: SUCCESS when the agent has done its part of the cycle plan."""

    TYPE_NAME = "FinishedPlan?"
    PART = "done"


class TransitionFailed(CopsSkill):
    """TransitionFailed?: SUCCESS when a move of the plan failed (the Transition
    Action or the transit to the return node found no way), else FAILURE. Reads
    ``cops``."""

    TYPE_NAME = "TransitionFailed?"
    OUTPUT_PORTS = {}  # reads the state only

    def update(self) -> Status:
        return Status.SUCCESS if self.state.transition_failed else Status.FAILURE
