"""A seeded course like the DARPA SubT Final's (see worldgen.subt_final).

The Final's course (CERBERUS paper, Section 4.2): a single entrance through an
inclined tunnel and a steep turn, an opening with three breaches into a Tunnel,
an Urban and a Cave section, and crossovers between the sections. Here (x east,
y north, the hall floor at z = 0):

- entrance: from the portal (the start) a narrow drift descends at
  ``entrance_slope_deg``, turns sharply (ENTRANCE_TURN_DEG) and runs into the
  hall's west wall;
- hall: a high box (the staging area) with breaches east (Tunnel), north
  (Urban) and south (Cave);
- tunnel: two or three parallel mine drifts (east from the hall) joined by
  crosscuts, with dead-end side cuts between them (no rails: the floor is flat);
- urban: worldgen_subt_urban (two levels of corridors and rooms, a staircase);
- cave: worldgen_subt_cave (narrow meandering passages, one large cavern);
- crossovers: a descending staircase from the upper urban level and a drift
  join the Urban and the Tunnel section; a drift from the southern drift meets
  the cave's trunk.

The sections are laid out in boxes that keep CLEARANCE_M of rock between them,
so passages meet only where the plan joins them.
"""
from __future__ import annotations

import math

import numpy as np

from .limits import DEFAULT_VOXEL_SIZE_M, check_voxels, voxel_count
from .world import World
from .worldgen_geometry import CLEARANCE_M, GRID_MARGIN_M, snap_height
from .worldgen_subt_cave import plan_cave
from .worldgen_subt_plan import CHAMBER_RADIUS_FACTOR, CoursePlan
from .worldgen_subt_urban import CORRIDOR_M, plan_urban

#: The entrance: horizontal run of the incline, the turn at its foot (degrees), the
#: drift from the turn to the hall (m), and the drift's width and height (m): the
#: Final started with a narrow tunnel.
ENTRANCE_RUN_M = 30.0
ENTRANCE_TURN_DEG = 100.0
ENTRANCE_LEG_M = 12.0
ENTRANCE_SIZE_M = 3.5
#: The hall: length (x), width (y) and height (m).
HALL_SIZE_M = (24.0, 16.0, 8.0)
#: Tunnel section: distance between parallel drifts, between survey stations along
#: a drift, the drifts' width and height ranges (m).
DRIFT_SPACING_M = 20.0
DRIFT_STATION_M = 15.0
DRIFT_WIDTH_M = (3.5, 4.5)
DRIFT_HEIGHT_M = (3.5, 4.5)
#: Stations wander this far across the drift (m) and the floor this far up or down,
#: by steps of about DRIFT_GRADE_STEP_M (grades of 1-3 %, so that drifts meeting at a
#: junction leave no step in its floor).
DRIFT_JITTER_M = 1.5
DRIFT_GRADE_M = 0.5
DRIFT_GRADE_STEP_M = 0.2
#: A crosscut joins neighbouring drifts at every this many stations.
CROSSCUT_EVERY = 4
#: Side cuts: length range (m, fits between two drifts) and largest angle off square.
SIDE_CUT_M = (4.0, 10.0)
SIDE_CUT_SKEW_DEG = 15.0
#: Drift from the hall's east wall to the first station (m).
TUNNEL_BREACH_M = 6.0
#: Below this many metres the tunnel section has two drifts, else three.
THREE_DRIFTS_FROM_M = 300.0
#: The crossover drift to the cave leaves the southern drift this far along it.
CAVE_CROSSOVER_AT = 0.7
#: ... and ends this far south of the Tunnel section's box, where the cave's trunk meets it.
CAVE_CROSSOVER_OUT_M = 3.0
#: Cave section: passage width and height ranges (m), the cavern's length as a share
#: of the section (within 0.75-2 cavern widths), the box's area per metre of passage
#: (m^2/m), its least depth and how far it reaches west of the hall (m).
CAVE_WIDTH_M = (1.6, 5.0)
CAVE_HEIGHT_M = (2.2, 4.5)
CAVERN_LENGTH_SHARE = 0.12
CAVE_AREA_PER_M = 10.0
CAVE_MIN_DEPTH_M = 30.0
CAVE_WEST_M = 30.0
#: Steepest slope a legged robot is given (entrance, stairs): GBPlanner2's default
#: limit (planners/gbplanner2/config.py), under the legged platform's 35 degrees.
MAX_WALKABLE_SLOPE_DEG = 30.0
#: Allowed relative error of each section's centreline length.
SECTION_TOLERANCE = 0.10


