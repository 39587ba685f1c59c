"""The Cave section of a SubT-Final-like course (see worldgen.subt_final): narrow
meandering passages and one large cavern, grown with worldgen.cave's
:class:`~delve.sim.worldgen_cave.CavePlan` inside a box of its own that keeps
clear of the other sections.

A breach runs from the hall's south wall into the box; a trunk passage meanders
from there down into the box and across to the end of the Tunnel section's
crossover drift, which it approaches from the south (so that it does not hug
the other sections); a cavern opens off
the middle of the trunk; side passages fill the rest of the section's length.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from .worldgen_cave import (CAVE_FLOOR_BAND_M, CAVE_MAX_SLOPE_DEG, CAVE_REACH, CAVE_STEP_M,
                            CavePlan, add_cave_branches)
from .worldgen_geometry import CLEARANCE_M
from .worldgen_subt_plan import CavePiece, CoursePlan, heading_of

#: Width of the breach from the hall into the cave and of the trunk's end at the
#: crossover drift (m).
CAVE_BREACH_WIDTH_M = 3.0
#: Share of the box's depth at which the trunk's waypoint lies.
TRUNK_WAYPOINT_DEPTH = 0.4
#: The trunk approaches the crossover drift's end from this far straight south of it (m).
TRUNK_APPROACH_M = 8.0
#: How far the cave's heading wanders per step while it heads for a goal (radians).
TRUNK_MEANDER_RAD = 0.35
#: The cavern opens off the trunk between these fractions of its samples.
CAVERN_ON_TRUNK = (0.3, 0.7)
#: Length of the narrow passage from the trunk to the cavern (m).
CAVERN_NECK_M = 15.0
#: Tries at growing the cavern (each off another trunk sample) before giving up.
CAVERN_TRIES = 16


@dataclass
class FencedCavePlan(CavePlan):
    """A CavePlan whose new samples must also stay inside a box and keep CLEARANCE_M
    of rock to some rectangles (the other sections), all in the plan's own frame."""

    box: tuple = (np.zeros(2), np.zeros(2))
    keep_out: list = field(default_factory=list)     # (lo xy, hi xy)

    def clear(self, q, w: float, h: float, path: np.ndarray) -> bool:
        r = CAVE_REACH * w
        lo, hi = self.box
        if q[0] - r < lo[0] or q[1] - r < lo[1] or q[0] + r > hi[0] or q[1] + r > hi[1]:
            return False
        for k_lo, k_hi in self.keep_out:
            gap = np.maximum(np.maximum(k_lo - q[:2], q[:2] - k_hi), 0.0)
            if float(np.hypot(*gap)) < r + CLEARANCE_M:
                return False
        return super().clear(q, w, h, path)


def plan_cave(plan: CoursePlan, rng: np.random.Generator, entry: int, target: int,
              box: tuple, keep_out: list, budget_m: float, width_m: tuple, height_m: tuple,
              cavern_width_m: float, cavern_height_m: float, cavern_length_m: float) -> None:
    """Grow the cave section, ``budget_m`` of centreline, from hall node ``entry`` (on
    the hall's south wall) into ``box`` (world xy (lo, hi)), its trunk ending at node
    ``target`` (the end of the Tunnel section's crossover drift); ``keep_out`` are world
    xy rectangles of the other sections. Adds its nodes and passages to ``plan``.
    ValueError when it does not fit."""
    centre = 0.5 * (np.asarray(box[0], float) + np.asarray(box[1], float))
    shift = np.array([centre[0], centre[1], 0.0])
    cp = FencedCavePlan(rng, tuple(width_m), tuple(height_m),
                        radius=0.5 * float(np.min(np.subtract(box[1], box[0]))),
                        box=(np.asarray(box[0], float) - centre, np.asarray(box[1], float) - centre),
                        keep_out=[(np.asarray(lo, float) - centre, np.asarray(hi, float) - centre)
                                  for lo, hi in keep_out])
    band = (-CAVE_FLOOR_BAND_M, CAVE_FLOOR_BAND_M)
    start, goal = plan.pos[entry] - shift, plan.pos[target] - shift
    root = start + [0.0, -(CAVE_BREACH_WIDTH_M + CLEARANCE_M + 3.0), 0.0]
    breach = _straight(cp, start, root)
    deep = np.array([root[0], cp.box[1][1] - TRUNK_WAYPOINT_DEPTH * (cp.box[1][1] - cp.box[0][1]),
                     0.0])
    tip = _toward(cp, breach[-1], deep, band)
    tip = _toward(cp, tip, goal - [0.0, TRUNK_APPROACH_M, 0.0], band)
    tip = _toward(cp, tip, goal, band, reach=True)
    trunk = list(range(breach[-1], tip + 1))
    _cavern(cp, trunk, cavern_width_m, cavern_height_m, cavern_length_m, band)
    add_cave_branches(cp, budget_m, band)
    got = cp.walk_length()
    if got < 0.9 * budget_m:
        raise ValueError(f"cannot fit a {budget_m:.0f} m cave section (only {got:.0f} m fitted): "
                         f"lower cave_length_m or raise the other sections' lengths")
    ids = []
    for i, p in enumerate(cp.pos):
        n = entry if i == 0 else target if i == tip else plan.add_node(p + shift, "cave")
        plan.cave[n] = CavePiece(cp.w[i], cp.h[i], cp.shape[i])
        ids.append(n)
    for i, j in cp.edges:
        plan.join(ids[i], ids[j], min(cp.w[i], cp.w[j]), min(cp.h[i], cp.h[j]), "cave", "cave",
                  "cave")


