"""A base-station restart: its mission executive crashes and comes back."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..errors import DelveError
from .base import BASE_STATION, OPTIONAL, Fault, FaultContext, Target

if TYPE_CHECKING:
    from ..runner import Mission
    from ..yamlio import YamlDict


class BaseRestart(Fault):
    """The base station's executive restarts: its tree stops and is built afresh
    from its file, its blackboard is cleared, and the messages in its radio's inbox
    and outbox are lost. Its services outlive the restart: the base map (kept on
    disk) and the team's configuration. With ``duration_s`` it is down that long
    (no tick, radio off the air) before the new tree starts; without it the new tree
    starts at once."""

    KIND = "base_restart"
    TARGETS = (BASE_STATION,)
    DURATION = OPTIONAL

    @classmethod
    def check(cls, item: "YamlDict", target: Target, ctx: FaultContext) -> None:
        if not ctx.has_base_tree:
            raise DelveError(f"fault {cls.KIND!r}: the scenario has no base station tree to restart "
                             f"(base_station: tree: ...)", ctx.path, item.key_line("kind"))

    @property
    def end_s(self) -> float | None:
        return None if not self.duration_s else self.at_s + self.duration_s

    def start(self, mission: "Mission") -> dict[str, Any]:
        from ..worlds import BASE

        down = self.duration_s or 0.0
        lost = mission.restart_agent(BASE, resume_s=mission.clock.now_s + down)
        if down:
            mission.radio.endpoints[BASE].blackout = True
        return {"messages_lost": lost}

    def end(self, mission: "Mission") -> dict[str, Any]:
        from ..worlds import BASE

        mission.radio.endpoints[BASE].blackout = False
        return {}
