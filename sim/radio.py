"""A lossy WiFi mesh: link budgets from range, line of sight and rock, multi-hop routes
through robots and deployed breadcrumbs, pings, and outboxes that keep every message
until a route carries it.

The link model (one evaluation per pair of nodes, every ``update_period_s``):

* **Path loss** (log-distance):
  ``PL(d) = PL(d0) + 10 · n · log10(max(d, d0) / d0)``.
* **Obstruction loss**, only when rock cuts the straight line between the two nodes
  (line of sight is tested by casting a ray into the world's rock mesh):
  ``L_obs = corner_loss_db · k + rock_loss_db_per_m · t``, where ``t`` is the length
  of rock crossed along the straight line (sampled with ``World.is_free`` every
  ``rock_sample_step_m``) and ``k >= 1`` the number of separate rock bodies crossed.
  A corner of a tunnel is a short crossing (a few metres, one corner loss: the
  diffraction round its edge); tens of metres of rock add up to far more than the
  link budget. The per-metre figure is an *effective* attenuation: it stands for
  how deep the receiver sits in the corner's radio shadow, not for transmission
  through solid rock (which at 5.8 GHz loses far more).
* **Received power and margin**: ``P_rx = P_tx − PL(d) − L_obs``;
  ``M = P_rx − sensitivity``. A link exists when ``M >= 0`` and ``d <= range_m``.
* **Packet loss** rises as the margin falls, as the outage probability of a Rayleigh
  fading channel: ``p_fade = 1 − exp(−10^(−M / 10))`` (0.63 at a 0 dB margin, 0.10 at
  10 dB, 0.01 at 20 dB). With the margin-independent floor ``loss`` (interference,
  collisions) each attempt over one hop fails with
  ``p = 1 − (1 − loss) · (1 − p_fade)``; the link's ``quality`` is ``1 − p``.
  With ``fading=False`` the margin only decides whether a link exists and ``p = loss``.

Defaults (:class:`RadioSpec`) stand for the 5.8 GHz Rajant mesh radios of the CERBERUS
paper (section 3.4) carried low on robots in rough tunnels: 20 dBm EIRP, free-space
loss 47.7 dB at 1 m for 5.8 GHz, path-loss exponent 2.6 and a −82 dBm sensitivity.
A straight tunnel links at up to ~122 m (quality ≈ 0.5 at 100 m, 0.86 at 50 m), a
right-angle corner of a 4 m tunnel cuts that to some 20 m of total separation
(10 m either side of the corner), and 10 m of rock or more between two tunnels
blocks the link.

The mesh: every robot radio and every active breadcrumb is a node; messages go
along the route of highest success probability (networkx Dijkstra with hop weights
``−ln(1 − p)``), each hop failing independently. A node added with ``relay=False``
is a WiFi client (the paper's aerial robots, which carried no mesh radio and joined
the nearest access point: a legged or roving robot, a breadcrumb or the base
station): it links only to mesh nodes, never to another client, and it ends or
starts routes but never forwards. A message that fails, or has no route, stays in
its outbox in order and is tried again at the next update: nothing sent is lost.

Breadcrumbs are static relay nodes that carrier robots drop at run time
(:meth:`RadioNetwork.deploy_breadcrumb`), only where they would link to a mesh node
(a drop out of the mesh's reach is refused, not made); each robot carries
``breadcrumbs_per_robot`` (4, as the paper's Carrier ANYmals) unless set otherwise,
and a breadcrumb relays for ``breadcrumb_battery_s`` (2 h) after its drop.

All randomness (per-hop losses of messages and pings) comes from the rng passed in,
drawn in a fixed order (endpoints by name, messages in outbox order, hops along the
route), so a run is reproducible from its seed.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import networkx as nx
import numpy as np

if TYPE_CHECKING:
    from .world import World

#: Height of a dropped breadcrumb's antenna above the ground (the paper: 17 cm).
BREADCRUMB_ANTENNA_HEIGHT_M = 0.17
#: Smallest success probability a hop weight is computed from (keeps weights finite).
_MIN_SUCCESS = 1e-12


@dataclass(frozen=True)
class Message:
    """A radio message (implements the robot interface's ``Message`` protocol)."""

    sender: str
    recipient: str
    kind: str
    data: Any
    sent_s: float


@dataclass(frozen=True)
class RadioSpec:
    """Link budget, loss and mesh parameters (see the module docstring for the formulas).

    Fields:
        range_m: hard limit on the length of one link, whatever its margin.
        loss: per-attempt packet loss of a link with ample margin (interference).
        update_period_s: how often (sim time) links are re-evaluated and outboxes sent.
        tx_power_dbm: transmit power including antenna gains (EIRP).
        path_loss_d0_db: path loss at the reference distance (free space, 5.8 GHz, 1 m).
        reference_distance_m: the reference distance d0.
        path_loss_exponent: n of the log-distance model.
        sensitivity_dbm: weakest received power a link still works at.
        fading: whether packet loss rises as the margin falls (Rayleigh outage).
        corner_loss_db: loss per separate rock body crossing the straight line.
        rock_loss_db_per_m: loss per metre of rock crossed along the straight line.
        rock_sample_step_m: spacing of the rock samples along a link; None = half a voxel.
        breadcrumbs_per_robot: breadcrumbs each radio carries unless set otherwise.
        breadcrumb_battery_s: how long a dropped breadcrumb relays.
    """

    range_m: float = 150.0
    loss: float = 0.05
    update_period_s: float = 1.0
    tx_power_dbm: float = 20.0
    path_loss_d0_db: float = 47.7
    reference_distance_m: float = 1.0
    path_loss_exponent: float = 2.6
    sensitivity_dbm: float = -82.0
    fading: bool = True
    corner_loss_db: float = 10.0
    rock_loss_db_per_m: float = 1.5
    rock_sample_step_m: float | None = None
    breadcrumbs_per_robot: int = 4
    breadcrumb_battery_s: float = 7200.0

    def __post_init__(self) -> None:
        positive = ("range_m", "update_period_s", "reference_distance_m", "path_loss_exponent",
                    "breadcrumb_battery_s")
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"radio {name} must be > 0, got {value}")
        if not 0.0 <= self.loss <= 1.0:
            raise ValueError(f"radio loss must lie in [0, 1], got {self.loss}")
        for name in ("corner_loss_db", "rock_loss_db_per_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"radio {name} must be >= 0, got {value}")
        if self.rock_sample_step_m is not None and not self.rock_sample_step_m > 0:
            raise ValueError(f"radio rock_sample_step_m must be > 0, got {self.rock_sample_step_m}")
        if int(self.breadcrumbs_per_robot) != self.breadcrumbs_per_robot or self.breadcrumbs_per_robot < 0:
            raise ValueError(f"radio breadcrumbs_per_robot must be a whole number >= 0, "
                             f"got {self.breadcrumbs_per_robot}")

    def path_loss_db(self, distance_m: np.ndarray | float) -> np.ndarray:
        """Log-distance path loss (dB) at the given distances."""
        d = np.maximum(np.asarray(distance_m, dtype=float), self.reference_distance_m)
        return self.path_loss_d0_db + 10.0 * self.path_loss_exponent * np.log10(d / self.reference_distance_m)

    @property
    def line_of_sight_range_m(self) -> float:
        """Longest link with a clear line of sight (margin 0), capped at ``range_m``."""
        budget = self.tx_power_dbm - self.sensitivity_dbm - self.path_loss_d0_db
        d = self.reference_distance_m * 10.0 ** (budget / (10.0 * self.path_loss_exponent))
        return float(min(d, self.range_m))

    def attempt_loss(self, margin_db: np.ndarray | float) -> np.ndarray:
        """Per-attempt packet loss of one hop at the given margins (dB)."""
        m = np.asarray(margin_db, dtype=float)
        if not self.fading:
            return np.full(m.shape, float(self.loss))
        p_fade = -np.expm1(-np.power(10.0, -m / 10.0))
        return 1.0 - (1.0 - self.loss) * (1.0 - p_fade)


@dataclass(frozen=True)
class LinkBudget:
    """The link model's figures for one pair of positions."""

    distance_m: float
    line_of_sight: bool
    rock_m: float
    rock_crossings: int
    rx_power_dbm: float
    margin_db: float
    loss: float

    @property
    def linked(self) -> bool:
        """Whether the pair forms a link (margin >= 0 within range)."""
        return math.isfinite(self.margin_db) and self.margin_db >= 0.0

    @property
    def quality(self) -> float:
        """Per-attempt success probability of the link (0 when there is no link)."""
        return 1.0 - self.loss if self.linked else 0.0


@dataclass(frozen=True)
class LinkState:
    """One current link between nodes ``a`` < ``b`` and its budget (for plots and logs)."""

    a: str
    b: str
    budget: LinkBudget

    @property
    def quality(self) -> float:
        return self.budget.quality

    @property
    def loss(self) -> float:
        return self.budget.loss


@dataclass(frozen=True, eq=False)
class Breadcrumb:
    """A deployed static relay node."""

    name: str
    owner: str
    position: np.ndarray
    deployed_s: float


@dataclass(frozen=True)
class BreadcrumbDrop:
    """The result of asking a robot to drop a breadcrumb.

    ``ok`` tells whether one was dropped; then ``name`` is the new node's name.
    Otherwise ``error`` says why not (no breadcrumbs left, position inside rock, no
    mesh node heard there, ...).
    ``remaining`` is the owner's count after the attempt.
    """

    ok: bool
    owner: str
    name: str | None
    remaining: int
    error: str = ""

    def __bool__(self) -> bool:
        return self.ok


class Endpoint:
    """What every radio has: an outbox its network sends from, an inbox it delivers
    to, counters, ``silent`` (a lost robot's radio sends nothing, not even into its
    outbox) and ``blackout`` (a radio fault: the node is off the network, but what is
    sent waits in the outbox as it does while out of range)."""

    def __init__(self, name: str, now_s: Callable[[], float]):
        self.name = name
        self._now_s = now_s
        self.outbox: deque[Message] = deque()
        self.inbox: list[Message] = []
        self.sent = 0
        self.delivered = 0
        self.silent = False
        self.blackout = False

    @property
    def off_air(self) -> bool:
        """Whether the node takes no part in the network now (silent or blacked out)."""
        return self.silent or self.blackout

    def send(self, recipient: str, kind: str, data: Any) -> None:
        if self.silent:
            return
        self.outbox.append(Message(self.name, recipient, kind, data, self._now_s()))
        self.sent += 1

    def receive(self) -> list[Message]:
        out, self.inbox = self.inbox, []
        return out

    @property
    def pending(self) -> int:
        return len(self.outbox)


class RadioEndpoint(Endpoint):
    """One node's radio on the WiFi mesh (implements the robot interface's ``Radio``)."""

    def __init__(self, name: str, network: RadioNetwork, breadcrumbs: int = 0, relay: bool = True):
        super().__init__(name, network.now_s)
        self._net = network
        self.pings = 0
        self.pings_answered = 0
        self.breadcrumbs = int(breadcrumbs)
        self.breadcrumbs_deployed = 0
        self.relay = bool(relay)

    def linked_to(self, other: str) -> bool:
        """Whether a route (direct or through the mesh) to ``other`` exists right now."""
        return self._net.linked(self.name, other)

    def ping(self, other: str) -> bool:
        """Send one echo request to ``other``; True if it and the reply got through."""
        return self._net.ping(self.name, other)

    def deploy_breadcrumb(self, position: np.ndarray) -> BreadcrumbDrop:
        """Drop one of this radio's breadcrumbs at ``position``."""
        return self._net.deploy_breadcrumb(self.name, position)


class RadioNetwork:
    """All radios of a run. ``update()`` re-evaluates links and delivers what it can.

    Nodes are the endpoints (robots, base station) and the active breadcrumbs. Links
    follow the model of the module docstring; ``linked(a, b)`` is True when a route
    joins ``a`` and ``b`` through the mesh, ``direct_link(a, b)`` when one link does.
    """

    def __init__(self, spec: RadioSpec, world: World, rng: np.random.Generator, now_s: Callable[[], float]):
        self.spec = spec
        self.world = world
        self.rng = rng
        self.now_s = now_s
        self.endpoints: dict[str, RadioEndpoint] = {}
        self.breadcrumbs: dict[str, Breadcrumb] = {}
        self._positions: dict[str, Callable[[], np.ndarray]] = {}
        self._links: dict[tuple[str, str], LinkBudget] = {}
        self._graph = nx.Graph()
        self._routes: dict[str, tuple[dict[str, float], dict[str, list[str]]]] = {}
        self._next_update_s = 0.0
        #: Pairs of nodes (sorted names) whose direct link is cut (a radio fault).
        self.cut_links: set[tuple[str, str]] = set()
        #: Deployed breadcrumbs that died before their battery ran out (a fault).
        self.dead_breadcrumbs: set[str] = set()

    # ---- nodes ------------------------------------------------------------------
    def add(self, name: str, position: Callable[[], np.ndarray], *, breadcrumbs: int | None = None,
            relay: bool = True) -> RadioEndpoint:
        """Add a radio at ``position()``, carrying ``breadcrumbs`` (default
        ``spec.breadcrumbs_per_robot``); ``relay=False`` for a client that never forwards."""
        if name in self.breadcrumbs:
            raise ValueError(f"radio name {name!r} is taken by a breadcrumb")
        count = self.spec.breadcrumbs_per_robot if breadcrumbs is None else breadcrumbs
        if int(count) != count or count < 0:
            raise ValueError(f"breadcrumbs of {name!r} must be a whole number >= 0, got {count}")
        ep = RadioEndpoint(name, self, int(count), relay)
        self.endpoints[name] = ep
        self._positions[name] = position
        return ep

    def set_breadcrumbs(self, name: str, count: int) -> None:
        """Set how many breadcrumbs the radio ``name`` carries (0 for a non-carrier)."""
        if int(count) != count or count < 0:
            raise ValueError(f"breadcrumbs of {name!r} must be a whole number >= 0, got {count}")
        self.endpoints[name].breadcrumbs = int(count)

    def deploy_breadcrumb(self, owner: str, position: np.ndarray) -> BreadcrumbDrop:
        """Drop one of ``owner``'s breadcrumbs at ``position``; it joins the mesh at the
        next link update. Returns a :class:`BreadcrumbDrop` (never raises for a refusal)."""
        ep = self.endpoints.get(owner)
        if ep is None:
            return BreadcrumbDrop(False, owner, None, 0, f"no radio named {owner!r} to drop a breadcrumb")
        if ep.breadcrumbs <= 0:
            return BreadcrumbDrop(False, owner, None, 0,
                                  f"{owner} has no breadcrumbs left ({ep.breadcrumbs_deployed} deployed)")
        p = np.asarray(position, dtype=float).reshape(-1)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            return BreadcrumbDrop(False, owner, None, ep.breadcrumbs,
                                  f"breadcrumb position must be 3 finite numbers, got {p.tolist()}")
        if not self.world.is_free(p[None])[0]:
            return BreadcrumbDrop(False, owner, None, ep.breadcrumbs,
                                  f"breadcrumb position {np.round(p, 2).tolist()} is inside rock")
        heard, best = self.mesh_heard_at(p, owner)
        if not heard:
            return BreadcrumbDrop(False, owner, None, ep.breadcrumbs,
                                  f"a breadcrumb at {np.round(p, 2).tolist()} would hear no mesh node{best}")
        ep.breadcrumbs -= 1
        ep.breadcrumbs_deployed += 1
        name = f"{owner}_breadcrumb_{ep.breadcrumbs_deployed}"
        self.breadcrumbs[name] = Breadcrumb(name, owner, p.copy(), float(self.now_s()))
        return BreadcrumbDrop(True, owner, name, ep.breadcrumbs)

    def mesh_heard_at(self, position: np.ndarray, owner: str | None = None) -> tuple[bool, str]:
        """Whether a relay at ``position`` would link to a mesh node on the air now (the
        base station, a relaying robot or an active breadcrumb; not ``owner``, which
        stands there, nor a client), and, when it would not, which node came closest
        (``" (best: NAME, margin M dB)"``, or "" with no node at all)."""
        nodes = {n: q for n, q in self.node_positions().items()
                 if n != owner and not self._is_client(n)}
        if not nodes:
            return False, ""
        names = list(nodes)
        p = np.asarray(position, float).reshape(1, 3)
        budgets = self._budgets(np.repeat(p, len(names), axis=0), np.array([nodes[n] for n in names]))
        if any(b.linked for b in budgets):
            return True, ""
        margins = [b.margin_db if math.isfinite(b.margin_db) else -math.inf for b in budgets]
        k = int(np.argmax(margins))
        margin = "out of range" if not math.isfinite(margins[k]) else f"margin {margins[k]:.1f} dB"
        return False, f" (best: {names[k]}, {margin})"

    def active_breadcrumbs(self) -> list[Breadcrumb]:
        """Breadcrumbs whose battery still runs (and that did not die), by name."""
        now = self.now_s()
        return [b for n, b in sorted(self.breadcrumbs.items())
                if now - b.deployed_s < self.spec.breadcrumb_battery_s and n not in self.dead_breadcrumbs]

    def node_positions(self) -> dict[str, np.ndarray]:
        """Current positions of every node (endpoints on the air, then active breadcrumbs)."""
        pos = {n: np.asarray(self._positions[n](), dtype=float).reshape(3) for n in sorted(self.endpoints)
               if not self.endpoints[n].off_air}
        pos.update({b.name: b.position.copy() for b in self.active_breadcrumbs()})
        return pos

    # ---- link state ---------------------------------------------------------------
    def linked(self, a: str, b: str) -> bool:
        """Whether a route joins ``a`` and ``b`` through the mesh (as of the last update)."""
        return self.route(a, b) is not None

    def direct_link(self, a: str, b: str) -> bool:
        """Whether one link joins ``a`` and ``b`` (as of the last update)."""
        return (min(a, b), max(a, b)) in self._links

    @property
    def links(self) -> list[tuple[str, str]]:
        """Current links as sorted name pairs."""
        return sorted(self._links)

    @property
    def link_states(self) -> list[LinkState]:
        """Current links with their budgets and quality, sorted by names."""
        return [LinkState(a, b, self._links[(a, b)]) for a, b in sorted(self._links)]

    def route(self, src: str, dst: str) -> list[str] | None:
        """Node names along the most reliable route from ``src`` to ``dst``, or None."""
        if src == dst:
            return [src] if src in self._graph else None
        if src not in self._graph or dst not in self._graph:
            return None
        if src not in self._routes:
            relay = {n: (self.endpoints[n].relay if n in self.endpoints else True) for n in self._graph}

            def weight(u: str, v: str, data: dict) -> float | None:
                return data["weight"] if (u == src or relay[u]) else None

            self._routes[src] = nx.single_source_dijkstra(self._graph, src, weight=weight)
        return list(self._routes[src][1][dst]) if dst in self._routes[src][1] else None

    def link_budget(self, a: np.ndarray, b: np.ndarray) -> LinkBudget:
        """The link model's figures between two positions (whatever nodes stand there)."""
        return self._budgets(np.asarray(a, float).reshape(1, 3), np.asarray(b, float).reshape(1, 3))[0]

    def _budgets(self, pa: np.ndarray, pb: np.ndarray) -> list[LinkBudget]:
        """Link budgets of position pairs (M, 3) x (M, 3), batched ray casts and samples."""
        s = self.spec
        m = len(pa)
        delta = pb - pa
        dist = np.linalg.norm(delta, axis=1)
        pl = s.path_loss_db(dist)
        los_margin = s.tx_power_dbm - pl - s.sensitivity_dbm
        reach = (dist <= s.range_m) & (los_margin >= 0.0)
        los = np.ones(m, dtype=bool)
        rock = np.zeros(m)
        crossings = np.zeros(m, dtype=int)
        idx = np.flatnonzero(reach & (dist > 0))
        if len(idx):
            d = dist[idx]
            dirs = delta[idx] / d[:, None]
            hit = self.world.cast_rays(pa[idx], dirs, float(d.max()))
            blocked = hit.astype(float) < d - 1e-6
            los[idx] = ~blocked
            bi = idx[blocked]
            if len(bi):
                rock[bi], crossings[bi] = self._rock_along(pa[bi], pb[bi])
                crossings[bi] = np.maximum(crossings[bi], 1)
        obstruction = np.where(los, 0.0, s.corner_loss_db * crossings + s.rock_loss_db_per_m * rock)
        rx = s.tx_power_dbm - pl - obstruction
        margin = np.where(reach, rx - s.sensitivity_dbm, -np.inf)
        loss = np.where(margin >= 0.0, s.attempt_loss(np.where(np.isfinite(margin), margin, 0.0)), 1.0)
        return [LinkBudget(float(dist[i]), bool(los[i]), float(rock[i]), int(crossings[i]), float(rx[i]),
                           float(margin[i]), float(loss[i])) for i in range(m)]

    def _rock_along(self, pa: np.ndarray, pb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Metres of rock and number of separate rock runs on each segment pa -> pb."""
        step = self.spec.rock_sample_step_m or 0.5 * self.world.voxel_size_m
        dist = np.linalg.norm(pb - pa, axis=1)
        n = np.maximum(np.ceil(dist / step).astype(int), 1)
        k = np.arange(int(n.max()))
        valid = k[None, :] < n[:, None]
        t = (k[None, :] + 0.5) / n[:, None]
        pts = pa[:, None, :] + t[..., None] * (pb - pa)[:, None, :]
        is_rock = np.zeros(valid.shape, dtype=bool)
        is_rock[valid] = ~self.world.is_free(pts[valid])
        thickness = is_rock.sum(axis=1) / n * dist
        starts = is_rock[:, 0].astype(int) + (is_rock[:, 1:] & ~is_rock[:, :-1]).sum(axis=1)
        return thickness, starts

    # ---- the update ---------------------------------------------------------------
    def update(self) -> None:
        """Re-evaluate links and deliver, once every ``update_period_s`` of sim time."""
        if self.now_s() + 1e-9 < self._next_update_s:
            return
        self._next_update_s = self.now_s() + self.spec.update_period_s
        self.refresh_links()
        for n in sorted(self.endpoints):
            self._deliver(self.endpoints[n])

    def _is_client(self, name: str) -> bool:
        """Whether node ``name`` is a WiFi client (an endpoint added with ``relay=False``)."""
        ep = self.endpoints.get(name)
        return ep is not None and not ep.relay

    def refresh_links(self) -> None:
        """Re-evaluate every link now (``update`` does this once a period)."""
        pos = self.node_positions()
        names = list(pos)
        pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
        self._links = {}
        if pairs:
            pa = np.array([pos[a] for a, _ in pairs])
            pb = np.array([pos[b] for _, b in pairs])
            for (a, b), budget in zip(pairs, self._budgets(pa, pb)):
                if self._is_client(a) and self._is_client(b):
                    continue  # a client joins an access point, never another client
                if budget.linked and (min(a, b), max(a, b)) not in self.cut_links:
                    self._links[(min(a, b), max(a, b))] = budget
        graph = nx.Graph()
        graph.add_nodes_from(names)
        for (a, b), budget in self._links.items():
            graph.add_edge(a, b, weight=-math.log(max(1.0 - budget.loss, _MIN_SUCCESS)))
        self._graph = graph
        self._routes = {}

    def _hops_survive(self, path: list[str]) -> bool:
        """Draw each hop of ``path`` in order; False at the first lost hop."""
        for u, v in itertools.pairwise(path):
            if self.rng.random() < self._links[(min(u, v), max(u, v))].loss:
                return False
        return True

    def ping(self, src: str, dst: str) -> bool:
        """An echo request from ``src`` to ``dst`` and its reply over the current route.

        False without a draw when no route exists; otherwise each hop of the request,
        then of the reply, is lost with its link's per-attempt loss.
        """
        ep = self.endpoints.get(src)
        if ep is not None:
            ep.pings += 1
        path = self.route(src, dst)
        if path is None:
            return False
        ok = self._hops_survive(path) and self._hops_survive(path[::-1])
        if ok and ep is not None:
            ep.pings_answered += 1
        return ok

    def _deliver(self, ep: RadioEndpoint) -> None:
        kept: deque[Message] = deque()
        while ep.outbox:
            msg = ep.outbox.popleft()
            target = self.endpoints.get(msg.recipient)
            path = self.route(ep.name, msg.recipient) if target is not None else None
            if path is not None and self._hops_survive(path):
                target.inbox.append(msg)
                ep.delivered += 1
            else:
                kept.append(msg)
        ep.outbox = kept
