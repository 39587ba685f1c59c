"""A lossy radio: links by range and line of sight, and outboxes that keep every
message until a link carries it."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:
    from .world import World


@dataclass(frozen=True)
class Message:
    """A radio message (the robot interface's ``Message``)."""

    sender: str
    recipient: str
    kind: str
    data: Any
    sent_s: float


@dataclass(frozen=True)
class RadioSpec:
    """Link range, per-attempt packet loss and how often links are re-evaluated."""

    range_m: float = 80.0
    loss: float = 0.05
    update_period_s: float = 1.0


class RadioEndpoint:
    """One node's radio (implements the robot interface's ``Radio``)."""

    def __init__(self, name: str, network: "RadioNetwork"):
        self.name = name
        self._net = network
        self.outbox: deque[Message] = deque()
        self.inbox: list[Message] = []
        self.sent = 0
        self.delivered = 0

    def send(self, recipient: str, kind: str, data: Any) -> None:
        self.outbox.append(Message(self.name, recipient, kind, data, self._net.now_s()))
        self.sent += 1

    def receive(self) -> list[Message]:
        out, self.inbox = self.inbox, []
        return out

    def linked_to(self, other: str) -> bool:
        return self._net.linked(self.name, other)

    @property
    def pending(self) -> int:
        return len(self.outbox)


class RadioNetwork:
    """All radios of a run. ``update()`` re-evaluates links and delivers what it can.

    A link exists when two nodes are within ``range_m`` and no rock lies between them.
    Each delivery attempt fails with probability ``loss``; a message that fails, or
    whose recipient is out of reach, stays in the outbox in order.
    """

    def __init__(self, spec: RadioSpec, world: "World", rng: np.random.Generator, now_s: Callable[[], float]):
        self.spec = spec
        self.world = world
        self.rng = rng
        self.now_s = now_s
        self.endpoints: dict[str, RadioEndpoint] = {}
        self._positions: dict[str, Callable[[], np.ndarray]] = {}
        self._links: set[tuple[str, str]] = set()
        self._next_update_s = 0.0

    def add(self, name: str, position: Callable[[], np.ndarray]) -> RadioEndpoint:
        ep = RadioEndpoint(name, self)
        self.endpoints[name] = ep
        self._positions[name] = position
        return ep

    def linked(self, a: str, b: str) -> bool:
        return (min(a, b), max(a, b)) in self._links

    @property
    def links(self) -> list[tuple[str, str]]:
        return sorted(self._links)

    def update(self) -> None:
        """Re-evaluate links and deliver, once every ``update_period_s`` of sim time."""
        if self.now_s() + 1e-9 < self._next_update_s:
            return
        self._next_update_s = self.now_s() + self.spec.update_period_s
        names = sorted(self.endpoints)
        pos = {n: self._positions[n]() for n in names}
        self._links = {
            (a, b)
            for i, a in enumerate(names)
            for b in names[i + 1 :]
            if np.linalg.norm(pos[a] - pos[b]) <= self.spec.range_m
            and self.world.line_of_sight(pos[a], pos[b])
        }
        for n in names:
            self._deliver(self.endpoints[n])

    def _deliver(self, ep: RadioEndpoint) -> None:
        kept: deque[Message] = deque()
        while ep.outbox:
            msg = ep.outbox.popleft()
            target = self.endpoints.get(msg.recipient)
            if (
                target is not None
                and self.linked(ep.name, msg.recipient)
                and self.rng.random() >= self.spec.loss
            ):
                target.inbox.append(msg)
                ep.delivered += 1
            else:
                kept.append(msg)
        ep.outbox = kept
