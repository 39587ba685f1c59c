"""A graph world: locations joined by tunnels, for COPS missions at the scale of
the paper (kilometres). Its robots are in :mod:`delve.sim.graph_robot`, its radio in
:mod:`delve.sim.graph_radio`.

The world is the ground-truth mobility-communication network: locations with
positions, straight tunnels between them (mobility edges, with their length) and
the pairs of locations between which radios reach (communication edges). Robots
drive along tunnels at their platform's speed. A robot that reaches a location
(within ``at_location_m``) *explores* it: it learns the location, the tunnels
leaving it, the locations at their far ends and the communication edges to
locations it already knows. Nothing beyond is known until someone goes there.

"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import networkx as nx
import numpy as np



def _pair(u: str, v: str) -> tuple[str, str]:
    return (u, v) if u <= v else (v, u)


def _xyz(p: np.ndarray) -> list[float]:
    return [round(float(c), 3) for c in p]


@dataclass
class Known:
    """What one robot learnt of a graph world (the topology dict, mutable)."""

    locations: dict[str, list[float]] = field(default_factory=dict)
    explored: list[str] = field(default_factory=list)
    mobility: dict[tuple[str, str], float] = field(default_factory=dict)
    communication: set[tuple[str, str]] = field(default_factory=set)

    def as_dict(self) -> dict[str, Any]:
        return {"locations": {s: list(p) for s, p in sorted(self.locations.items())},
                "explored": sorted(self.explored),
                "mobility": [[u, v, length] for (u, v), length in sorted(self.mobility.items())],
                "communication": [list(e) for e in sorted(self.communication)]}


class GraphWorld:
    """Locations (name -> xyz), tunnels (``graph`` edges with ``length_m``) and
    communication edges between locations."""

    at_location_m = 1.0

    def __init__(self, positions: dict[str, tuple[float, float, float]], tunnels: list[tuple[str, str]],
                 communication: list[tuple[str, str]], base: str):
        self.graph = nx.Graph()
        for name, p in positions.items():
            self.graph.add_node(name, pos=np.asarray(p, dtype=float).reshape(3))
        for u, v in tunnels:
            self.graph.add_edge(u, v, length_m=float(np.linalg.norm(self.pos(u) - self.pos(v))))
        self.communication = {_pair(u, v) for u, v in communication if u != v}
        if base not in self.graph:
            raise ValueError(f"base location '{base}' is not a location")
        self.base = base
        names = list(self.graph.nodes)
        self._names = names
        self._xyz = np.array([self.pos(n) for n in names])

    def pos(self, location: str) -> np.ndarray:
        return self.graph.nodes[location]["pos"]

    @property
    def start(self) -> np.ndarray:
        return self.pos(self.base).copy()

    def __len__(self) -> int:
        return self.graph.number_of_nodes()

    def nearest(self, point: np.ndarray) -> tuple[str, float]:
        """The location nearest to ``point`` and its distance."""
        d = np.linalg.norm(self._xyz - np.asarray(point, float).reshape(1, 3), axis=1)
        i = int(np.argmin(d))
        return self._names[i], float(d[i])

    def location_at(self, point: np.ndarray) -> str | None:
        name, d = self.nearest(point)
        return name if d <= self.at_location_m else None

    def can_communicate(self, u: str, v: str) -> bool:
        return u == v or _pair(u, v) in self.communication

    def reveal(self, known: "Known", location: str) -> bool:
        """Add to ``known`` what exploring ``location`` shows: the location, its tunnels,
        the locations at their far ends and its communication edges to locations
        already known. False if it was explored before."""
        if location in known.explored:
            return False
        known.explored.append(location)
        known.locations[location] = _xyz(self.pos(location))
        for nb in self.graph.neighbors(location):
            known.locations.setdefault(nb, _xyz(self.pos(nb)))
            known.mobility[_pair(location, nb)] = round(self.graph.edges[location, nb]["length_m"], 3)
        for other in list(known.locations):
            if other != location and self.can_communicate(location, other):
                known.communication.add(_pair(location, other))
        return True

    def explored_topology(self, locations: list[str]) -> dict[str, Any]:
        """The topology dict of having explored ``locations`` (in order)."""
        known = Known()
        for s in locations:
            self.reveal(known, s)
        return known.as_dict()

    def start_problem(self, point: Any) -> str | None:
        """Why a robot cannot start at ``point`` (None when it can): it must stand at a location."""
        p = np.asarray(point, dtype=float).reshape(-1)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            return "not 3 finite numbers"
        name, d = self.nearest(p)
        return None if d <= self.at_location_m else f"not at a location (nearest is '{name}', {d:.1f} m away)"
