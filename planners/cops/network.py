"""The mobility-communication network N = (S, ->, ~>) of the COPS paper.

Locations S are graph nodes; mobility edges (->) are the moves a local planner can
make between locations in one time step, each with a mobility cost C̄(s, s');
communication edges (~>) are the pairs of locations between which two robots can
share information, each with a communication cost C̃(s, s'). Both are
``networkx.DiGraph``; an undirected tunnel simply has both directions.

The network also carries the team it is planned for (robots with their current
location and the extensions' attributes: static, exploration capable, collision
constrained), the base station (a static robot) and the frontier locations.
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass, replace
from typing import Any, Iterable, Mapping

import networkx as nx
import numpy as np
from scipy.spatial import cKDTree

#: Default mobility cost of one move when an edge names none.
DEFAULT_MOBILITY_COST = 1.0
#: Default communication cost of one message over a communication edge.
DEFAULT_COMMUNICATION_COST = 0.1


@dataclass(frozen=True)
class Robot:
    """One member of the team.

    ``static`` robots never move (the base station, deployed relays); ``explorer``
    robots carry the sensors needed to explore a frontier; ``collision`` robots take
    part in the collision constraints on the network's collision locations.
    """

    name: str
    location: str
    static: bool = False
    explorer: bool = True
    collision: bool = False


class MCNetwork:
    """A mobility-communication network with its team, base station and frontiers."""

    def __init__(self, base: str | None = None) -> None:
        self.mobility: nx.DiGraph = nx.DiGraph()
        self.communication: nx.DiGraph = nx.DiGraph()
        self.base: str | None = base
        self.base_station: str | None = None
        self.robots: dict[str, Robot] = {}
        self.frontiers: set[str] = set()
        self.collision_locations: set[str] = set()

    # -- construction -------------------------------------------------------------
    def add_location(self, name: str, pos: Iterable[float] | None = None, frontier: bool = False) -> None:
        p = None if pos is None else tuple(float(c) for c in pos)
        self.mobility.add_node(name, pos=p)
        self.communication.add_node(name, pos=p)
        if frontier:
            self.frontiers.add(name)

    def add_mobility_edge(self, u: str, v: str, cost: float = DEFAULT_MOBILITY_COST,
                          bidirectional: bool = True, length_m: float | None = None) -> None:
        for a, b in ((u, v), (v, u)) if bidirectional else ((u, v),):
            self.mobility.add_edge(a, b, cost=float(cost), length_m=length_m)

    def add_communication_edge(self, u: str, v: str, cost: float = DEFAULT_COMMUNICATION_COST,
                               bidirectional: bool = True) -> None:
        for a, b in ((u, v), (v, u)) if bidirectional else ((u, v),):
            self.communication.add_edge(a, b, cost=float(cost))

    def add_robot(self, robot: Robot, base_station: bool = False) -> None:
        self.robots[robot.name] = robot
        if base_station:
            self.base_station = robot.name

    # -- queries --------------------------------------------------------------------
    @property
    def locations(self) -> list[str]:
        return list(self.mobility.nodes)

    def __contains__(self, location: object) -> bool:
        return location in self.mobility

    def __len__(self) -> int:
        return self.mobility.number_of_nodes()

    def position(self, location: str) -> tuple[float, ...] | None:
        return self.mobility.nodes[location].get("pos")

    def positions(self) -> dict[str, str]:
        """Current location of every robot."""
        return {name: r.location for name, r in self.robots.items()}

    def mobility_cost(self, u: str, v: str) -> float:
        return 0.0 if u == v else float(self.mobility.edges[u, v]["cost"])

    def communication_cost(self, u: str, v: str) -> float:
        return 0.0 if u == v else float(self.communication.edges[u, v]["cost"])

    def can_communicate(self, u: str, v: str) -> bool:
        """Robots at u can send to robots at v: same location or a communication edge."""
        return u == v or self.communication.has_edge(u, v)

    def hop_distances(self, source: str) -> dict[str, int]:
        """Number of mobility moves from ``source`` to every reachable location."""
        return nx.single_source_shortest_path_length(self.mobility, source)

    def static_robots(self) -> set[str]:
        return {n for n, r in self.robots.items() if r.static}

    def explorers(self) -> set[str]:
        return {n for n, r in self.robots.items() if r.explorer and not r.static}

    def collision_robots(self) -> set[str]:
        return {n for n, r in self.robots.items() if r.collision}

    # -- derived networks -------------------------------------------------------------
    def copy(self) -> "MCNetwork":
        net = MCNetwork(self.base)
        net.mobility = self.mobility.copy()
        net.communication = self.communication.copy()
        net.base_station = self.base_station
        net.robots = dict(self.robots)
        net.frontiers = set(self.frontiers)
        net.collision_locations = set(self.collision_locations)
        return net

    def with_positions(self, positions: Mapping[str, str]) -> "MCNetwork":
        """A copy whose robots stand at ``positions`` (robots not named keep theirs)."""
        net = self.copy()
        for name, loc in positions.items():
            if name not in net.robots:
                raise ValueError(f"unknown robot '{name}'")
            if loc not in net:
                raise ValueError(f"robot '{name}' at unknown location '{loc}'")
            net.robots[name] = replace(net.robots[name], location=loc)
        return net

    def subnetwork(self, locations: Iterable[str]) -> "MCNetwork":
        """The network induced on ``locations`` (robots and frontiers outside are dropped)."""
        keep = set(locations)
        net = MCNetwork(self.base if self.base in keep else None)
        net.mobility = self.mobility.subgraph(keep).copy()
        net.communication = self.communication.subgraph(keep).copy()
        net.robots = {n: r for n, r in self.robots.items() if r.location in keep}
        net.base_station = self.base_station if self.base_station in net.robots else None
        net.frontiers = self.frontiers & keep
        net.collision_locations = self.collision_locations & keep
        return net

    # -- checks and serialisation --------------------------------------------------------
    def check(self) -> None:
        """Raise ``ValueError`` with a one-line reason if the network is malformed."""
        for kind, graph in (("mobility", self.mobility), ("communication", self.communication)):
            for u, v, data in graph.edges(data=True):
                if u == v:
                    raise ValueError(f"{kind} edge {u}->{v} is a self-loop (staying is implicit)")
                c = data.get("cost")
                if not isinstance(c, (int, float)) or isinstance(c, bool) or not math.isfinite(c):
                    raise ValueError(f"{kind} edge {u}->{v} has a non-numeric cost {c!r}")
                if c < 0:
                    raise ValueError(f"{kind} edge {u}->{v} has negative cost {c:g}")
        if set(self.mobility.nodes) != set(self.communication.nodes):
            extra = sorted(set(self.communication.nodes) ^ set(self.mobility.nodes))
            raise ValueError(f"edge to unknown location '{extra[0]}'")
        if self.base is not None and self.base not in self:
            raise ValueError(f"base location '{self.base}' is not a location")
        for r in self.robots.values():
            if r.location not in self:
                raise ValueError(f"robot '{r.name}' at unknown location '{r.location}'")
        if self.base_station is not None:
            if self.base_station not in self.robots:
                raise ValueError(f"base station '{self.base_station}' is not a robot")
            bs = self.robots[self.base_station]
            if not bs.static:
                raise ValueError(f"base station '{bs.name}' must be static")
            if self.base is not None and bs.location != self.base:
                raise ValueError(f"base station '{bs.name}' is at '{bs.location}', not at the base '{self.base}'")
        for f in sorted(self.frontiers):
            if f not in self:
                raise ValueError(f"frontier '{f}' is not a location")
        for s in sorted(self.collision_locations):
            if s not in self:
                raise ValueError(f"collision location '{s}' is not a location")

    def to_dict(self) -> dict[str, Any]:
        """The dict form read by :func:`network_from_dict` (every edge listed one way)."""
        locs = []
        for s in self.mobility.nodes:
            entry: dict[str, Any] = {"name": s}
            pos = self.position(s)
            if pos is not None:
                entry["pos"] = list(pos)
            locs.append(entry)
        return {
            "base": self.base,
            "locations": locs,
            "mobility": [{"from": u, "to": v, "cost": d["cost"], "directed": True}
                         for u, v, d in self.mobility.edges(data=True)],
            "communication": [{"from": u, "to": v, "cost": d["cost"], "directed": True}
                              for u, v, d in self.communication.edges(data=True)],
            "robots": [{"name": r.name, "location": r.location, "static": r.static,
                        "explorer": r.explorer, "collision": r.collision}
                       for r in self.robots.values()],
            "base_station": self.base_station,
            "frontiers": sorted(self.frontiers),
            "collision_locations": sorted(self.collision_locations),
        }


# ---------------------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------------------

_TOP_KEYS = {"base", "locations", "mobility", "communication", "robots", "base_station",
             "frontiers", "collision_locations"}


def _name(value: Any, what: str) -> str:
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise ValueError(f"{what} must be a name, got {value!r}")
    return str(value)


def _bool(d: Mapping[str, Any], key: str, default: bool, what: str) -> bool:
    v = d.get(key, default)
    if not isinstance(v, bool):
        raise ValueError(f"{what}: '{key}' must be true or false, got {v!r}")
    return v


def _edge(entry: Any, kind: str, default_cost: float) -> tuple[str, str, float, bool]:
    if isinstance(entry, (list, tuple)):
        if len(entry) not in (2, 3):
            raise ValueError(f"{kind} edge {list(entry)!r} must be [from, to] or [from, to, cost]")
        u, v = _name(entry[0], f"{kind} edge end"), _name(entry[1], f"{kind} edge end")
        cost = entry[2] if len(entry) == 3 else default_cost
        directed = False
    elif isinstance(entry, Mapping):
        unknown = set(entry) - {"from", "to", "cost", "directed", "length_m"}
        if unknown:
            raise ValueError(f"{kind} edge has unknown key '{sorted(unknown)[0]}'")
        if "from" not in entry or "to" not in entry:
            raise ValueError(f"{kind} edge {dict(entry)!r} needs 'from' and 'to'")
        u, v = _name(entry["from"], f"{kind} edge end"), _name(entry["to"], f"{kind} edge end")
        cost = entry.get("cost", default_cost)
        directed = _bool(entry, "directed", False, f"{kind} edge {u}->{v}")
    else:
        raise ValueError(f"{kind} edge {entry!r} must be a list or a mapping")
    if isinstance(cost, bool) or not isinstance(cost, (int, float)) or not math.isfinite(cost):
        raise ValueError(f"{kind} edge {u}->{v} has a non-numeric cost {cost!r}")
    if cost < 0:
        raise ValueError(f"{kind} edge {u}->{v} has negative cost {cost:g}")
    return u, v, float(cost), directed


def network_from_dict(d: Mapping[str, Any]) -> MCNetwork:
    """Build and check an :class:`MCNetwork` from its YAML/JSON dict form.

    ::

        base: s0                         # base location (optional)
        locations:                       # names, or mappings with pos / frontier
          - {name: s0, pos: [0, 0, 0]}
          - s1
        mobility:                        # [from, to], [from, to, cost] or a mapping
          - [s0, s1]                     # undirected unless `directed: true`
          - {from: s1, to: s2, cost: 2.0, directed: true}
        communication:
          - [s0, s1, 0.1]
        robots:
          - {name: base, location: s0, static: true, explorer: false}
          - {name: r1, location: s0, explorer: true, collision: false}
        base_station: base               # a static robot at the base location
        frontiers: [s2]
        collision_locations: [s1]

    Raises ``ValueError`` with a one-line reason for a malformed network: an edge to
    an unknown location, a negative cost, a base station that is not static, ...
    """
    if not isinstance(d, Mapping):
        raise ValueError("network must be a mapping")
    unknown = set(d) - _TOP_KEYS
    if unknown:
        raise ValueError(f"network has unknown key '{sorted(unknown)[0]}'")
    locs = d.get("locations")
    if not isinstance(locs, list) or not locs:
        raise ValueError("network: 'locations' must be a non-empty list")
    net = MCNetwork()
    for entry in locs:
        if isinstance(entry, Mapping):
            bad = set(entry) - {"name", "pos", "frontier"}
            if bad:
                raise ValueError(f"location has unknown key '{sorted(bad)[0]}'")
            if "name" not in entry:
                raise ValueError(f"location {dict(entry)!r} needs a 'name'")
            name = _name(entry["name"], "location name")
            pos = entry.get("pos")
            if pos is not None and (not isinstance(pos, (list, tuple)) or len(pos) not in (2, 3)
                                    or not all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                               for c in pos)):
                raise ValueError(f"location '{name}': 'pos' must be 2 or 3 numbers")
            frontier = _bool(entry, "frontier", False, f"location '{name}'")
        else:
            name, pos, frontier = _name(entry, "location name"), None, False
        if name in net:
            raise ValueError(f"location '{name}' is defined twice")
        net.add_location(name, pos, frontier)
    for kind, default in (("mobility", DEFAULT_MOBILITY_COST), ("communication", DEFAULT_COMMUNICATION_COST)):
        edges = d.get(kind, [])
        if not isinstance(edges, list):
            raise ValueError(f"network: '{kind}' must be a list")
        for entry in edges:
            u, v, cost, directed = _edge(entry, kind, default)
            for end in (u, v):
                if end not in net:
                    raise ValueError(f"{kind} edge {u}->{v}: unknown location '{end}'")
            if u == v:
                raise ValueError(f"{kind} edge {u}->{v} is a self-loop (staying is implicit)")
            if kind == "mobility":
                length = entry.get("length_m") if isinstance(entry, Mapping) else None
                net.add_mobility_edge(u, v, cost, bidirectional=not directed, length_m=length)
            else:
                net.add_communication_edge(u, v, cost, bidirectional=not directed)
    if d.get("base") is not None:
        net.base = _name(d["base"], "base")
        if net.base not in net:
            raise ValueError(f"base location '{net.base}' is not a location")
    robots = d.get("robots", [])
    if not isinstance(robots, list):
        raise ValueError("network: 'robots' must be a list")
    for entry in robots:
        if not isinstance(entry, Mapping):
            raise ValueError(f"robot {entry!r} must be a mapping")
        bad = set(entry) - {"name", "location", "static", "explorer", "collision"}
        if bad:
            raise ValueError(f"robot has unknown key '{sorted(bad)[0]}'")
        if "name" not in entry or "location" not in entry:
            raise ValueError(f"robot {dict(entry)!r} needs 'name' and 'location'")
        name = _name(entry["name"], "robot name")
        if name in net.robots:
            raise ValueError(f"robot '{name}' is defined twice")
        loc = _name(entry["location"], f"robot '{name}' location")
        if loc not in net:
            raise ValueError(f"robot '{name}' at unknown location '{loc}'")
        static = _bool(entry, "static", False, f"robot '{name}'")
        net.add_robot(Robot(name, loc, static,
                            _bool(entry, "explorer", not static, f"robot '{name}'"),
                            _bool(entry, "collision", False, f"robot '{name}'")))
    if d.get("base_station") is not None:
        net.base_station = _name(d["base_station"], "base_station")
    for key, target in (("frontiers", net.frontiers), ("collision_locations", net.collision_locations)):
        values = d.get(key, [])
        if not isinstance(values, list):
            raise ValueError(f"network: '{key}' must be a list")
        for v in values:
            name = _name(v, key)
            if name not in net:
                raise ValueError(f"{key[:-1].replace('_', ' ')} '{name}' is not a location")
            target.add(name)
    net.check()
    return net


# ---------------------------------------------------------------------------------------
# Tunnel-like networks
# ---------------------------------------------------------------------------------------

def tunnel_network_graph(n_locations: int, spacing_m: float = 50.0, seed: int = 0, *,
                         fork_probability: float = 0.2, max_depth_m: float = 1000.0,
                         comm_range_m: float = 100.0, los_tolerance: float = 0.02,
                         turn_deg: float = 12.0, fork_angle_deg: tuple[float, float] = (40.0, 75.0),
                         base_station: str | None = "base",
                         communication_cost: float = DEFAULT_COMMUNICATION_COST) -> MCNetwork:
    """A random tunnel system of ``n_locations`` locations about ``spacing_m`` apart.

    Tunnels grow from the base location ``s0`` with small heading changes and fork
    with probability ``fork_probability`` per new location; no tunnel goes deeper
    than ``max_depth_m`` along the tunnel from the base. Mobility edges join
    consecutive locations of a tunnel (cost: length / spacing). Two locations share
    a communication edge when they are within ``comm_range_m`` along the tunnel and
    in line of sight: the straight line between them is at least
    ``1 - los_tolerance`` of the tunnel path (so radio does not bend round a corner
    or a fork). With ``base_station`` a static, non-exploring robot of that name
    stands at the base.
    """
    if n_locations < 1:
        raise ValueError("a tunnel network needs at least one location")
    rng = np.random.default_rng(seed)
    pos = [np.zeros(2)]
    depth = [0.0]
    parent: list[int | None] = [None]
    tips: list[tuple[int, float]] = [(0, float(rng.uniform(-0.3, 0.3)))]
    min_sep = 0.6 * spacing_m
    failures = 0
    while len(pos) < n_locations:
        if not tips:
            # re-open a tunnel side wall somewhere not too deep: a fork from an old location
            cands = [i for i in range(len(pos)) if depth[i] + spacing_m <= max_depth_m]
            if not cands or failures > 50 * n_locations:
                raise ValueError(f"cannot fit {n_locations} locations within depth {max_depth_m:g} m")
            i = int(rng.choice(cands))
            tips.append((i, float(rng.uniform(0, 2 * math.pi))))
        k = int(rng.integers(len(tips)))
        node, heading = tips[k]
        placed = False
        for _ in range(8):
            h = heading + math.radians(float(rng.normal(0.0, turn_deg)))
            p = pos[node] + spacing_m * np.array([math.cos(h), math.sin(h)])
            if depth[node] + spacing_m > max_depth_m + 1e-9:
                break
            if min(float(np.linalg.norm(p - q)) for q in pos) >= min_sep:
                placed = True
                break
        if not placed:
            tips.pop(k)
            failures += 1
            continue
        new = len(pos)
        pos.append(p)
        depth.append(depth[node] + spacing_m)
        parent.append(node)
        tips[k] = (new, h)
        if rng.random() < fork_probability:
            side = 1.0 if rng.random() < 0.5 else -1.0
            tips.append((new, h + side * math.radians(float(rng.uniform(*fork_angle_deg)))))
    net = MCNetwork(base="s0")
    names = [f"s{i}" for i in range(len(pos))]
    for i, name in enumerate(names):
        net.add_location(name, (float(pos[i][0]), float(pos[i][1]), 0.0))
    tunnel = nx.Graph()
    tunnel.add_nodes_from(range(len(pos)))
    for i, par in enumerate(parent):
        if par is not None:
            length = float(np.linalg.norm(pos[i] - pos[par]))
            tunnel.add_edge(i, par, length=length)
            net.add_mobility_edge(names[par], names[i], cost=round(length / spacing_m, 6), length_m=length)
    tree = cKDTree(np.array(pos))
    for i, j in sorted(tree.query_pairs(comm_range_m)):
        straight = float(np.linalg.norm(pos[i] - pos[j]))
        try:
            along = nx.shortest_path_length(tunnel, i, j, weight="length")
        except nx.NetworkXNoPath:
            continue
        if along <= comm_range_m * (1 + 1e-9) and straight >= (1.0 - los_tolerance) * along:
            net.add_communication_edge(names[i], names[j], cost=communication_cost)
    if base_station:
        net.add_robot(Robot(base_station, "s0", static=True, explorer=False), base_station=True)
    net.check()
    return net


def add_team(network: MCNetwork, n_robots: int, location: str | None = None, prefix: str = "r",
             explorer: bool = True) -> list[str]:
    """Add ``n_robots`` mobile robots ``r1..rn`` at ``location`` (default: the base)."""
    loc = location if location is not None else network.base
    if loc is None or loc not in network:
        raise ValueError(f"cannot place robots at unknown location '{loc}'")
    names = []
    for i in range(1, n_robots + 1):
        name = f"{prefix}{i}"
        network.add_robot(Robot(name, loc, explorer=explorer))
        names.append(name)
    return names


def dead_ends(network: MCNetwork) -> list[str]:
    """Locations with a single mobility neighbour, other than the base (tunnel ends)."""
    und = network.mobility.to_undirected(as_view=True)
    return [s for s in network.locations if s != network.base and und.degree(s) <= 1]


def spread_team_network(n_locations: int, n_robots: int, seed: int = 0) -> MCNetwork:
    """A :func:`tunnel_network_graph` with a team spread over it, the frontiers at its
    dead ends: half the robots (rounded up) at the base, the rest at random locations
    (seeded). The planner's benchmark and tests use it."""
    net = tunnel_network_graph(n_locations, seed=seed)
    rng = random.Random(seed)
    others = [s for s in net.locations if s != net.base]
    for i in range(n_robots):
        net.add_robot(Robot(f"r{i + 1}", net.base if i < (n_robots + 1) // 2 else rng.choice(others)))
    net.frontiers = set(dead_ends(net))
    return net
