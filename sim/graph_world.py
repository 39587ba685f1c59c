"""A graph world: locations joined by tunnels, with a datagram radio over
communication edges, for COPS missions at the scale of the paper (kilometres).

The world is the ground-truth mobility-communication network: locations with
positions, straight tunnels between them (mobility edges, with their length) and
the pairs of locations between which radios reach (communication edges). Robots
drive along tunnels at their platform's speed. A robot that reaches a location
(within ``at_location_m``) *explores* it: it learns the location, the tunnels
leaving it, the locations at their far ends and the communication edges to
locations it already knows. Nothing beyond is known until someone goes there.

Robots implement the robot interface's motion and radio parts and its
``NetworkView`` (``topology``, ``location``, ``route``); there is no voxel map.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import networkx as nx
import numpy as np

from .body import RobotBody
from .platforms import Platform
from .radio import Endpoint

IDLE, FOLLOWING, ARRIVED, BLOCKED = "idle", "following", "arrived", "blocked"


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


class GraphRobot(RobotBody):
    """A robot on a :class:`GraphWorld`: drives tunnel by tunnel, explores locations.

    ``follow_path`` takes waypoints that must be locations, each joined to the one
    before (or to the robot's location) by a tunnel; otherwise the path is blocked.
    """

    def __init__(self, name: str, platform: Platform, world: GraphWorld, start: np.ndarray,
                 radio: "GraphRadioEndpoint", endurance_s: float | None = None):
        self._name = name
        self._platform = platform
        self.world = world
        self._radio = radio
        start_at = world.location_at(np.asarray(start, dtype=float))
        self._pos = world.pos(start_at).copy() if start_at is not None else np.asarray(start, float).reshape(3).copy()
        self._home = self._pos.copy()
        self._endurance = math.inf if endurance_s is None else float(endurance_s)
        self._distance = 0.0
        self._trail = [self._pos.copy()]
        self._path: list[np.ndarray] = []
        self._status = IDLE
        self._commands = 0
        self._alive = True
        self._parked = False
        self.blocked_reason = ""
        self._last_location: str | None = None
        self._stuck_s = 0.0
        self.transitions = 0
        self._known = Known()
        self._arrive()

    # ---- the robot interface (motion, radio; the rest in RobotBody) ---------------
    @property
    def traversed_path(self) -> np.ndarray:
        return np.array(self._trail + [self._pos])

    @property
    def radio(self) -> "GraphRadioEndpoint":
        return self._radio

    @property
    def remaining_path(self) -> np.ndarray:
        return np.array(self._path).reshape(-1, 3)

    @property
    def alive(self) -> bool:
        return self._alive

    def follow_path(self, path: np.ndarray) -> None:
        self._commands += 1
        pts = np.asarray(path, dtype=float).reshape(-1, 3)
        here = self.world.location_at(self._pos) or self._last_location
        stops = []
        for p in pts:
            loc = self.world.location_at(p)
            if loc is None or (loc != here and not self.world.graph.has_edge(here, loc)):
                self._path, self._status = [], BLOCKED
                self.blocked_reason = f"no tunnel from {here} to {np.round(p, 1).tolist()}"
                return
            stops.append(self.world.pos(loc).copy())
            here = loc
        self._path, self._status, self.blocked_reason = stops, FOLLOWING if stops else ARRIVED, ""

    def stop(self) -> None:
        self._commands += 1
        self._path = []
        if self._status == FOLLOWING:
            self._status = IDLE

    def park(self) -> None:
        self.stop()
        self._parked = True

    @property
    def explored(self) -> list[str]:
        """Locations this robot explored, in order."""
        return self._known.explored

    def jam(self, duration_s: float) -> None:
        """A fault: the robot cannot move for ``duration_s``."""
        self._stuck_s = max(self._stuck_s, duration_s)

    def kill(self) -> None:
        """The robot dies where it stands: it stops and its radio falls silent."""
        self._alive = False
        self._path = []
        self._status = BLOCKED
        self.blocked_reason = "robot lost"
        self._radio.silent = True

    # ---- NetworkView --------------------------------------------------------------
    def topology(self) -> dict[str, Any]:
        """What this robot explored so far, as a plain topology dict."""
        return self._known.as_dict()

    def location(self) -> str | None:
        """The location the robot has reached (and explored); None on the way."""
        loc = self._last_location
        return loc if loc is not None and np.allclose(self._pos, self.world.pos(loc)) else None

    def arrived(self, location: str) -> bool:
        """At a location is at its position."""
        return self.location() == location

    def route(self, location: str) -> np.ndarray | None:
        """Waypoints along known tunnels to ``location`` (shortest by length)."""
        here = self.location() or self._last_location
        k = self._known
        if location not in k.locations or here is None:
            return None
        g = nx.Graph()
        g.add_weighted_edges_from((u, v, length) for (u, v), length in k.mobility.items())
        if here == location:
            return np.array([self.world.pos(location)])
        try:
            names = nx.shortest_path(g, here, location, weight="weight")
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            return None
        return np.array([self.world.pos(s) for s in names[1:]])

    # ---- simulation ------------------------------------------------------------
    def step(self, dt_s: float) -> None:
        if not self._alive or self._parked:
            return
        self._endurance = max(0.0, self._endurance - dt_s)
        if self._endurance == 0.0:
            self._path, self._status, self.blocked_reason = [], BLOCKED, "endurance exhausted"
            return
        if self._stuck_s > 0:
            self._stuck_s = max(0.0, self._stuck_s - dt_s)
            return
        budget = self._platform.speed_mps * dt_s
        while budget > 1e-9 and self._path:
            delta = self._path[0] - self._pos
            dist = float(np.linalg.norm(delta))
            move = min(budget, dist)
            if dist > 1e-9:
                self._pos = self._pos + delta * (move / dist)
            self._distance += move
            budget -= move
            if move >= dist - 1e-9:
                self._pos = self._path.pop(0).copy()
                self._trail.append(self._pos.copy())
                self._arrive()
        if not self._path and self._status == FOLLOWING:
            self._status = ARRIVED

    def _arrive(self) -> None:
        """Count the transition and explore the location the robot reached."""
        loc = self.world.location_at(self._pos)
        if loc is None:
            return
        if self._last_location is not None and loc != self._last_location:
            self.transitions += 1
        self._last_location = loc
        self.world.reveal(self._known, loc)


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
    to them are the same or share a communication edge, and neither is silent."""

    def __init__(self, spec: GraphRadioSpec, world: GraphWorld, rng: np.random.Generator,
                 now_s: Callable[[], float]):
        self.spec = spec
        self.world = world
        self.rng = rng
        self.now_s = now_s
        self.endpoints: dict[str, GraphRadioEndpoint] = {}
        self._positions: dict[str, Callable[[], np.ndarray]] = {}
        self._next_update_s = 0.0

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
        if ea is None or eb is None or ea.silent or eb.silent:
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