def plan_entrance_and_hall(plan: CoursePlan, slope_deg: float, v: float) -> dict[str, int]:
    """The portal, the incline, the turn and the hall; returns the node ids by name
    (portal, hall, and the breaches west, east, north, south)."""
    hx, hy, hz = 0.5 * HALL_SIZE_M[0], 0.5 * HALL_SIZE_M[1], HALL_SIZE_M[2]
    plan.add_box([-hx, -hy, 0.0], [hx, hy, hz])
    ids = {"hall": plan.add_node([0.0, 0.0, 0.0], "hall")}
    for name, xy, width in (("west", (-hx, 0.0), HALL_SIZE_M[1]), ("east", (hx, 0.0), HALL_SIZE_M[1]),
                            ("north", (0.0, hy), HALL_SIZE_M[0]), ("south", (0.0, -hy), HALL_SIZE_M[0])):
        ids[name] = plan.add_node([xy[0], xy[1], 0.0], "hall")
        plan.join(ids["hall"], ids[name], width, hz, "hall", "hall", "box")
    turn = plan.add_node([-hx - ENTRANCE_LEG_M, 0.0, 0.0], "entrance")
    down = -math.radians(ENTRANCE_TURN_DEG)           # heading down the incline
    rise = snap_height(ENTRANCE_RUN_M * math.tan(math.radians(slope_deg)), v)
    s = ENTRANCE_SIZE_M
    heading = np.array([math.cos(down), math.sin(down), 0.0])
    # a flat landing of one drift width between the incline and the turn, so that the
    # drift on from the turn does not undercut the incline's floor
    foot = plan.add_node(plan.pos[turn] - s * heading, "entrance")
    ids["portal"] = plan.add_node(plan.pos[foot] - ENTRANCE_RUN_M * heading + [0.0, 0.0, rise],
                                  "entrance")
    plan.join(ids["portal"], foot, s, s, "ramp", "entrance", "tunnel")
    plan.join(foot, turn, s, s, "tunnel", "entrance", "tunnel")
    plan.join(turn, ids["west"], s, s, "tunnel", "entrance", "tunnel")
    return ids


