"""The plan of a SubT-Final-like course (see worldgen.subt_final): its centreline
nodes and passages, each tagged with its section, and how they are carved.

A passage is carved by its ``shape``: ``"tunnel"`` an arched mine drift
(:func:`~delve.sim.worldgen_geometry.carve_tunnel`, with round junction chambers),
``"corridor"`` a straight passage of square section (urban corridors and stairs),
``"cave"`` a natural passage between two cave samples
(:func:`~delve.sim.worldgen_geometry.carve_cave_segment`), ``"box"`` nothing of
its own (the hall, rooms and doors are boxes carved beside the graph).
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from .world import World
from .worldgen_cave import CAVE_REACH, joined_cap_rise
from .worldgen_geometry import (GRID_MARGIN_M, VoxelCanvas, assemble_world, carve_cave_segment, carve_chamber,
                                carve_tunnel, cave_section_top, horizontal_frame)

#: Junction chamber radius of mine drifts as a fraction of the widest drift there.
CHAMBER_RADIUS_FACTOR = 0.6
#: A chamber's floor rises at most this much per metre with a climbing drift (tan 30 deg).
MAX_CHAMBER_RISE = 0.6
#: The sections of the course, in the order the course is laid out.
SECTIONS = ("entrance", "hall", "tunnel", "urban", "cave")


@dataclass
class Passage:
    """One centreline edge and how it is carved."""

    a: int
    b: int
    width: float
    height: float
    kind: str            # what the graph calls it: tunnel, ramp, corridor, stairs, room, hall, cave
    section: str
    shape: str           # how it is carved: tunnel, corridor, cave, box


@dataclass
class CavePiece:
    """A cave sample's cross-section: width, height and harmonic shape (see carve_cave_segment)."""

    width: float
    height: float
    shape: np.ndarray


@dataclass
class CoursePlan:
    """Centreline nodes (floor points), passages and boxes of a course under construction."""

    pos: list = field(default_factory=list)
    section: list = field(default_factory=list)
    level: list = field(default_factory=list)
    passages: list[Passage] = field(default_factory=list)
    boxes: list = field(default_factory=list)        # (lo, hi) world boxes carved free
    cave: dict = field(default_factory=dict)         # node -> CavePiece

    def add_node(self, p, section: str, level: int = 0) -> int:
        """Add a floor point; returns its id."""
        self.pos.append(np.asarray(p, float))
        self.section.append(section)
        self.level.append(level)
        return len(self.pos) - 1

    def join(self, a: int, b: int, width: float, height: float, kind: str, section: str,
             shape: str) -> Passage:
        """Join two nodes by a passage."""
        p = Passage(a, b, float(width), float(height), kind, section, shape)
        self.passages.append(p)
        return p

    def length(self, p: Passage) -> float:
        """Centreline length of a passage."""
        return float(np.linalg.norm(self.pos[p.b] - self.pos[p.a]))

    def section_length(self, section: str) -> float:
        """Walkable centreline length of one section."""
        return sum(self.length(p) for p in self.passages if p.section == section)

    def add_box(self, lo, hi) -> None:
        """Carve the box [lo, hi] free (a hall, a room, a door)."""
        self.boxes.append((np.asarray(lo, float), np.asarray(hi, float)))

    # ------------------------------------------------------------------ carving
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """World box holding every passage, box and chamber."""
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for b_lo, b_hi in self.boxes:
            lo, hi = np.minimum(lo, b_lo), np.maximum(hi, b_hi)
        for p in self.passages:
            pa, pb = self.pos[p.a], self.pos[p.b]
            if p.shape == "cave":
                ca, cb = self.cave[p.a], self.cave[p.b]
                reach = CAVE_REACH * max(ca.width, cb.width)
                top = max(cave_section_top(ca.height), cave_section_top(cb.height))
            else:
                reach = CHAMBER_RADIUS_FACTOR * p.width          # a drift's chambers reach furthest
                top = p.height + MAX_CHAMBER_RISE * reach
            lo = np.minimum(lo, np.minimum(pa, pb) - [reach, reach, 0.0])
            hi = np.maximum(hi, np.maximum(pa, pb) + [reach, reach, top])
        return lo, hi

    def carve(self, canvas: VoxelCanvas) -> None:
        """Carve every box, passage and mine junction chamber into the canvas."""
        for lo, hi in self.boxes:
            carve_box(canvas, lo, hi)
        sloped = {n for p in self.passages if abs(self.pos[p.a][2] - self.pos[p.b][2]) > 1e-6
                  for n in (p.a, p.b)}
        caves = Counter(n for p in self.passages if p.shape == "cave" for n in (p.a, p.b))
        for p in self.passages:
            pa, pb = self.pos[p.a], self.pos[p.b]
            if p.shape == "tunnel":
                carve_tunnel(canvas, pa, pb, p.width, p.height)
            elif p.shape == "corridor":
                # flat corridors run on half a width past their ends, so that corners are
                # square; never where a stair starts (its foot would get a step)
                ext = [0.0 if n in sloped else 0.5 * p.width for n in (p.a, p.b)]
                carve_corridor(canvas, pa, pb, p.width, p.height, ext[0], ext[1])
            elif p.shape == "cave":
                ca, cb = self.cave[p.a], self.cave[p.b]
                carve_cave_segment(canvas, pa, pb, ca.width, cb.width, ca.height, cb.height,
                                   ca.shape, cb.shape, joined_cap_rise(caves[p.a], caves[p.b]))
        for n, (r, h, upward) in self.chambers().items():
            carve_chamber(canvas, self.pos[n], r, h, upward)

    def chambers(self) -> dict[int, tuple[float, float, list]]:
        """Round chambers (radius, height, climbing passages) at every mine-drift node
        (junctions, bends and rounded dead ends, as in worldgen.tunnel_network)."""
        drifts: dict[int, list[Passage]] = {}
        meeting: dict[int, list[Passage]] = {}
        for p in self.passages:
            for n in (p.a, p.b):
                meeting.setdefault(n, []).append(p)
                if p.shape == "tunnel":
                    drifts.setdefault(n, []).append(p)
        out = {}
        for n, ps in sorted(drifts.items()):
            upward = []
            for p in meeting[n]:         # the floor rises with every passage that climbs away
                d = self.pos[p.b if p.a == n else p.a] - self.pos[n]
                run = float(np.hypot(d[0], d[1]))
                if d[2] > 0 and run > 1e-9:
                    upward.append((d[:2] / run, d[2] / run))
            out[n] = (CHAMBER_RADIUS_FACTOR * max(p.width for p in ps),
                      max(p.height for p in ps), upward)
        return out

    # -------------------------------------------------------------------- world
    def graph(self) -> nx.Graph:
        """The centreline: nodes with pos, level, section; edges with width_m, height_m,
        kind, length_m, section."""
        g = nx.Graph()
        for n, p in enumerate(self.pos):
            g.add_node(n, pos=p.copy(), level=self.level[n], section=self.section[n])
        for p in self.passages:
            g.add_edge(p.a, p.b, width_m=p.width, height_m=p.height, kind=p.kind,
                       length_m=self.length(p), section=p.section)
        return g

    def build(self, name: str, voxel_size_m: float, start: int) -> World:
        """Carve the plan into a grid (ValueError when over the voxel limit) and wrap it in a World."""
        lo, hi = self.bounds()
        canvas = VoxelCanvas(lo, hi, voxel_size_m)
        self.carve(canvas)
        crop_to_free(canvas)
        return assemble_world(name, canvas, self.graph(), self.pos[start])


