"""What robots know of the mobility-communication network: a mergeable topology.

A :class:`Topology` is the information a robot gathers and carries (the COPS
paper's "extensions" of the network). It holds every location the robot has seen
(with its position), the ones it has *explored* (visited, or fully mapped), and the
mobility and communication edges it observed. Merging two topologies is a union,
so the base station merges what comes back in any order.

:meth:`Topology.network` turns it into the planning network N: the explored
locations with the edges among them; a frontier is an explored location with a
mobility edge to a location nobody has explored yet.

On voxel worlds a location may be a *region* of lattice cells merged into one
open area (:mod:`delve.planners.cops.regions`); ``merged`` maps each member cell
that is not its region's name to that name. Merging two topologies merges regions
that share a cell and renames what is known of the members, so a name once used
always resolves (:meth:`Topology.resolve`).

Plain data: the dict form (``to_dict`` / ``from_dict``) is what robots send over
the radio and what the simulator's graph world reports.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

from networkx.utils import UnionFind

from .network import DEFAULT_COMMUNICATION_COST, MCNetwork, Robot
from .regions import region_name


def _pair(u: str, v: str) -> tuple[str, str]:
    return (u, v) if u <= v else (v, u)


@dataclass
class Topology:
    """Locations (name -> position), explored locations and undirected edges.

    ``mobility`` maps an edge (u, v), u < v, to its length in metres.
    ``unreachable``: locations a robot found it cannot get to from a neighbour (on a
    voxel world, a ledge or a sliver of floor that the map shows connected through
    free space); they are no frontier's target."""

    locations: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    explored: set[str] = field(default_factory=set)
    mobility: dict[tuple[str, str], float] = field(default_factory=dict)
    communication: set[tuple[str, str]] = field(default_factory=set)
    unreachable: set[str] = field(default_factory=set)
    merged: dict[str, str] = field(default_factory=dict)

    # -- building -------------------------------------------------------------------
    def add_location(self, name: str, pos: Iterable[float], explored: bool = False) -> None:
        p = tuple(float(c) for c in pos)
        if len(p) != 3 or not all(math.isfinite(c) for c in p):
            raise ValueError(f"location '{name}' needs a finite (x, y, z) position, got {p}")
        self.locations.setdefault(name, p)
        if explored:
            self.explored.add(name)

    def add_mobility_edge(self, u: str, v: str, length_m: float | None = None) -> None:
        for s in (u, v):
            if s not in self.locations:
                raise ValueError(f"mobility edge {u}-{v} names unknown location '{s}'")
        if u == v:
            raise ValueError(f"mobility edge {u}-{v} is a self-loop")
        if length_m is None:
            length_m = math.dist(self.locations[u], self.locations[v])
        self.mobility[_pair(u, v)] = float(length_m)

    def add_communication_edge(self, u: str, v: str) -> None:
        if u != v:
            self.communication.add(_pair(u, v))

    def merge(self, other: "Topology") -> bool:
        """Add everything ``other`` knows; True when something was new. Regions of
        both that share a cell become one, named by
        :func:`delve.planners.cops.regions.region_name`, and what either knew of a
        member is known of the region."""
        before = self.size()
        for name, pos in other.locations.items():
            self.locations.setdefault(name, pos)
        self.explored |= other.explored
        for e, length in other.mobility.items():
            self.mobility.setdefault(e, length)
        self.communication |= other.communication
        self.unreachable |= other.unreachable
        if other.merged or self.merged:
            self._merge_regions(other.merged)
        return self.size() != before

    def _merge_regions(self, merged: Mapping[str, str]) -> None:
        """Join the regions of ``self.merged`` and ``merged``, then rename members."""
        regions = UnionFind()
        for member, name in sorted([*self.merged.items(), *merged.items()]):
            regions.union(member, name)
        self.merged = {m: region_name(group) for group in regions.to_sets() for m in sorted(group)}
        self.merged = {m: n for m, n in sorted(self.merged.items()) if m != n}
        if not self.merged.keys() & (self.locations.keys() | self.unreachable):
            return
        rename = self.resolve
        for name in sorted(self.locations):
            if rename(name) != name:
                pos = self.locations.pop(name)
                self.locations.setdefault(rename(name), pos)
        self.explored = {rename(s) for s in self.explored}
        # a cell some robot could not get to is no reason to think its region unreachable
        self.unreachable = {s for s in self.unreachable if rename(s) == s}
        mobility: dict[tuple[str, str], float] = {}
        for (u, v), length in sorted(self.mobility.items()):
            a, b = rename(u), rename(v)
            if a != b:
                mobility.setdefault(_pair(a, b), length)
        self.mobility = mobility
        self.communication = {_pair(rename(u), rename(v)) for u, v in self.communication if rename(u) != rename(v)}

    def resolve(self, name: str) -> str:
        """The location a name stands for now: its region's name for a member of a
        merged location, else the name itself."""
        return self.merged.get(name, name)

    def members(self, name: str) -> list[str]:
        """The names a location has had: itself and its region's other members, sorted."""
        head = self.resolve(name)
        return sorted({head, *(m for m, n in self.merged.items() if n == head)})

    def copy(self) -> "Topology":
        return Topology(dict(self.locations), set(self.explored), dict(self.mobility), set(self.communication),
                        set(self.unreachable), dict(self.merged))

    def size(self) -> tuple[int, int, int, int, int, int]:
        return (len(self.locations), len(self.explored), len(self.mobility), len(self.communication),
                len(self.unreachable), len(self.merged))

    # -- queries ----------------------------------------------------------------------
    def neighbours(self, location: str) -> list[str]:
        """Mobility neighbours of ``location`` (explored or not), sorted by name."""
        out = [v if u == location else u for u, v in self.mobility if location in (u, v)]
        return sorted(out)

    def frontiers(self) -> set[str]:
        """Explored locations with a mobility edge to a location nobody explored (and
        nobody found unreachable)."""
        out = set()
        for u, v in self.mobility:
            if (u in self.explored) != (v in self.explored):
                inner, outer = (u, v) if u in self.explored else (v, u)
                if outer not in self.unreachable:
                    out.add(inner)
        return out

    def unexplored_exits(self, location: str) -> list[str]:
        return [n for n in self.neighbours(location) if n not in self.explored and n not in self.unreachable]

    def network(self, base: str, *, spacing_m: float | None = None,
                communication_cost: float = DEFAULT_COMMUNICATION_COST) -> MCNetwork:
        """The planning network N over the explored locations (``base`` must be one).

        A move's mobility cost is its length over ``spacing_m`` (1 per move without
        it), so that costs count time steps of roughly equal duration."""
        if base not in self.explored:
            raise ValueError(f"base location '{base}' has not been explored")
        net = MCNetwork(base=base)
        for s in sorted(self.explored):
            net.add_location(s, self.locations[s], frontier=False)
        for (u, v), length in sorted(self.mobility.items()):
            if u in self.explored and v in self.explored:
                cost = 1.0 if not spacing_m else round(max(length / spacing_m, 1e-3), 6)
                net.add_mobility_edge(u, v, cost=cost, length_m=length)
        for u, v in sorted(self.communication):
            if u in self.explored and v in self.explored:
                net.add_communication_edge(u, v, cost=communication_cost)
        net.frontiers = self.frontiers()
        return net

    # -- plain data --------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {"locations": {s: list(p) for s, p in sorted(self.locations.items())},
                "explored": sorted(self.explored),
                "mobility": [[u, v, round(length, 3)] for (u, v), length in sorted(self.mobility.items())],
                "communication": [list(e) for e in sorted(self.communication)],
                "unreachable": sorted(self.unreachable), **({"merged": dict(sorted(self.merged.items()))}
                                                            if self.merged else {})}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Topology":
        """Read the dict form; a ``ValueError`` names the first malformed entry."""
        topo = cls()
        try:
            for name, pos in d.get("locations", {}).items():
                topo.add_location(str(name), pos)
            for s in d.get("explored", []):
                if s not in topo.locations:
                    raise ValueError(f"explored location '{s}' is not a location")
                topo.explored.add(str(s))
            for e in d.get("mobility", []):
                topo.add_mobility_edge(str(e[0]), str(e[1]), float(e[2]) if len(e) > 2 else None)
            for u, v in d.get("communication", []):
                for s in (u, v):
                    if s not in topo.locations:
                        raise ValueError(f"communication edge {u}-{v} names unknown location '{s}'")
                topo.add_communication_edge(str(u), str(v))
            for s in d.get("unreachable", []):
                if s not in topo.locations:
                    raise ValueError(f"unreachable location '{s}' is not a location")
                topo.unreachable.add(str(s))
            for member, name in dict(d.get("merged", {})).items():
                topo.merged[str(member)] = str(name)
        except (TypeError, IndexError, AttributeError) as err:
            raise ValueError(f"malformed topology: {err}") from None
        return topo


def team_network(topology: Topology, base: str, base_station: str, positions: Mapping[str, str], *,
                 explorers: Iterable[str] | None = None, spacing_m: float | None = None) -> MCNetwork:
    """The planning network with the team placed on it: the base station static at
    ``base``, every other robot at its location in ``positions``."""
    net = topology.network(base, spacing_m=spacing_m)
    net.add_robot(Robot(base_station, base, static=True, explorer=False), base_station=True)
    ex = None if explorers is None else set(explorers)
    for r in sorted(positions):
        if r == base_station:
            continue
        if positions[r] not in net:
            raise ValueError(f"robot '{r}' is at '{positions[r]}', which is not an explored location")
        net.add_robot(Robot(r, positions[r], explorer=ex is None or r in ex))
    net.check()
    return net
