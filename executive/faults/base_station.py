"""A base-station restart: its mission executive crashes and comes back."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..errors import DelveError
from .base import BASE_STATION, OPTIONAL, FaultContext, Target
from .radio import RadioHold

if TYPE_CHECKING:
    from ..runner import Mission
    from ..yamlio import YamlDict


class BaseRestart(RadioHold):
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

    def radios_down(self) -> set[str]:
        from ..worlds import BASE

        return {BASE} if self.duration_s else set()

    def start(self, mission: "Mission") -> dict[str, Any]:
        from ..worlds import BASE

        lost = mission.restart_agent(BASE, resume_s=mission.clock.now_s + (self.duration_s or 0.0))
        self.apply(mission)
        return {"messages_lost": lost}
