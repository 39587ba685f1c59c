"""Why a COPS problem has no plan: the planner's exceptions."""
from __future__ import annotations


class PlanningError(Exception):
    """A COPS problem that has no plan; ``str(err)`` is a one-line reason."""


class InfeasibleProblem(PlanningError):
    """No information-consistent plan exists (within the horizon searched)."""


class SolverTimeout(PlanningError):
    """The solver found no plan within its limits (work limits or the safety stop)."""