def _straight(cp: FencedCavePlan, a: np.ndarray, b: np.ndarray) -> list[int]:
    """Samples every CAVE_STEP_M on the straight line a -> b (a breach: no clearance
    check, it is meant to join what it touches); returns them in order."""
    n = max(int(math.ceil(np.linalg.norm(b - a) / CAVE_STEP_M)), 1)
    heading = heading_of(a, b)
    w = CAVE_BREACH_WIDTH_M
    out, shape = [], np.zeros((3, 2))
    for k in range(n + 1):
        shape = cp.new_shape(shape)
        out.append(cp.add(a + (b - a) * (k / n), w, cp.height_for(w, cp.height[1]), shape, 0,
                          heading))
        if k:
            cp.edges.append((out[-2], out[-1]))
    return out


def _toward(cp: FencedCavePlan, tip: int, goal: np.ndarray, band: tuple,
            reach: bool = False) -> int:
    """Meander from sample ``tip`` until within a step of ``goal`` (with ``reach``: on
    to a last sample at ``goal``); returns the last sample. ValueError when boxed in."""
    rng = cp.rng
    max_slope = math.radians(CAVE_MAX_SLOPE_DEG)
    steps = int(4 * np.linalg.norm((goal - cp.pos[tip])[:2]) / CAVE_STEP_M) + 8
    for _ in range(steps):
        p = cp.pos[tip]
        dist = float(np.hypot(*(goal - p)[:2]))
        if dist <= 1.2 * CAVE_STEP_M:
            break
        dist_g = nx.single_source_dijkstra_path_length(cp.graph(), tip)
        path = np.array([dist_g.get(i, np.inf) for i in range(len(cp.pos))])
        for attempt in range(12):
            hd = heading_of(p, goal) + rng.normal(0.0, TRUNK_MEANDER_RAD * (1 + attempt // 3))
            sl = float(np.clip(math.atan2(goal[2] - p[2], dist) + rng.normal(0.0, math.radians(3.0)),
                               -max_slope, max_slope))
            if not band[0] <= p[2] + CAVE_STEP_M * math.tan(sl) <= band[1]:
                sl = 0.0
            q = p + CAVE_STEP_M * np.array([math.cos(hd), math.sin(hd), math.tan(sl)])
            w = float(np.clip(cp.w[tip] * math.exp(rng.normal(0.0, 0.2)), *cp.width))
            h = cp.height_for(w, cp.height[1])
            if cp.clear(q, w, h, path + CAVE_STEP_M):
                new = cp.add(q, w, h, cp.new_shape(cp.shape[tip]), 0, hd)
                cp.edges.append((tip, new))
                tip = new
                break
        else:
            raise ValueError("cannot route the cave's trunk to the tunnel crossover: raise "
                             "cave_length_m or lower the cavern's size")
    else:
        raise ValueError("cannot route the cave's trunk to the tunnel crossover")
    if reach:
        w = min(CAVE_BREACH_WIDTH_M, cp.width[1])
        new = cp.add(goal, w, cp.height_for(w, cp.height[1]), cp.new_shape(cp.shape[tip]), 0,
                     heading_of(cp.pos[tip], goal))
        cp.edges.append((tip, new))
        tip = new
    return tip


def _cavern(cp: FencedCavePlan, trunk: list[int], width_m: float, height_m: float,
            length_m: float, band: tuple) -> None:
    """Grow the cavern off the middle of the trunk: a neck (a narrow passage
    CAVERN_NECK_M long, so that the cavern keeps its rock to the trunk), then a
    passage whose width stays within 80-100 % of ``width_m`` and whose height
    reaches ``height_m``."""
    rng = cp.rng
    lo, hi = (int(CAVERN_ON_TRUNK[0] * len(trunk)), int(CAVERN_ON_TRUNK[1] * len(trunk)) + 1)
    narrow, low = cp.width, cp.height
    for i in rng.permutation(trunk[lo:hi])[:CAVERN_TRIES]:
        i = int(i)
        for side in rng.permutation([-0.5 * math.pi, 0.5 * math.pi]):
            n_before, e_before = len(cp.pos), len(cp.edges)
            if _grown(cp, i, cp.heading[i] + float(side), CAVERN_NECK_M, narrow[1], band) \
                    >= 0.9 * CAVERN_NECK_M:
                cp.width = (0.8 * width_m, width_m)
                cp.height = (max(low[0], 0.8 * height_m), height_m)
                got = _grown(cp, len(cp.pos) - 1, cp.heading[-1], length_m, height_m, band)
                cp.width, cp.height = narrow, low
                if got >= 0.6 * length_m:
                    return
            del cp.pos[n_before:], cp.w[n_before:], cp.h[n_before:], cp.shape[n_before:]
            del cp.level[n_before:], cp.heading[n_before:], cp.edges[e_before:]
    raise ValueError(f"cannot fit a cavern {width_m:g} m wide in the cave section: raise "
                     f"cave_length_m or lower cavern_width_m")


def _grown(cp: FencedCavePlan, start: int, heading: float, length_m: float, hmax: float,
           band: tuple) -> float:
    """Grow one passage of the plan's current widths from sample ``start``; returns its length."""
    e_before = len(cp.edges)
    cp.grow(start, None, heading, length_m, 0, cp.width, hmax, band)
    return sum(float(np.linalg.norm(cp.pos[b] - cp.pos[a])) for a, b in cp.edges[e_before:])