def crop_to_free(canvas: VoxelCanvas, margin_m: float = GRID_MARGIN_M) -> None:
    """Shrink the canvas to its free voxels and ``margin_m`` of rock around them (the
    plan's box is generous: cave sections and chambers are bounded loosely)."""
    m = int(math.ceil(margin_m / canvas.voxel_size_m))
    lo, hi = np.zeros(3, int), np.zeros(3, int)
    for a in range(3):
        used = np.flatnonzero(canvas.free.any(axis=tuple(b for b in range(3) if b != a)))
        lo[a], hi[a] = max(used[0] - m, 0), min(used[-1] + m + 1, canvas.shape[a])
    canvas.free = np.ascontiguousarray(canvas.free[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]])
    canvas.origin = canvas.origin + lo * canvas.voxel_size_m
    canvas.shape = tuple(int(n) for n in canvas.free.shape)


def carve_box(canvas: VoxelCanvas, lo, hi) -> None:
    """Carve free every voxel whose centre lies in the world box [lo, hi]."""
    win = canvas.window(lo, hi)
    if win is None:
        return
    sl, xs, ys, zs = win
    inside = ((xs >= lo[0]) & (xs <= hi[0]) & (ys >= lo[1]) & (ys <= hi[1]))[..., None] \
        & (zs >= lo[2]) & (zs <= hi[2])
    canvas.free[sl] |= inside


def carve_corridor(canvas: VoxelCanvas, a, b, width_m: float, height_m: float,
                   extend_a_m: float = 0.0, extend_b_m: float = 0.0) -> None:
    """Carve a straight passage of rectangular section from floor point a to b.

    The floor follows the segment (a stair is a steep one: on the voxel grid its
    floor rises in steps of one voxel), the roof lies ``height_m`` above it; the
    passage runs on ``extend_a_m`` / ``extend_b_m`` past its ends at the end's height.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    length, u, n = horizontal_frame(a, b)
    if length < 1e-9:
        return
    half = 0.5 * width_m
    reach = half + max(extend_a_m, extend_b_m)
    lo = np.minimum(a, b) - [reach, reach, 0.0]
    hi = np.maximum(a, b) + [reach, reach, height_m]
    win = canvas.window(lo, hi)
    if win is None:
        return
    sl, xs, ys, zs = win
    x, y = xs - a[0], ys - a[1]
    along = x * u[0] + y * u[1]
    lat = x * n[0] + y * n[1]
    ok = (along >= -extend_a_m) & (along <= length + extend_b_m) & (np.abs(lat) <= half)
    floor = a[2] + np.clip(along / length, 0.0, 1.0) * (b[2] - a[2])
    canvas.free[sl] |= ok[..., None] & (zs >= floor[..., None]) & (zs <= floor[..., None] + height_m)


def heading_of(a, b) -> float:
    """Horizontal heading (radians) from point a to point b."""
    return math.atan2(float(b[1] - a[1]), float(b[0] - a[0]))
