"""Planning and carving of natural caves (see worldgen.cave).

A :class:`CavePlan` grows meandering passages sample by sample, checks that
each new sample keeps CLEARANCE_M of rock to the passages it is not next to
along the centreline, and :func:`build_cave` carves the plan into a grid.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from .world import World
from .worldgen_geometry import (CLEARANCE_M, SHAFT_RADIUS_M, VoxelCanvas, assemble_world,
                                carve_cave_segment, carve_shaft, cave_section_top, slabs_conflict)

#: Horizontal distance between centreline samples of a cave passage.
CAVE_STEP_M = 2.5
#: Distance between the control points of a passage's width profile.
CAVE_PROFILE_STEP_M = 10.0
#: Half-length of the stretch over which a passage keeps each control width.
CAVE_PLATEAU_M = 2.5
#: Chance that a control point of a passage is a squeeze (width within 1 m of
#: the minimum) or a chamber (at least 85 % of the maximum width).
CAVE_SQUEEZE_P = 0.15
CAVE_CHAMBER_P = 0.10
#: Horizontal reach of a cave section as a fraction of its width (shape noise included).
CAVE_REACH = 0.65
#: Steepest floor slope of a cave passage.
CAVE_MAX_SLOPE_DEG = 12.0
#: Lower-level cave floors stay within this many metres of the entrance.
CAVE_FLOOR_BAND_M = 3.0
#: Passages at most this far apart along the centreline may touch.
CAVE_NEIGHBOUR_PATH_M = 4.0


@dataclass
class CavePlan:
    """Centreline samples of a cave under construction, with clearance checks."""

    rng: np.random.Generator
    width: tuple[float, float]
    height: tuple[float, float]
    radius: float                          # soft horizontal extent around the entrance
    pos: list = field(default_factory=list)          # floor points
    w: list = field(default_factory=list)
    h: list = field(default_factory=list)
    shape: list = field(default_factory=list)        # (3, 2) harmonic amplitudes
    level: list = field(default_factory=list)
    heading: list = field(default_factory=list)
    edges: list = field(default_factory=list)        # (i, j)
    shafts: list = field(default_factory=list)       # (low, up, radius)

    def walk_length(self) -> float:
        """Total centreline length of the passages (shafts excluded)."""
        return sum(float(np.linalg.norm(self.pos[j] - self.pos[i])) for i, j in self.edges)

    def graph(self) -> nx.Graph:
        """The samples joined by their passages, weighted by length."""
        g = nx.Graph()
        g.add_nodes_from(range(len(self.pos)))
        g.add_weighted_edges_from((i, j, float(np.linalg.norm(self.pos[j] - self.pos[i])))
                                  for i, j in self.edges)
        return g

    def add(self, p, w, h, shape, level, heading) -> int:
        """Add a centreline sample (floor point and section); returns its index."""
        self.pos.append(np.asarray(p, float))
        self.w.append(float(w))
        self.h.append(float(h))
        self.shape.append(np.asarray(shape, float))
        self.level.append(level)
        self.heading.append(float(heading))
        return len(self.pos) - 1

    def slabs(self) -> np.ndarray:
        """Clearance samples (x, y, radius, floor, ceiling) of every centreline sample."""
        if not self.pos:
            return np.zeros((0, 5))
        p = np.array(self.pos)
        w = np.array(self.w)
        top = np.array([cave_section_top(h) for h in self.h])
        return np.column_stack([p[:, 0], p[:, 1], CAVE_REACH * w, p[:, 2], p[:, 2] + top])

    def height_for(self, w: float, hmax: float) -> float:
        """A passage height to go with width w: wide passages are tall ones."""
        wl, wh = self.width
        frac = 0.0 if wh == wl else (w - wl) / (wh - wl)
        frac = float(np.clip(frac ** 0.6 * self.rng.uniform(0.75, 1.1), 0.0, 1.0))
        return float(np.clip(self.height[0] + frac * (self.height[1] - self.height[0]),
                             self.height[0], hmax))

    def profile(self, length: float, first_w: float | None, widths: tuple[float, float],
                force: tuple = ()) -> tuple:
        """Control widths every CAVE_PROFILE_STEP_M along a passage: squeezes, chambers, between.

        ``force`` names control kinds ("squeeze", "chamber") that must appear
        early in the passage; ``first_w`` fixes the width where it starts.
        """
        lo, hi = widths
        n = max(int(math.ceil(length / CAVE_PROFILE_STEP_M)) + 1, 2)
        squeeze = (lo, min(lo + 1.0, hi))
        chamber = (max(0.85 * hi, lo), hi)
        mid = (min(lo + 1.0, hi), max(0.45 * hi, min(lo + 1.0, hi)))
        kinds = []
        for _ in range(n):
            u = self.rng.random()
            kinds.append("squeeze" if u < CAVE_SQUEEZE_P
                         else "chamber" if u < CAVE_SQUEEZE_P + CAVE_CHAMBER_P else "mid")
        early = {"chamber": 2, "squeeze": 4}     # forced features come early, while
        for k in force:                         # the passage is sure to get there
            slots = list(range(1, min(n, early[k] + 1)))
            if slots and k not in [kinds[i] for i in slots]:
                kinds[int(self.rng.choice(slots))] = k
        ws = []
        for k in kinds:
            a, b = {"squeeze": squeeze, "chamber": chamber, "mid": mid}[k]
            ws.append(float(math.exp(self.rng.uniform(math.log(a), math.log(b)))))
        if first_w is not None:
            ws[0] = first_w
        return np.array(ws)

    def grow(self, start: int | None, p0, heading: float, length: float, level: int,
             widths: tuple[float, float], hmax: float, z_band: tuple[float, float],
             first_w: float | None = None, force: tuple = (), max_slope_deg=CAVE_MAX_SLOPE_DEG
             ) -> int:
        """Grow one meandering passage from sample ``start`` (or from point p0 if None).

        Steps of CAVE_STEP_M with a wandering heading and floor slope; stops at
        ``length`` (the last step cut short to match it) or when every
        heading it tries would come too close to another passage. Returns the
        number of samples added.
        """
        rng = self.rng
        ctrl = self.profile(length, first_w, widths, force)
        # each control width holds over a plateau, so squeezes and chambers have length
        centres = np.arange(len(ctrl)) * CAVE_PROFILE_STEP_M
        knots = np.ravel(np.column_stack([centres - CAVE_PLATEAU_M, centres + CAVE_PLATEAU_M]))
        knot_w = np.repeat(ctrl, 2)
        if start is None:
            shape = self.new_shape(np.zeros((3, 2)))
            w0 = float(ctrl[0])
            start = self.add(p0, w0, self.height_for(w0, hmax), shape, level, heading)
        g = self.graph()
        dist = nx.single_source_dijkstra_path_length(g, start)
        path = np.array([dist.get(i, np.inf) for i in range(len(self.pos))])
        arc, slope, added, tip = 0.0, 0.0, 0, start
        max_slope = math.radians(max_slope_deg)
        while arc < length - 0.3:
            placed = False
            for attempt in range(12):
                turn = rng.normal(0.0, 0.25 if attempt == 0 else 0.7)
                hd = heading + turn
                p_tip = self.pos[tip]
                dist_c = float(np.hypot(p_tip[0], p_tip[1])) if level == 0 else 0.0
                if dist_c > self.radius:      # wander back towards the entrance
                    back = math.atan2(-p_tip[1], -p_tip[0])
                    hd += 0.4 * math.atan2(math.sin(back - hd), math.cos(back - hd))
                sl = float(np.clip(0.8 * slope + rng.normal(0.0, math.radians(3.0)),
                                   -max_slope, max_slope))
                if p_tip[2] > z_band[1]:
                    sl = -abs(sl)
                elif p_tip[2] < z_band[0]:
                    sl = abs(sl)
                step = np.array([math.cos(hd), math.sin(hd), math.tan(sl)]) * CAVE_STEP_M
                step *= min(1.0, (length - arc) / float(np.linalg.norm(step)))
                q = p_tip + step
                s_here = arc + float(np.linalg.norm(step))
                w = float(np.interp(s_here, knots, knot_w))
                if attempt >= 8:        # no room: the passage pinches in instead
                    w = max(widths[0], 0.5 * w)
                h = self.height_for(w, hmax)
                if not self.clear(q, w, h, path + (s_here - arc)):
                    continue
                shape = self.new_shape(self.shape[tip])
                new = self.add(q, w, h, shape, level, hd)
                self.edges.append((tip, new))
                path = np.append(path + (s_here - arc), 0.0)
                tip, heading, slope, arc, added = new, hd, sl, s_here, added + 1
                placed = True
                break
            if not placed:
                break
        return added

    def new_shape(self, prev: np.ndarray) -> np.ndarray:
        """Next harmonic amplitudes of the cross-section: a slow random walk."""
        sigma = np.array([0.06, 0.08, 0.05])[:, None]
        rho = 0.7
        c = rho * prev + math.sqrt(1 - rho * rho) * self.rng.normal(0.0, 1.0, (3, 2)) * sigma
        total = np.abs(c).sum()
        return c * (0.3 / total) if total > 0.3 else c

    def clear(self, q, w: float, h: float, path: np.ndarray) -> bool:
        """Whether a new sample keeps CLEARANCE_M of rock to passages it is not next to."""
        s = self.slabs()
        far = path > CAVE_REACH * w + s[:, 2] + CLEARANCE_M + CAVE_NEIGHBOUR_PATH_M
        if not far.any():
            return True
        mine = np.array([[q[0], q[1], CAVE_REACH * w, q[2], q[2] + cave_section_top(h)]])
        return not slabs_conflict(mine, s[far], CLEARANCE_M)



def add_cave_branches(plan: CavePlan, target: float, band) -> None:
    """Add side passages off the lower level until the centreline is ``target`` long."""
    rng = plan.rng
    for _ in range(400):
        remaining = target - plan.walk_length()
        if remaining < 0.3:
            return
        lower = [i for i in range(len(plan.pos)) if plan.level[i] == 0]
        deg = np.zeros(len(plan.pos), int)
        for i, j in plan.edges:
            deg[i] += 1
            deg[j] += 1
        cands = [i for i in lower if deg[i] <= 2]
        b = int(rng.choice(cands))
        side = rng.choice([-1.0, 1.0])
        heading = plan.heading[b] + side * rng.uniform(math.radians(50), math.radians(110))
        length = min(remaining, float(rng.uniform(0.12, 0.3)) * target)
        if remaining - length < CAVE_STEP_M:
            length = remaining
        squeeze = () if any(w <= plan.width[0] + 1.0 for w in plan.w) else ("squeeze",)
        plan.grow(b, None, heading, length, 0, plan.width, plan.height[1], band,
                  first_w=plan.w[b], force=squeeze)
    # a crowded cave: let passages wander further out
    plan.radius *= 1.5


def add_cave_upper(plan: CavePlan, shaft_h: float, length: float) -> float:
    """Vertical shaft from a lower passage up to an otherwise unconnected upper passage."""
    rng = plan.rng
    wl, wh = plan.width
    r = float(min(rng.uniform(*SHAFT_RADIUS_M), 0.4 * wh))
    root_w = min(wh, 2 * r + 3.0)
    up_w = (max(wl, min(2.0, wh)), max(min(wh, 8.0), max(wl, min(2.0, wh))))
    up_hmax = max(min(plan.height[1], 5.0), plan.height[0])
    g = plan.graph()
    slabs = plan.slabs()
    order = rng.permutation(len(plan.pos))
    for i in order:
        i = int(i)
        p = plan.pos[i]
        if i == 0 or plan.level[i] != 0 or plan.w[i] < 2 * r:
            continue
        if p[2] + cave_section_top(plan.h[i]) + CLEARANCE_M > p[2] + shaft_h:
            continue
        dist = nx.single_source_dijkstra_path_length(g, i)
        path = np.array([dist.get(k, np.inf) for k in range(len(plan.pos))])
        far = path > r + CAVE_REACH * np.array(plan.w) + CLEARANCE_M + CAVE_NEIGHBOUR_PATH_M
        column = np.array([[p[0], p[1], r, p[2], p[2] + shaft_h + cave_section_top(up_hmax)]])
        if slabs_conflict(column, slabs[far], CLEARANCE_M):
            continue
        top = p + [0.0, 0.0, shaft_h]
        up_band = (top[2] - 1.0, top[2] + 1.0)
        best = None
        for _ in range(6):
            n_before, e_before = len(plan.pos), len(plan.edges)
            heading = float(rng.uniform(-math.pi, math.pi))
            plan.grow(None, top, heading, length, 1, up_w, up_hmax, up_band,
                      first_w=root_w, max_slope_deg=6.0)
            got = sum(float(np.linalg.norm(plan.pos[b] - plan.pos[a]))
                      for a, b in plan.edges[e_before:])
            if got >= 0.5 * length and got > 0:
                best = (n_before, got)
                break
            del plan.pos[n_before:], plan.w[n_before:], plan.h[n_before:]
            del plan.shape[n_before:], plan.level[n_before:], plan.heading[n_before:]
            del plan.edges[e_before:]
        if best is None:
            continue
        plan.shafts.append((i, best[0], r))
        return best[1]
    raise ValueError("cannot place the shaft and upper passage: raise total_length_m or "
                     "change shaft_height_m")


def joined_cap_rise(degree_a: int, degree_b: int) -> tuple[float, float]:
    """The cap rise of a segment whose ends join ``degree`` segments each: the cave's
    slope limit where another segment goes on, level at a dead end."""
    rise = math.tan(math.radians(CAVE_MAX_SLOPE_DEG))
    return (rise if degree_a > 1 else 0.0, rise if degree_b > 1 else 0.0)


def build_cave(plan: CavePlan, name: str, v: float) -> World:
    """Carve the planned cave into a voxel grid and wrap it in a World."""
    s = plan.slabs()
    lo = np.array([(s[:, 0] - s[:, 2]).min(), (s[:, 1] - s[:, 2]).min(), s[:, 3].min()])
    hi = np.array([(s[:, 0] + s[:, 2]).max(), (s[:, 1] + s[:, 2]).max(), s[:, 4].max()])
    canvas = VoxelCanvas(lo, hi, v)
    degree = Counter(n for edge in plan.edges for n in edge)
    for i, j in plan.edges:
        carve_cave_segment(canvas, plan.pos[i], plan.pos[j], plan.w[i], plan.w[j],
                           plan.h[i], plan.h[j], plan.shape[i], plan.shape[j],
                           joined_cap_rise(degree[i], degree[j]))
    for low, up, r in plan.shafts:
        carve_shaft(canvas, plan.pos[low][:2], r, plan.pos[low][2], plan.pos[up][2])

    graph = nx.Graph()
    for i, p in enumerate(plan.pos):
        graph.add_node(i, pos=p.copy(), level=plan.level[i])
    for i, j in plan.edges:
        graph.add_edge(i, j, width_m=min(plan.w[i], plan.w[j]),
                       height_m=min(plan.h[i], plan.h[j]), kind="cave",
                       length_m=float(np.linalg.norm(plan.pos[j] - plan.pos[i])))
    for low, up, r in plan.shafts:
        rise = float(plan.pos[up][2] - plan.pos[low][2])
        graph.add_edge(low, up, width_m=2 * r, height_m=rise, kind="shaft", length_m=rise)
    return assemble_world(name, canvas, graph, plan.pos[0])
