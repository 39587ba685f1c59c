"""Independent robots: every robot on its own tree (the SubT Final's practice, and
what a scenario without ``team:`` gets)."""
from __future__ import annotations

from .base import TeamStrategy


class Independent(TeamStrategy):
    """No team service: each robot explores, shares and comes home by its own tree.
    Over when every robot's tree has finished; succeeded when each ended in SUCCESS."""
