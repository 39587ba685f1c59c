"""Agents: one per robot and one for the base station, each ticking its own tree."""
from __future__ import annotations

import uuid
from dataclasses import dataclass, field
from typing import Callable

import py_trees
from py_trees.common import Status

from ..skills.base import AgentContext


@dataclass
class Agent:
    """A tree, its tick period on the sim clock and its context (blackboard namespace
    ``/<name>``). ``on_change(agent, node, old, new)`` is told of every status change."""

    name: str
    root: py_trees.behaviour.Behaviour
    period_s: float
    ctx: AgentContext
    on_change: Callable[["Agent", py_trees.behaviour.Behaviour, Status, Status], None] | None = None
    next_tick_s: float = 0.0
    ticks: int = 0
    #: Each node's status when the tree was stopped (None before): stopping leaves every
    #: node INVALID, and the outputs show where the tree was.
    stopped_statuses: dict[uuid.UUID, Status] | None = None
    _last: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.root.setup_with_descendants()
        self._nodes = list(self.root.iterate())

    @property
    def finished(self) -> bool:
        return self.root.status in (Status.SUCCESS, Status.FAILURE)

    def tick_if_due(self, now_s: float) -> bool:
        """Tick once if the period has elapsed and the tree has not finished."""
        if self.finished or now_s + 1e-9 < self.next_tick_s:
            return False
        self.next_tick_s = now_s + self.period_s
        self.root.tick_once()
        self.ticks += 1
        if self.on_change is not None:
            for node in self._nodes:
                old = self._last.get(node.id, Status.INVALID)
                if node.status != old:
                    self._last[node.id] = node.status
                    self.on_change(self, node, old, node.status)
        return True

    def stop(self) -> None:
        """Stop the tree (its running behaviours terminate), keeping each node's status
        of the moment in ``stopped_statuses`` (the first time only)."""
        if self.stopped_statuses is None:
            self.stopped_statuses = {n.id: n.status for n in self.root.iterate()}
        self.root.stop(Status.INVALID)

    @property
    def final_status(self) -> Status:
        """The root's status, or the one it had when the tree was stopped."""
        return self.root.status if self.stopped_statuses is None else self.stopped_statuses[self.root.id]
