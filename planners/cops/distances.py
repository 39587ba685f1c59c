"""How far information is from where it must go: lower bounds over a network that
prune the time-expanded network and bound the horizons searched."""
from __future__ import annotations

import math
from collections import deque
from typing import Iterable, Mapping

from .network import MCNetwork


def information_distance(net: MCNetwork, sources: Iterable[str], reverse: bool = False,
                         start: Mapping[str, int] | None = None) -> dict[str, int]:
    """Lower bound on the steps information needs from ``sources``: a move costs one
    step, a communication edge none (0-1 BFS). With ``reverse``, distances *to* sources."""
    dist: dict[str, int] = {}
    dq: deque[tuple[int, str]] = deque()
    for s in sources:
        d0 = 0 if start is None else start.get(s, 0)
        if d0 < dist.get(s, math.inf):
            dist[s] = d0
    for s, d in sorted(dist.items(), key=lambda kv: kv[1]):
        dq.append((d, s))
    mob = net.mobility.reverse(copy=False) if reverse else net.mobility
    com = net.communication.reverse(copy=False) if reverse else net.communication
    while dq:
        d, u = dq.popleft()
        if d > dist.get(u, math.inf):
            continue
        for v in com.successors(u):
            if d < dist.get(v, math.inf):
                dist[v] = d
                dq.appendleft((d, v))
        for v in mob.successors(u):
            if d + 1 < dist.get(v, math.inf):
                dist[v] = d + 1
                dq.append((d + 1, v))
    return dist


def m_distance(network: MCNetwork, pos: Mapping[str, str], masters: Iterable[str]) -> dict[str, int]:
    """Lower bound on the step at which the plan m, held by ``masters`` at ``pos``, can
    reach each location (:func:`information_distance` from the masters' locations)."""
    return information_distance(network, {pos[r] for r in masters})
