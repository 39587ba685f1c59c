"""Planning and carving of mine tunnel networks (see worldgen.tunnel_network).

A :class:`MinePlan` grows the centreline on a jittered square lattice, checks
that new tunnels keep CLEARANCE_M of rock to the tunnels they do not join,
and :func:`build_mine` carves the plan into a voxel grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from .world import World
from .worldgen_geometry import (CLEARANCE_M, SHAFT_RADIUS_M, VoxelCanvas, assemble_world,
                                carve_chamber, carve_shaft, carve_tunnel, segment_slabs, slab,
                                slabs_conflict, snap_toward_zero)

#: Floor-to-floor rise between the levels of a two-level mine or up a gallery shaft.
LEVEL_RISE_M = (12.0, 15.0)
#: Junctions move off their lattice site by up to this fraction of the spacing.
LATTICE_JITTER = 0.12
#: Junction chamber radius as a fraction of the widest tunnel that meets there.
CHAMBER_RADIUS_FACTOR = 0.6
#: Edges climbing at more than this fraction of the slope limit are kind "ramp".
RAMP_SLOPE_FRACTION = 0.75
#: Floor kept around a shaft mouth in the upper chamber, so robots can pass it.
SHAFT_MOUTH_MARGIN_M = 2.0
#: A climbing tunnel is flat for this fraction of the widest tunnel at each end
#: (worldgen_geometry.landing_floor), past the flat floors of the tunnels it meets;
#: it climbs at its slope in between. At least CHAMBER_RADIUS_FACTOR, so junction
#: chambers stay flat.
LANDING_FACTOR = 0.7
#: Smallest horizontal angle between two passages leaving one junction: closer
#: ones would run into each other (the clearance check skips passages that share
#: a junction), e.g. a drift laid under a ramp's climb.
MIN_BRANCH_ANGLE_DEG = 45.0
#: Lattice steps: the four directions a tunnel may leave a junction in.
LATTICE_DIRECTIONS = ((1, 0), (0, 1), (-1, 0), (0, -1))


@dataclass
class _Node:
    pos: np.ndarray
    level: int
    site: tuple[int, int] | None
    grow: bool = True
    min_chamber_r: float = 0.0


@dataclass
class _Edge:
    a: int
    b: int
    width: float
    height: float
    kind: str

    @property
    def walkable(self) -> bool:
        """Whether robots can walk along it (everything but shafts)."""
        return self.kind != "shaft"


@dataclass
class MinePlan:
    """The centreline of a mine under construction, with its clearance checks."""

    rng: np.random.Generator
    spacing: float
    voxel: float
    max_slope: float                 # radians
    width: tuple[float, float]
    height: tuple[float, float]
    nodes: list[_Node] = field(default_factory=list)
    edges: list[_Edge] = field(default_factory=list)
    sites: list[dict] = field(default_factory=lambda: [{}, {}])
    shaft_radius: dict = field(default_factory=dict)   # edge index -> radius

    # -- bookkeeping
    def add_node(self, pos, level, site=None, grow=True) -> int:
        """Add a junction (floor point) on a level, at a lattice site if given; returns its id."""
        self.nodes.append(_Node(np.asarray(pos, float), level, site, grow))
        if site is not None:
            self.sites[level][site] = len(self.nodes) - 1
        return len(self.nodes) - 1

    def add_edge(self, a, b, kind=None, width=None, height=None) -> int:
        """Join two nodes; size drawn from the ranges and kind from the slope unless given."""
        w = self.draw_width() if width is None else width
        h = self.draw_height() if height is None else height
        if kind is None:
            kind = "ramp" if self.slope(a, b) >= RAMP_SLOPE_FRACTION * self.max_slope else "tunnel"
        self.edges.append(_Edge(a, b, w, h, kind))
        return len(self.edges) - 1

    def draw_width(self) -> float:
        """A tunnel width drawn from the width range."""
        return float(self.rng.uniform(*self.width))

    def draw_height(self) -> float:
        """A tunnel height drawn from the height range."""
        return float(self.rng.uniform(*self.height))

    @property
    def landing(self) -> float:
        """Length of the flat floor at each end of a climbing tunnel (m)."""
        return LANDING_FACTOR * self.width[1]

    def climb_run(self, horizontal: float) -> float:
        """Horizontal run over which a tunnel of this horizontal length climbs (between landings)."""
        return max(horizontal - 2.0 * self.landing, 0.0)

    def rise_over(self, horizontal: float, slope_tan: float) -> float:
        """Floor rise (snapped to the voxel) of a tunnel climbing at ``slope_tan`` between its landings."""
        return snap_toward_zero(self.climb_run(horizontal) * slope_tan, self.voxel)

    def slope(self, a: int, b: int) -> float:
        """Slope (radians) of the floor between two nodes where it climbs (between the landings)."""
        pa, pb = self.nodes[a].pos, self.nodes[b].pos
        dz = abs(pb[2] - pa[2])
        if dz < 1e-9:
            return 0.0
        return math.atan2(dz, self.climb_run(float(np.hypot(*(pb[:2] - pa[:2])))))

    def passage_slabs(self, pa: np.ndarray, pb: np.ndarray, width: float,
                      height: float) -> np.ndarray:
        """Clearance samples of a tunnel from floor point pa to pb (with its landings)."""
        return segment_slabs(pa, pb, 0.5 * width, height, landing_m=self.landing)

    def bearing_clear(self, n: int, xy: np.ndarray) -> bool:
        """Whether a passage from node n towards ``xy`` leaves it at least
        MIN_BRANCH_ANGLE_DEG away (horizontally) from every walkable passage there."""
        p = self.nodes[n].pos[:2]
        new = np.asarray(xy[:2], float) - p
        for e in self.edges:
            if n not in (e.a, e.b) or not e.walkable:
                continue
            old = self.nodes[e.b if e.a == n else e.a].pos[:2] - p
            cos = float(new @ old) / max(float(np.linalg.norm(new) * np.linalg.norm(old)), 1e-12)
            if cos > math.cos(math.radians(MIN_BRANCH_ANGLE_DEG)):
                return False
        return True

    def length(self, e: _Edge) -> float:
        """Centreline length of an edge."""
        return float(np.linalg.norm(self.nodes[e.b].pos - self.nodes[e.a].pos))

    def walk_length(self) -> float:
        """Total centreline length of the walkable edges."""
        return sum(self.length(e) for e in self.edges if e.walkable)

    def neighbours(self, n: int) -> list[int]:
        """Nodes joined to node n."""
        return [e.b if e.a == n else e.a for e in self.edges if n in (e.a, e.b)]

    def has_edge(self, a: int, b: int) -> bool:
        """Whether nodes a and b are already joined."""
        return any({e.a, e.b} == {a, b} for e in self.edges)

    def site_xy(self, site: tuple[int, int]) -> np.ndarray:
        """Horizontal position of a lattice site."""
        return np.array([site[0], site[1]], float) * self.spacing

    def jittered(self, site: tuple[int, int]) -> np.ndarray:
        """A lattice site's position moved by a random jitter."""
        jitter = self.rng.uniform(-LATTICE_JITTER, LATTICE_JITTER, 2)
        return self.site_xy(site) + jitter * self.spacing

    # -- clearance
    def chamber_at(self, p: np.ndarray) -> np.ndarray:
        """Clearance sample of a junction chamber of the usual size at floor point p."""
        return slab(p[0], p[1], CHAMBER_RADIUS_FACTOR * self.width[1], p[2],
                    p[2] + self.height[1])

    def chamber_slab(self, n: int) -> np.ndarray:
        """Clearance sample of the junction chamber at node n."""
        p = self.nodes[n].pos
        r = max(CHAMBER_RADIUS_FACTOR * self.width[1], self.nodes[n].min_chamber_r)
        return slab(p[0], p[1], r, p[2], p[2] + self.height[1])

    def elements(self):
        """(clearance samples, incident node set) of every planned passage."""
        out = [(self.chamber_slab(n), {n}) for n in range(len(self.nodes))]
        for i, e in enumerate(self.edges):
            pa, pb = self.nodes[e.a].pos, self.nodes[e.b].pos
            if e.kind == "shaft":
                lo, hi = min(pa[2], pb[2]), max(pa[2], pb[2])
                out.append((slab(pa[0], pa[1], self.shaft_radius[i], lo, hi), {e.a, e.b}))
            else:
                out.append((self.passage_slabs(pa, pb, e.width, e.height), {e.a, e.b}))
        return out

    def clear(self, samples: np.ndarray, incident: set) -> bool:
        """True when the samples keep CLEARANCE_M of rock to every non-incident passage."""
        for s, inc in self.elements():
            if inc & incident:
                continue
            if slabs_conflict(samples, s, CLEARANCE_M):
                return False
        return True

    def edge_is_clear(self, a: int, pb: np.ndarray) -> bool:
        """Whether a tunnel from node a to a new node at floor point pb keeps its clearance
        (and leaves a away from the passages already there)."""
        pa = self.nodes[a].pos
        if not self.bearing_clear(a, pb):
            return False
        samples = self.passage_slabs(pa, pb, self.width[1], self.height[1])
        if not self.clear(samples, {a}):
            return False
        return self.clear(self.chamber_at(pb), {a})

    # -- growth
    def frontier(self, level: int, region) -> list[tuple[int, tuple, tuple]]:
        """(parent node, free site, direction) for every way the level's tree can grow."""
        out = []
        (i0, i1), (j0, j1) = region
        for n, node in enumerate(self.nodes):
            if node.level != level or not node.grow or node.site is None:
                continue
            for d in LATTICE_DIRECTIONS:
                s = (node.site[0] + d[0], node.site[1] + d[1])
                if i0 <= s[0] < i1 and j0 <= s[1] < j1 and s not in self.sites[level]:
                    out.append((n, s, d))
        return out

    def incoming_direction(self, n: int):
        """Lattice direction of the tunnel node n was reached by (None for the root)."""
        node = self.nodes[n]
        for m in self.neighbours(n):
            other = self.nodes[m]
            if other.level == node.level and other.site is not None and node.site is not None \
                    and m < n:
                return (node.site[0] - other.site[0], node.site[1] - other.site[1])
        return None

    def choose_rise(self, z0: float, horizontal: float, band: tuple[float, float],
                    steep: bool) -> float:
        """Floor rise of a new tunnel: flat, gentle or (if allowed) steep, kept in the band."""
        u = self.rng.random()
        tmax = math.tan(self.max_slope)
        if u < 0.5:
            frac = 0.0
        elif u < 0.9 or not steep:
            frac = self.rng.uniform(0.15, 0.5)
        else:
            frac = self.rng.uniform(0.8, 1.0)
        slope = math.tan(frac * self.max_slope) if frac > 0 else 0.0
        dz = self.rise_over(horizontal, min(slope, tmax))
        signs = [s for s in (1.0, -1.0) if band[0] <= z0 + s * dz <= band[1]]
        if signs:
            return float(self.rng.choice(signs)) * dz
        toward = -1.0 if z0 > 0.5 * (band[0] + band[1]) else 1.0
        room = (z0 - band[0]) if toward < 0 else (band[1] - z0)
        return toward * min(dz, snap_toward_zero(max(room, 0.0), self.voxel))

    def grow(self, level: int, region: list, budget: float, band: tuple[float, float],
             steep: bool, trim: bool, site_weight=None, max_edges: int | None = None) -> int:
        """Grow the level's tree edge by edge (a random, straight-biased spanning tree).

        Stops once the walkable length reaches ``budget``; with ``trim`` the
        last tunnel is cut short so the length is met exactly. The region
        widens when the tree runs out of room. Returns the edges added.
        """
        added = 0
        min_len = max(0.25 * self.spacing, 1.5 * self.width[1])
        stuck = 0
        while self.walk_length() < budget - 1e-6 and (max_edges is None or added < max_edges):
            cands = self.frontier(level, region)
            if not cands:
                stuck += 1
                if stuck > 6:
                    break
                region[0] = (region[0][0], region[0][1] + 1)
                region[1] = (region[1][0] - 1, region[1][1] + 1)
                continue
            weights = np.array([(3.0 if self.incoming_direction(n) == d else 1.0)
                                * (site_weight(s) if site_weight else 1.0)
                                for n, s, d in cands])
            order = self.rng.choice(len(cands), size=len(cands), replace=False,
                                    p=weights / weights.sum())
            placed = False
            for k in order:
                n, s, d = cands[k]
                parent = self.nodes[n]
                below = self.sites[0].get(s, -1) if level == 1 else -1
                xy = self.nodes[below].pos[:2].copy() if below >= 0 else self.jittered(s)
                horizontal = float(np.linalg.norm(xy - parent.pos[:2]))
                dz = self.choose_rise(parent.pos[2], horizontal, band, steep)
                pb = np.array([xy[0], xy[1], parent.pos[2] + dz])
                full = float(np.linalg.norm(pb - parent.pos))
                remaining = budget - self.walk_length()
                trimmed = False
                if trim and full > remaining:
                    if remaining < min_len:
                        return added
                    pb = self.shortened(parent.pos, pb, remaining / full)
                    trimmed = True
                if not self.edge_is_clear(n, pb):
                    continue
                m = self.add_node(pb, level, s, grow=not trimmed)
                self.add_edge(n, m)
                added += 1
                placed = True
                break
            if not placed:
                # every candidate conflicts: block those sites and widen the search
                for n, s, d in cands:
                    self.sites[level].setdefault(s, -1)
                stuck += 1
                if stuck > 6:
                    break
        return added

    def shortened(self, pa: np.ndarray, pb: np.ndarray, fraction: float) -> np.ndarray:
        """Floor point ``fraction`` of the way (horizontally) from pa to pb, its rise cut
        so that the tunnel from pa climbs no steeper between its landings."""
        horizontal = float(np.hypot(*(pb[:2] - pa[:2])))
        run = self.climb_run(horizontal)
        out = pa + (pb - pa) * fraction
        tan = abs(pb[2] - pa[2]) / run if run > 0 else 0.0
        out[2] = pa[2] + math.copysign(self.rise_over(fraction * horizontal, tan), pb[2] - pa[2])
        return out

    def close_loops(self, loops: int) -> int:
        """Join lattice neighbours on the lower level that the tree left apart."""
        if loops <= 0:
            return 0
        g = nx.Graph()
        g.add_edges_from((e.a, e.b) for e in self.edges)
        cands = []
        for s, n in sorted(self.sites[0].items()):
            if n < 0 or not self.nodes[n].grow:
                continue
            for d in ((1, 0), (0, 1)):
                m = self.sites[0].get((s[0] + d[0], s[1] + d[1]))
                if m is None or m < 0 or not self.nodes[m].grow or self.has_edge(n, m):
                    continue
                if self.slope(n, m) > self.max_slope + 1e-9:
                    continue
                cands.append((n, m, nx.shortest_path_length(g, n, m)))
        added = 0
        if cands:
            w = np.array([c[2] for c in cands], float)
            for k in self.rng.choice(len(cands), size=len(cands), replace=False, p=w / w.sum()):
                if added == loops:
                    break
                n, m, _ = cands[k]
                pa, pb = self.nodes[n].pos, self.nodes[m].pos
                if self.bearing_clear(n, pb) and self.bearing_clear(m, pa) and \
                        self.clear(self.passage_slabs(pa, pb, self.width[1], self.height[1]),
                                   {n, m}):
                    self.add_edge(n, m)
                    added += 1
        return added

    def shrink_leaves(self, excess: float) -> None:
        """Shorten dead-end tunnels (towards their junction) to cut ``excess`` metres."""
        min_len = max(0.25 * self.spacing, 1.5 * self.width[1])
        deg: dict[int, int] = {}
        for e in self.edges:
            deg[e.a] = deg.get(e.a, 0) + 1
            deg[e.b] = deg.get(e.b, 0) + 1
        for e in self.edges:
            if excess <= 1e-9:
                return
            if not e.walkable or self.nodes[e.a].level != self.nodes[e.b].level:
                continue
            for leaf, hub in ((e.b, e.a), (e.a, e.b)):
                if deg[leaf] != 1 or leaf == 0:
                    continue
                length = self.length(e)
                cut = min(excess, length - min_len)
                if cut <= 0:
                    break
                p_hub, p_leaf = self.nodes[hub].pos, self.nodes[leaf].pos
                self.nodes[leaf].pos = self.shortened(p_hub, p_leaf, (length - cut) / length)
                self.nodes[leaf].grow = False
                excess -= cut
                break

    def ensure_steep_edge(self) -> None:
        """Make sure some lower tunnel climbs at 75-100 % of the slope limit (a leaf edge)."""
        if any(e.kind == "ramp" for e in self.edges):
            return
        deg = {}
        for e in self.edges:
            deg[e.a] = deg.get(e.a, 0) + 1
            deg[e.b] = deg.get(e.b, 0) + 1
        leaves = [i for i, e in enumerate(self.edges)
                  if deg[e.b] == 1 and e.b != 0 and self.nodes[e.b].level == 0]
        for i in self.rng.permutation(len(leaves)) if leaves else []:
            e = self.edges[leaves[i]]
            pa, pb = self.nodes[e.a].pos, self.nodes[e.b].pos
            horizontal = float(np.hypot(*(pb[:2] - pa[:2])))
            dz = self.rise_over(horizontal, math.tan(0.9 * self.max_slope))
            for sign in sorted((1.0, -1.0), key=lambda s: abs(pa[2] + s * dz)):
                old = pb.copy()
                pb[2] = pa[2] + sign * dz
                if self.slope(e.a, e.b) >= RAMP_SLOPE_FRACTION * self.max_slope and \
                        self.clear(self.passage_slabs(pa, pb, e.width, e.height), {e.a, e.b}):
                    e.kind = "ramp"
                    return
                pb[:] = old


