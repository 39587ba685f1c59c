"""Map sharing: robots send what they mapped; the base station merges it."""
from __future__ import annotations

from typing import Any

from py_trees.common import Status

from .base import Param, Skill, mailbox

MAP_DELTA = "map_delta"


class ShareMap(Skill):
    """Send the onboard map's changes to ``recipient`` every ``period_s``.

    Messages wait in the radio's outbox while the link is down, so nothing mapped is
    lost; the last changes are sent when the behaviour is stopped.
    Returns RUNNING (it is a background task).
    """

    PARAMS = {
        "period_s": Param(float, 5.0, "how often changes are sent", exclusive_minimum=0),
        "recipient": Param(str, "base", "who receives the map"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.sent_s = -float("inf")

    def update(self) -> Status:
        now = self.ctx.clock.now_s
        if now - self.sent_s >= self.p["period_s"]:
            self.sent_s = now
            self._send()
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if self.ctx.robot is not None and new_status != Status.RUNNING:
            self._send()

    def _send(self) -> None:
        flat, values = self.robot.onboard_map.take_changes()
        if len(flat):
            self.robot.radio.send(self.p["recipient"], MAP_DELTA, {"flat": flat, "values": values})


class MergeMaps(Skill):
    """Base station: merge every map delta that arrives into the base map; log every
    message of a kind no other behaviour takes (reports for the supervisor) as a
    ``base_received`` event.

    Reads services ``radio`` and ``map`` of the base station's agent.
    Returns RUNNING (it is a background task).
    """

    AGENT = "base"

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        if "radio" in ctx.services:  # not when a tree is only checked
            mailbox(ctx, ctx.services["radio"]).claim(MAP_DELTA)

    def update(self) -> Status:
        box, base_map = mailbox(self.ctx, self.ctx.services["radio"]), self.ctx.services["map"]
        for msg in box.take(MAP_DELTA):
            base_map.merge(msg.data["flat"], msg.data["values"])
        for msg in box.take_unclaimed():
            self.event("base_received", sender=msg.sender, kind=msg.kind, data=msg.data, sent_s=msg.sent_s)
        return Status.RUNNING