class TunnelSection:
    """The drifts of the Tunnel section: stations on two or three parallel drifts, the
    breach from the hall's east node, crosscuts; :meth:`fill` adds the side cuts.
    ``lo``/``hi`` bound it in x and y (m)."""

    def __init__(self, plan: CoursePlan, rng: np.random.Generator, east: int, budget_m: float,
                 v: float):
        self.plan, self.rng = plan, rng
        self.n_drifts = 3 if budget_m >= THREE_DRIFTS_FROM_M else 2
        ys = [DRIFT_SPACING_M, 0.0, -DRIFT_SPACING_M][3 - self.n_drifts:]
        gaps = self.n_drifts - 1
        per_station = (self.n_drifts * DRIFT_STATION_M + gaps * DRIFT_SPACING_M / CROSSCUT_EVERY
                       + gaps * (1 - 1 / CROSSCUT_EVERY) * 0.5 * sum(SIDE_CUT_M))
        fixed = TUNNEL_BREACH_M + 2 * DRIFT_SPACING_M          # breach and crossover drifts
        self.m = max(int(round((budget_m - fixed) / per_station)) + 1, 2)
        x0 = plan.pos[east][0] + TUNNEL_BREACH_M
        self.stations: list[list[int]] = []
        for y in ys:
            row, z = [], 0.0
            for i in range(self.m):
                dy = float(rng.uniform(-DRIFT_JITTER_M, DRIFT_JITTER_M)) if i else 0.0
                z = 0.0 if i == 0 else snap_height(float(np.clip(z + rng.normal(0.0, DRIFT_GRADE_STEP_M),
                                                                 -DRIFT_GRADE_M, DRIFT_GRADE_M)), v)
                row.append(plan.add_node([x0 + i * DRIFT_STATION_M, y + dy, z], "tunnel"))
            for a, b in zip(row, row[1:]):
                self.join(a, b)
            self.stations.append(row)
        self.middle = self.stations[1 if self.n_drifts == 3 else 0]
        self.join(east, self.middle[0])
        self.crosscuts = []
        for g in range(gaps):
            off = int(rng.integers(CROSSCUT_EVERY))
            at = [i for i in range(self.m) if (i + off) % CROSSCUT_EVERY == 0] or [self.m // 2]
            for i in at:
                self.join(self.stations[g][i], self.stations[g + 1][i])
            self.crosscuts.append(set(at))
        reach = DRIFT_JITTER_M + CHAMBER_RADIUS_FACTOR * DRIFT_WIDTH_M[1]
        self.lo = np.array([plan.pos[east][0], ys[-1] - reach])
        self.hi = np.array([x0 + (self.m - 1) * DRIFT_STATION_M + reach, ys[0] + reach])

    def join(self, a: int, b: int) -> None:
        """A drift of random size between two nodes."""
        self.plan.join(a, b, float(self.rng.uniform(*DRIFT_WIDTH_M)),
                       float(self.rng.uniform(*DRIFT_HEIGHT_M)), "tunnel", "tunnel", "tunnel")

    def station_near(self, drift: int, x: float) -> int:
        """The station of a drift (0 = northernmost, -1 = southernmost) nearest to x."""
        row = self.stations[drift]
        return min(row, key=lambda n: abs(self.plan.pos[n][0] - x))

    def fill(self, budget_m: float) -> None:
        """Side cuts between the drifts (then a dead-end drift east off the middle one)
        until the section is ``budget_m`` long; ValueError when it already is longer."""
        plan, rng = self.plan, self.rng
        left = budget_m - plan.section_length("tunnel")
        if left < -SECTION_TOLERANCE * budget_m:
            raise ValueError(f"tunnel_length_m (x scale) = {budget_m:.0f} m is too short for the "
                             f"tunnel section's drifts and crossovers: raise tunnel_length_m or scale")
        slots = [(g, i) for g in range(self.n_drifts - 1) for i in range(self.m)
                 if i not in self.crosscuts[g]]
        for k in rng.permutation(len(slots)):
            if left < SIDE_CUT_M[0]:
                break
            g, i = slots[int(k)]
            down = i % 2 == 0                 # from the northern drift of the gap, south
            base = self.stations[g][i] if down else self.stations[g + 1][i]
            length = min(float(rng.uniform(*SIDE_CUT_M)), left)
            if left - length < SIDE_CUT_M[0]:
                length = min(left, SIDE_CUT_M[1])
            ang = math.radians(-90.0 if down else 90.0) + math.radians(
                float(rng.uniform(-SIDE_CUT_SKEW_DEG, SIDE_CUT_SKEW_DEG)))
            end = plan.pos[base] + [length * math.cos(ang), length * math.sin(ang), 0.0]
            self.join(base, plan.add_node(end, "tunnel"))
            left -= length
        if left > 0.5:
            tip = plan.pos[self.middle[-1]]
            self.join(self.middle[-1], plan.add_node(tip + [left, 0.0, 0.0], "tunnel"))
            self.hi[0] += left


def check_slope(name: str, value: float) -> float:
    """A slope in degrees that a legged robot walks: (0, MAX_WALKABLE_SLOPE_DEG]."""
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(value) and 0.0 < value <= MAX_WALKABLE_SLOPE_DEG):
        raise ValueError(f"{name} must lie in (0, {MAX_WALKABLE_SLOPE_DEG:g}] degrees (a slope a "
                         f"legged robot walks), got {value:g}")
    return value