def mine_regions(n_sites: int) -> list:
    """Lattice index ranges [(i0, i1), (j0, j1)] roomy enough for about n_sites junctions."""
    side = max(int(math.ceil(math.sqrt(n_sites))) + 1, 2)
    return [(0, side), (-(side // 2), side - side // 2)]



def add_upper_level(plan: MinePlan, rise: float, ramp: bool, shaft: bool,
                     share: float, region: list) -> None:
    """Second level ``rise`` above the portal, reached by a ramp and/or a shaft."""
    rng, s = plan.rng, plan.spacing
    z_up = plan.nodes[0].pos[2] + rise
    lower = [n for n, node in enumerate(plan.nodes) if node.level == 0 and node.grow]
    root = None
    if ramp:
        root = _add_level_ramp(plan, lower, z_up, near_lower=shaft)
        if root is None:
            raise ValueError("cannot route a ramp between the levels clear of the other "
                             "tunnels: raise spacing_m or total_length_m")
    else:
        for n in rng.permutation(lower):
            if n == 0:
                continue
            p = plan.nodes[int(n)].pos
            top = np.array([p[0], p[1], z_up])
            if plan.clear(plan.chamber_at(top), set()):
                root = plan.add_node(top, 1, plan.nodes[int(n)].site)
                break
        if root is None:
            raise ValueError("cannot place the upper level above the lower one")

    (i0, i1), (j0, j1) = region
    lower_sites = {st for st, n in plan.sites[0].items() if n >= 0}

    def toward_lower(site):   # head for the nearest lower junction to stand a shaft on
        d = min(abs(site[0] - t[0]) + abs(site[1] - t[1]) for t in lower_sites)
        return 8.0 ** -d

    def weight(site):
        if shaft:
            return toward_lower(site)
        if site in lower_sites:
            return 3.0
        return 1.0 if (i0 <= site[0] < i1 and j0 <= site[1] < j1) else 0.2

    ri = plan.nodes[root].site
    up_region = [(min(i0, ri[0]) - 1, max(i1, ri[0] + 1) + 1),
                 (min(j0, ri[1]) - 1, max(j1, ri[1] + 1) + 1)]
    band = (z_up - 1.0, z_up + 1.0)
    ramp_len = sum(plan.length(e) for e in plan.edges if e.kind == "ramp"
                   and plan.nodes[e.a].level != plan.nodes[e.b].level)
    budget = plan.walk_length() + max(share - ramp_len, s)
    plan.grow(1, up_region, budget, band, steep=False, trim=False, site_weight=weight)
    if shaft:
        for _ in range(8):
            if _add_level_shaft(plan):
                return
            plan.grow(1, up_region, math.inf, band, steep=False, trim=False,
                      site_weight=toward_lower, max_edges=1)
        raise ValueError("cannot place a shaft between the levels: raise total_length_m")


def _add_level_ramp(plan: MinePlan, lower: list[int], z_up: float,
                    near_lower: bool) -> int | None:
    """A long straight ramp from a lower node out to the upper level's first node.

    With ``near_lower`` the ramps whose top lands closest to a lower junction
    are tried first (a shaft will have to join the levels there too).
    """
    rng, s = plan.rng, plan.spacing
    lower_sites = [st for st, n in plan.sites[0].items() if n >= 0]
    cands = []
    for n in lower:
        node = plan.nodes[n]
        dz = z_up - node.pos[2]
        steepest = dz / math.tan(0.95 * plan.max_slope) + 2.0 * plan.landing
        kmin = max(int(round(steepest / s)), 1)
        taken = {tuple(np.subtract(plan.nodes[m].site, node.site)) for m in plan.neighbours(n)
                 if plan.nodes[m].site is not None}
        for d in LATTICE_DIRECTIONS:
            if d in taken:
                continue
            for k in (kmin - 1, kmin, kmin + 1, kmin + 2):
                top = (node.site[0] + k * d[0], node.site[1] + k * d[1])
                gap = min(abs(top[0] - t[0]) + abs(top[1] - t[1]) for t in lower_sites
                          if t != node.site) if near_lower and len(lower_sites) > 1 else 0
                cands.append((gap, k, rng.random(), n, d))
    cands.sort()
    for _, k, _, n, d in cands:
        node = plan.nodes[n]
        # the ramp climbs at 80-95 % of the slope limit, so its top is off the lattice
        dz = z_up - node.pos[2]
        run = dz / math.tan(rng.uniform(0.8, 0.95) * plan.max_slope) + 2.0 * plan.landing
        site = (node.site[0] + k * d[0], node.site[1] + k * d[1])
        if site in plan.sites[1] or run > (k + 0.5) * s or run < (k - 0.5) * s:
            continue
        xy = node.pos[:2] + run * np.asarray(d, float)
        top = np.array([xy[0], xy[1], z_up])
        w, h = plan.draw_width(), plan.draw_height()
        samples = plan.passage_slabs(node.pos, top, w, h)
        if plan.bearing_clear(n, top) and plan.clear(samples, {n}) and \
                plan.clear(plan.chamber_at(top), set()):
            root = plan.add_node(top, 1, site)
            plan.add_edge(n, root, kind="ramp", width=w, height=h)
            return root
    return None


def _add_level_shaft(plan: MinePlan) -> bool:
    """A vertical shaft from a lower node up to the upper node right above it."""
    rng = plan.rng
    pairs = []
    for site, u in sorted(plan.sites[1].items()):
        low = plan.sites[0].get(site)
        if u < 0 or low is None or low < 0:
            continue
        if np.allclose(plan.nodes[u].pos[:2], plan.nodes[low].pos[:2]):
            pairs.append((low, u))
    for k in rng.permutation(len(pairs)):
        low, up = pairs[int(k)]
        if _try_shaft(plan, low, up):
            return True
    return False


def _try_shaft(plan: MinePlan, low: int, up: int) -> bool:
    """Sink a shaft from node ``low`` up to node ``up`` (straight above) if it keeps clear."""
    r = float(plan.rng.uniform(*SHAFT_RADIUS_M))
    pl, pu = plan.nodes[low].pos, plan.nodes[up].pos
    if pu[2] - pl[2] < plan.height[1] + CLEARANCE_M + 1.0:
        return False
    if not plan.clear(slab(pl[0], pl[1], r, pl[2], pu[2]), {low, up}):
        return False
    old = plan.nodes[up].min_chamber_r
    plan.nodes[up].min_chamber_r = r + SHAFT_MOUTH_MARGIN_M
    if not plan.clear(plan.chamber_slab(up), {up}):
        plan.nodes[up].min_chamber_r = old
        return False
    plan.nodes[low].min_chamber_r = max(plan.nodes[low].min_chamber_r, r)
    i = plan.add_edge(low, up, kind="shaft", width=2 * r, height=pu[2] - pl[2])
    plan.shaft_radius[i] = r
    return True


def add_gallery(plan: MinePlan, rise: float) -> None:
    """A shaft from a lower node up to a small dead-end gallery (one or two short drives)."""
    rng, s = plan.rng, plan.spacing
    lower = [n for n, node in enumerate(plan.nodes) if node.level == 0 and node.grow and n != 0]
    lower = lower or [0]
    for n in rng.permutation(lower):
        n = int(n)
        p = plan.nodes[n].pos
        top = np.array([p[0], p[1], p[2] + rise])
        if not plan.clear(plan.chamber_at(top), set()):
            continue
        g = plan.add_node(top, 1, None, grow=False)
        low_r = plan.nodes[n].min_chamber_r
        if not _try_shaft(plan, n, g):
            plan.nodes.pop()
            continue
        wanted = 1 + int(rng.random() < 0.5)
        made = 0
        for d in rng.permutation(len(LATTICE_DIRECTIONS)):
            if made == wanted:
                break
            ang = math.atan2(*LATTICE_DIRECTIONS[int(d)][::-1]) + rng.uniform(-0.2, 0.2)
            run = rng.uniform(0.45, 0.7) * s
            end = top + [run * math.cos(ang), run * math.sin(ang), 0.0]
            if plan.edge_is_clear(g, end):
                m = plan.add_node(end, 1, None, grow=False)
                plan.add_edge(g, m, kind="tunnel")
                made += 1
        if made:
            return
        plan.edges.pop()                      # the shaft up to the failed gallery
        plan.shaft_radius.pop(len(plan.edges))
        plan.nodes.pop()
        plan.nodes[n].min_chamber_r = low_r
    raise ValueError("cannot place a shaft and gallery above the network: raise total_length_m")


def build_mine(plan: MinePlan, name: str) -> World:
    """Carve the planned mine into a voxel grid and wrap it in a World."""
    nodes, edges = plan.nodes, plan.edges
    incident: dict[int, list[_Edge]] = {n: [] for n in range(len(nodes))}
    for e in edges:
        incident[e.a].append(e)
        incident[e.b].append(e)
    chambers = []
    for n, node in enumerate(nodes):
        walk = [e for e in incident[n] if e.walkable]
        if not walk:
            r, h = max(node.min_chamber_r, CHAMBER_RADIUS_FACTOR * plan.width[0]), plan.height[0]
        else:
            r = max(CHAMBER_RADIUS_FACTOR * max(e.width for e in walk), node.min_chamber_r)
            h = max(e.height for e in walk)
        upward = []
        for e in walk:
            other = nodes[e.b if e.a == n else e.a].pos
            d = other - node.pos
            run = float(np.hypot(d[0], d[1]))
            if d[2] > 0 and run > 1e-9:
                upward.append((d[:2] / run, d[2] / plan.climb_run(run)))
        chambers.append((node.pos, r, h, upward))

    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for pos, r, h, upward in chambers:
        rise = max([sl * max(r - plan.landing, 0.0) for _, sl in upward], default=0.0)
        lo = np.minimum(lo, pos - [r, r, 0.0])
        hi = np.maximum(hi, pos + [r, r, h + rise])
    for e in edges:
        pa, pb = nodes[e.a].pos, nodes[e.b].pos
        half = 0.5 * e.width
        lo = np.minimum(lo, np.minimum(pa, pb) - [half, half, 0.0])
        hi = np.maximum(hi, np.maximum(pa, pb) + [half, half, e.height])

    canvas = VoxelCanvas(lo, hi, plan.voxel)
    for i, e in enumerate(edges):
        pa, pb = nodes[e.a].pos, nodes[e.b].pos
        if e.kind == "shaft":
            low, up = (pa, pb) if pa[2] <= pb[2] else (pb, pa)
            carve_shaft(canvas, low[:2], plan.shaft_radius[i], low[2], up[2])
        else:
            carve_tunnel(canvas, pa, pb, e.width, e.height, plan.landing)
    for pos, r, h, upward in chambers:
        carve_chamber(canvas, pos, r, h, upward, plan.landing)

    graph = nx.Graph()
    for n, node in enumerate(nodes):
        graph.add_node(n, pos=node.pos.copy(), level=node.level)
    for e in edges:
        graph.add_edge(e.a, e.b, width_m=e.width, height_m=e.height, kind=e.kind,
                       length_m=plan.length(e), landing_m=0.0 if e.kind == "shaft" else plan.landing)
    return assemble_world(name, canvas, graph, nodes[0].pos)
