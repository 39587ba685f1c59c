"""What the artifact figures and pictures read of a mission's artifacts (so that
they need not import the course that calls them)."""
from __future__ import annotations

from typing import Any, Protocol

from ...sim.artifacts import Artifact
from ...sim.referee import Referee


class CourseView(Protocol):
    """The ground truth (``artifacts``), the ``referee``, the base station's ``desk``
    (who reported each submission: ``desk.reporters``) and each robot's ``sensors``
    (what they picked up: ``sensors[name].detected``)."""

    artifacts: list[Artifact]
    referee: Referee
    desk: Any
    sensors: dict[str, Any]
