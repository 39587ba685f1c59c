"""The Urban section of a SubT-Final-like course (see worldgen.subt_final): two
levels of square-section corridors with rooms, a staircase between them and a
second, descending staircase that crosses over to the Tunnel section.

Layout (x east, y north): a lower spine corridor runs east from the hall's north
breach; branch corridors run north off it every BRANCH_SPACING_M with rooms
(boxes behind a wall, one door each) on both sides. At the spine's east end a
staircase climbs north to the upper level, whose spine runs back west above the
lower rooms (a slab of URBAN_LEVEL_RISE_M - ROOM_HEIGHT_M between them) with its
own branches and rooms. East of the first staircase a second one descends from
the upper level to the foot the Tunnel section's crossover drift starts from.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .worldgen_geometry import CLEARANCE_M
from .worldgen_subt_plan import CoursePlan

#: Floor-to-floor height of the two urban levels (m).
URBAN_LEVEL_RISE_M = 5.0
#: Width and height of an urban corridor (a square section) and of a staircase (m).
CORRIDOR_M = 3.0
#: Rooms: height, depth (across the corridor) and length (along it), metres.
ROOM_HEIGHT_M = 3.0
ROOM_DEPTH_M = (5.0, 7.0)
ROOM_LENGTH_M = (5.0, 9.0)
#: Wall between a room and its corridor, and between neighbouring rooms (m).
WALL_M = 0.8
#: A room's door: width and height (m).
DOOR_WIDTH_M = 1.6
DOOR_HEIGHT_M = 2.4
#: Rock between the rooms of neighbouring branches (m).
ROOM_GAP_M = 1.2
#: Distance between neighbouring branch corridors (m).
BRANCH_SPACING_M = CORRIDOR_M + 2 * (WALL_M + ROOM_DEPTH_M[1]) + ROOM_GAP_M
#: Most centreline length (corridor and rooms) one branch takes before another is added.
BRANCH_MAX_M = 40.0
#: Shortest share of the urban length a branch may get (m).
BRANCH_MIN_M = 5.0


@dataclass(frozen=True)
class UrbanPlan:
    """Where the urban section ended up: the foot of its crossover staircase (a node
    on the lower level that the Tunnel section joins), and its box in the plan."""

    crossover_foot: int
    lo: np.ndarray
    hi: np.ndarray


def plan_urban(plan: CoursePlan, rng: np.random.Generator, entry: int, y0: float,
               budget_m: float, stair_slope_deg: float) -> UrbanPlan:
    """Lay out the urban section from hall node ``entry`` (on the hall's north wall),
    its lower spine at y = ``y0``, ``budget_m`` of centreline (within a few cm).
    ValueError when the budget does not hold the corridors and staircases."""
    w, rise = CORRIDOR_M, URBAN_LEVEL_RISE_M
    run = rise / math.tan(math.radians(stair_slope_deg))
    reach = 0.5 * w + WALL_M + ROOM_DEPTH_M[1]          # a branch's rooms, from its axis
    x0, z0 = float(plan.pos[entry][0]), float(plan.pos[entry][2])
    stair = math.hypot(run, rise)

    def layout(nb: int):
        xs = [x0 + (k + 0.5) * BRANCH_SPACING_M for k in range(nb)]
        x_s = xs[-1] + reach + CLEARANCE_M + 0.5 * w + 0.5            # first staircase
        x_c = x_s + w + CLEARANCE_M + 2.0                            # the descending one
        fixed = ((y0 - plan.pos[entry][1]) + (x_s - x0) + (w + stair) + (x_s - xs[0])
                 + (x_c - x_s) + (0.5 * w + stair))
        return xs, x_s, x_c, (budget_m - fixed) / (2 * nb)

    nb = 1
    xs, x_s, x_c, share = layout(nb)
    while share > BRANCH_MAX_M:
        nb += 1
        xs, x_s, x_c, share = layout(nb)
    if share < BRANCH_MIN_M:
        need = budget_m - 2 * nb * (share - BRANCH_MIN_M)
        raise ValueError(f"the urban section needs at least {need:.0f} m for its corridors and "
                         f"staircases, got {budget_m:.0f} m: raise urban_length_m or scale")

    y1, z1 = y0 + w + run, z0 + rise
    a0 = plan.add_node([x0, y0, z0], "urban")
    plan.join(entry, a0, w, w, "corridor", "urban", "corridor")
    lower = _spine(plan, a0, [x for x in xs if x > x0] + [x_s], y0, z0, 0)
    f1 = plan.add_node([x_s, y0 + 0.5 * w, z0], "urban")
    t1 = plan.add_node([x_s, y0 + 0.5 * w + run, z1], "urban", 1)
    j1 = plan.add_node([x_s, y1, z1], "urban", 1)
    plan.join(lower[-1], f1, w, w, "corridor", "urban", "corridor")
    plan.join(f1, t1, w, w, "stairs", "urban", "corridor")
    plan.join(t1, j1, w, w, "corridor", "urban", "corridor")
    upper = _spine(plan, j1, xs[::-1], y1, z1, 1)[::-1]
    j2 = plan.add_node([x_c, y1, z1], "urban", 1)
    t2 = plan.add_node([x_c, y1 - 0.5 * w, z1], "urban", 1)
    foot = plan.add_node([x_c, y1 - 0.5 * w - run, z0], "urban")
    plan.join(j1, j2, w, w, "corridor", "urban", "corridor")
    plan.join(j2, t2, w, w, "corridor", "urban", "corridor")
    plan.join(t2, foot, w, w, "stairs", "urban", "corridor")

    roots = [(lower[k], 0) for k in range(nb)] + [(upper[k], 1) for k in range(nb)]
    tops = []
    left = budget_m - plan.section_length("urban")
    for i, (root, level) in enumerate(roots):
        tops.append(_branch(plan, rng, root, level, left / (len(roots) - i)))
        left = budget_m - plan.section_length("urban")
    lo = np.array([x0 - w, y0 - w, z0])
    hi = np.array([x_c + w, max(tops) + w, z1 + ROOM_HEIGHT_M])
    return UrbanPlan(foot, lo, hi)


def _spine(plan: CoursePlan, start: int, xs: list[float], y: float, z: float,
           level: int) -> list[int]:
    """A corridor along x from node ``start`` through the points at ``xs``; returns
    the nodes at ``xs``."""
    nodes, prev = [], start
    for x in xs:
        n = plan.add_node([x, y, z], "urban", level)
        plan.join(prev, n, CORRIDOR_M, CORRIDOR_M, "corridor", "urban", "corridor")
        nodes.append(n)
        prev = n
    return nodes


def _branch(plan: CoursePlan, rng: np.random.Generator, root: int, level: int,
            share_m: float) -> float:
    """A branch corridor north from spine node ``root`` with rooms on both sides, taking
    ``share_m`` of centreline (corridor, doors to room centres and a dead-end tail).
    Returns the y of its north end."""
    w = CORRIDOR_M
    x, y_root, z = plan.pos[root]
    used, prev, y = 0.0, root, y_root + 0.5 * w + WALL_M
    while True:
        length = float(rng.uniform(*ROOM_LENGTH_M))
        depth = rng.uniform(*ROOM_DEPTH_M, size=2)
        yc = y + 0.5 * length
        cost = (yc - plan.pos[prev][1]) + float(np.sum(0.5 * w + WALL_M + 0.5 * depth))
        if used + cost > share_m:
            break
        node = plan.add_node([x, yc, z], "urban", level)
        plan.join(prev, node, w, w, "corridor", "urban", "corridor")
        for side, d in zip((1.0, -1.0), depth):
            _room(plan, node, side, float(d), length, level)
        used += cost
        prev, y = node, y + length + WALL_M
    tail = share_m - used
    end = plan.pos[prev][1] + tail
    if tail > 1e-6:
        node = plan.add_node([x, end, z], "urban", level)
        plan.join(prev, node, w, w, "corridor", "urban", "corridor")
    return max(end, y)


def _room(plan: CoursePlan, door_node: int, side: float, depth: float, length: float,
          level: int) -> None:
    """A room beside the corridor at ``door_node`` (east for side +1, west for -1):
    a box behind a wall, a door through it, and a centreline edge to its centre."""
    x, yc, z = plan.pos[door_node]
    near = x + side * (0.5 * CORRIDOR_M + WALL_M)
    far = near + side * depth
    plan.add_box([min(near, far), yc - 0.5 * length, z], [max(near, far), yc + 0.5 * length,
                                                          z + ROOM_HEIGHT_M])
    wall = x + side * 0.5 * CORRIDOR_M
    plan.add_box([min(wall, near) - 0.1, yc - 0.5 * DOOR_WIDTH_M, z],
                 [max(wall, near) + 0.1, yc + 0.5 * DOOR_WIDTH_M, z + DOOR_HEIGHT_M])
    centre = plan.add_node([0.5 * (near + far), yc, z], "urban", level)
    plan.join(door_node, centre, DOOR_WIDTH_M, DOOR_HEIGHT_M, "room", "urban", "box")
