"""Multi-agent frontiers (Section III-D): robots share frontier summaries, trajectory points,
their current goal and the topometric map whenever a link exists; the base station keeps what
reaches it (the uplink of explore-sync).

Message ``csiro_share`` (robot -> robot or base): ``{"robot": str, "t_s": float, "summaries":
[FrontierSummary.to_message(), ...] (all the sender's own frontiers now), "trajectory": float[k, 3]
(trajectory points new to that recipient), "goal": {"key": [owner, id], "observer": [3]} | None,
"topometric": [entries new to that recipient] (TopometricMap.changes)}``.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status

from ...planners.csiro.sharing import FrontierSummary
from ..base import Skill, mailbox
from .frontiers import body_lift
from .state import BASE, SHARE, CsiroState, csiro_config, csiro_state

#: ``ctx.services`` key of the base station's :class:`BaseFrontiers`.
BASE_SERVICE = "csiro_base"


def apply_share(st: CsiroState, data: dict[str, Any], lift: np.ndarray) -> None:
    """Take in a ``csiro_share`` message: the sender's summaries replace those it sent before
    (each hung off the topometric map, its observer lifted by ``lift``), its trajectory points
    join L, its goal replaces its last one, its topometric changes are merged."""
    sender = str(data["robot"])
    st.topometric.merge(data.get("topometric", ()))
    for key in [k for k in st.summaries if k[0] == sender]:
        del st.summaries[key]
        st.topometric.detach_frontier(key)
    for m in data.get("summaries", ()):
        s = FrontierSummary.from_message(m)
        st.summaries[s.key] = s
        st.topometric.attach_frontier(s.key, sender, s.updated_s, s.observer + lift)
    points = np.asarray(data.get("trajectory", ()), float).reshape(-1, 3)
    st.places[sender] = np.concatenate([st.places.get(sender, np.zeros((0, 3))), points])
    goal = data.get("goal")
    if goal is None:
        st.goals.pop(sender, None)
    else:
        st.goals[sender] = ((str(goal["key"][0]), int(goal["key"][1])), np.asarray(goal["observer"], float))


class ShareFrontiers(Skill):
    """Share with every teammate and the base station that a link reaches (``radio.linked_to``),
    every ``share_period_s`` (5 s): the robot's own frontier summaries, its trajectory points and
    topometric map entries that recipient has not had yet, and its current goal; and take in
    what the others share. The team comes from ``csiro_config``. Logs ``csiro_shared`` (to whom)
    at most once a period. Returns RUNNING (a background task).
    """

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.shared_s = -float("inf")
        self.sent: dict[str, tuple[int, int]] = {}   # recipient -> (trajectory points, map entries) sent
        if ctx.robot is not None:  # not when a tree is only checked
            mailbox(ctx, ctx.robot.radio).claim(SHARE)

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        st = csiro_state(self.ctx, r.view_up_deg)
        lift = body_lift(r)
        for msg in mailbox(self.ctx, r.radio).take(SHARE):
            apply_share(st, msg.data, lift)
        if now - self.shared_s >= st.selection.share_period_s:
            self.shared_s = now
            peers = [p for p in (*csiro_config(self.ctx).team, BASE) if p != self.ctx.name]
            reached = [p for p in peers if r.radio.linked_to(p)]
            for peer in reached:
                r.radio.send(peer, SHARE, self._message(st, peer))
            if reached:
                self.event("csiro_shared", to=reached, frontiers=len(st.own_summaries(self.ctx.name)))
        return Status.RUNNING

    def _message(self, st: CsiroState, peer: str) -> dict[str, Any]:
        name = self.ctx.name
        points, entries = self.sent.get(peer, (0, 0))
        self.sent[peer] = (len(st.trajectory), len(st.topometric))
        goal = None if st.goal is None or st.goal not in st.summaries else {
            "key": list(st.goal), "observer": st.summaries[st.goal].observer.tolist()}
        return {"robot": name, "t_s": self.ctx.clock.now_s,
                "summaries": [s.to_message() for s in st.own_summaries(name)],
                "trajectory": st.trajectory.points(points), "goal": goal,
                "topometric": st.topometric.changes(entries)}


class BaseFrontiers:
    """What reached the base station: every robot's latest summaries, trajectory points and the
    merged topometric map (a :class:`CsiroState` without sensing), and when each robot last
    shared."""

    def __init__(self, st: CsiroState) -> None:
        self.state = st
        self.last_s: dict[str, float] = {}


class CollectFrontiers(Skill):
    """Base station: take in every ``csiro_share`` (the robots' frontiers, trajectories and
    topometric maps: the uplink of explore-sync) into ``ctx.services["csiro_base"]``. Logs
    ``csiro_uplink`` (robot, frontiers) for a robot's first message after two share periods
    without one. Returns RUNNING (a background task)."""

    AGENT = "base"

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        if "radio" in ctx.services:  # not when a tree is only checked
            mailbox(ctx, ctx.services["radio"]).claim(SHARE)

    def update(self) -> Status:
        base = self.ctx.services.get(BASE_SERVICE)
        if base is None:
            base = self.ctx.services[BASE_SERVICE] = BaseFrontiers(csiro_state(self.ctx))
        now, period = self.ctx.clock.now_s, base.state.selection.share_period_s
        for msg in mailbox(self.ctx, self.ctx.services["radio"]).take(SHARE):
            sender = str(msg.data["robot"])
            if now - base.last_s.get(sender, -float("inf")) > 2 * period:
                self.event("csiro_uplink", robot=sender, frontiers=len(msg.data.get("summaries", ())))
            base.last_s[sender] = now
            apply_share(base.state, msg.data, np.zeros(3))
        return Status.RUNNING


__all__ = ["BASE_SERVICE", "BaseFrontiers", "CollectFrontiers", "ShareFrontiers", "apply_share"]
