"""The radio of a graph world: datagrams over communication edges."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .graph_world import GraphWorld
from .radio import Endpoint


@dataclass(frozen=True)
class GraphRadioSpec:
    """``loss``: chance that one message (or acknowledgement) is lost on its link;
    ``update_period_s``: how often outboxes are sent."""

    loss: float = 0.05
    update_period_s: float = 1.0


class GraphRadioEndpoint(Endpoint):
    """A datagram radio (implements the robot interface's ``Radio``): a message goes
    out at the next update over one communication edge, or is lost. Reliability is the
    job of the protocol above it (COPS re-sends until acknowledged)."""

    def __init__(self, name: str, network: "GraphRadioNetwork"):
        super().__init__(name, network.now_s)
        self._net = network
        self.dropped = 0

    def linked_to(self, other: str) -> bool:
        return self._net.linked(self.name, other)

    def ping(self, other: str) -> bool:
        return self._net.linked(self.name, other) and self._net.rng.random() >= self._net.spec.loss


class GraphRadioNetwork:
    """All radios on a graph world. Two radios are linked when the locations nearest
    to them are the same or share a communication edge, neither is off the air (silent
    or blacked out) and their link is not cut."""

    def __init__(self, spec: GraphRadioSpec, world: GraphWorld, rng: np.random.Generator,
                 now_s: Callable[[], float]):
        self.spec = spec
        self.world = world
        self.rng = rng
        self.now_s = now_s
        self.endpoints: dict[str, GraphRadioEndpoint] = {}
        self._positions: dict[str, Callable[[], np.ndarray]] = {}
        self._next_update_s = 0.0
        #: Pairs of radios (sorted names) whose link is cut (a radio fault).
        self.cut_links: set[tuple[str, str]] = set()

    def add(self, name: str, position: Callable[[], np.ndarray], **_: Any) -> GraphRadioEndpoint:
        ep = GraphRadioEndpoint(name, self)
        self.endpoints[name] = ep
        self._positions[name] = position
        return ep

    def where(self, name: str) -> str:
        return self.world.nearest(self._positions[name]())[0]

    def linked(self, a: str, b: str, where: dict[str, str] | None = None) -> bool:
        """Whether ``a`` and ``b`` can talk now (``where``: their locations, if known)."""
        ea, eb = self.endpoints.get(a), self.endpoints.get(b)
        if ea is None or eb is None or ea.off_air or eb.off_air or (min(a, b), max(a, b)) in self.cut_links:
            return False
        at = where.__getitem__ if where is not None else self.where
        return self.world.can_communicate(at(a), at(b))

    def update(self) -> None:
        """Send every outbox once: delivered over a link unless lost, else dropped."""
        if self.now_s() + 1e-9 < self._next_update_s:
            return
        self._next_update_s = self.now_s() + self.spec.update_period_s
        where = {name: self.where(name) for name in self.endpoints}  # once per update, not per message
        for name in sorted(self.endpoints):
            ep = self.endpoints[name]
            while ep.outbox:
                msg = ep.outbox.popleft()
                target = self.endpoints.get(msg.recipient)
                if target is not None and self.linked(name, msg.recipient, where) and \
                        self.rng.random() >= self.spec.loss:
                    target.inbox.append(msg)
                    ep.delivered += 1
                else:
                    ep.dropped += 1
