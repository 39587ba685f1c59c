"""Who is who in a COPS problem: the robots' positions, the static robots, the
explorers and the masters, taken from the network where not given, and checked."""
from __future__ import annotations

from typing import Iterable, Mapping

from .network import MCNetwork


def robot_sets(network: MCNetwork, positions: Mapping[str, str] | None, static: Iterable[str] | None,
               explorers: Iterable[str] | None) -> tuple[dict[str, str], set[str], set[str]]:
    """(positions, static robots, explorers), the network's own where not given,
    checked: every location known, every robot named placed; explorers are mobile."""
    pos = dict(network.positions() if positions is None else positions)
    for r, s in pos.items():
        if s not in network:
            raise ValueError(f"robot '{r}' at unknown location '{s}'")
    st = set(network.static_robots() & set(pos) if static is None else static)
    ex = set((network.explorers() & set(pos)) if explorers is None else explorers) - st
    for name, group in (("static", st), ("explorer", ex)):
        for r in sorted(group):
            if r not in pos:
                raise ValueError(f"{name} robot '{r}' has no position")
    return pos, st, ex


def master_robots(network: MCNetwork, pos: Mapping[str, str], masters: Iterable[str] | None) -> set[str]:
    """The robots holding m at the start (default: the base station), each placed."""
    if masters is None:
        if network.base_station is None:
            raise ValueError("no master robot: give masters or a base station")
        masters = {network.base_station}
    ms = set(masters)
    for r in sorted(ms):
        if r not in pos:
            raise ValueError(f"master robot '{r}' has no position")
    return ms