def build_course(seed: int, lengths: dict[str, float], entrance_slope_deg: float,
                 stair_slope_deg: float, cavern_width_m: float, cavern_height_m: float,
                 v: float, name: str) -> World:
    """Plan and carve the course; ``lengths`` are the tunnel, urban and cave sections'
    centreline lengths (m). Parameters are checked by worldgen.subt_final."""
    rng = np.random.default_rng(seed)
    plan = CoursePlan()
    ids = plan_entrance_and_hall(plan, entrance_slope_deg, v)
    tunnel = TunnelSection(plan, rng, ids["east"], lengths["tunnel"], v)
    hall_top = plan.pos[ids["north"]][1]
    y0 = max(tunnel.hi[1], hall_top + TUNNEL_BREACH_M) + CLEARANCE_M + 0.5 * CORRIDOR_M + 1.0
    urban = plan_urban(plan, rng, ids["north"], y0, lengths["urban"], stair_slope_deg)

    foot = plan.pos[urban.crossover_foot]       # straight south to the tunnel's edge, then
    edge = plan.add_node([foot[0], tunnel.hi[1], foot[2]], "tunnel")   # to the nearest station
    tunnel.join(urban.crossover_foot, edge)
    tunnel.join(edge, tunnel.station_near(0, foot[0]))
    south = tunnel.stations[-1][int(round(CAVE_CROSSOVER_AT * (tunnel.m - 1)))]
    s = plan.pos[south]
    target = plan.add_node([s[0], tunnel.lo[1] - CAVE_CROSSOVER_OUT_M, s[2]], "cave")
    tunnel.join(south, target)
    tunnel.fill(lengths["tunnel"])

    hall_lo = -0.5 * np.array(HALL_SIZE_M[:2])
    cavern_len = float(np.clip(CAVERN_LENGTH_SHARE * lengths["cave"], 0.75 * cavern_width_m,
                               2.0 * cavern_width_m))
    area = CAVE_AREA_PER_M * lengths["cave"] + (cavern_width_m + 2 * CLEARANCE_M) * (
        cavern_len + cavern_width_m)
    west, east = hall_lo[0] - CAVE_WEST_M, tunnel.hi[0] + CLEARANCE_M
    top = hall_lo[1] - 1.0
    depth = (max(CAVE_MIN_DEPTH_M, area / (east - west)) + (top - tunnel.lo[1])
             + cavern_width_m + 2 * CLEARANCE_M)      # room for the cavern beside the trunk
    plan_cave(plan, rng, ids["south"], target, (np.array([west, top - depth]), np.array([east, top])),
              [(hall_lo, -hall_lo), (tunnel.lo, tunnel.hi)], lengths["cave"], CAVE_WIDTH_M,
              CAVE_HEIGHT_M, cavern_width_m, cavern_height_m, cavern_len)

    for section in ("tunnel", "urban", "cave"):
        got, want = plan.section_length(section), lengths[section]
        if abs(got - want) > SECTION_TOLERANCE * want:
            raise ValueError(f"{section}_length_m: cannot lay out a {want:.0f} m {section} "
                             f"section (got {got:.0f} m): change {section}_length_m or scale")
    lo, hi = plan.bounds()
    extent = hi - lo + 2 * GRID_MARGIN_M
    check_voxels(voxel_count(extent, v), v, f"the course's box of {extent[0]:.0f} x {extent[1]:.0f} "
                 f"x {extent[2]:.0f} m", "scale", voxel_count(extent, DEFAULT_VOXEL_SIZE_M))
    return plan.build(name, v, ids["portal"])
