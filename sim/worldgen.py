"""Seeded procedural worlds: mine tunnel networks and natural caves, plus meshes.

Every generator draws all its randomness from ``numpy.random.default_rng(seed)``:
the same seed and parameters give the same :class:`~delve.sim.world.World`
(byte-identical ``free`` grid). Each first plans a centreline graph (with
clearance checks so that passages only meet where the plan says they do),
then carves free space segment by segment into a boolean grid, and finally
wraps the rock surface in a marching-cubes mesh
(:func:`~delve.sim.worldgen_geometry.free_space_mesh`).

``total_length_m`` counts every walkable centreline edge (tunnels, caves and
ramps, on every level) and not the vertical shafts.
"""

from __future__ import annotations

import math
from importlib.resources import files
from pathlib import Path

import numpy as np

from .limits import DEFAULT_VOXEL_SIZE_M, MAX_TOTAL_LENGTH_M, check_total_length, check_voxels
from .meshio import from_mesh, write_scan_mesh
from .world import World
from .worldgen_cave import (CAVE_FLOOR_BAND_M, CavePlan, add_cave_branches, add_cave_upper,
                            build_cave)
from .worldgen_geometry import CLEARANCE_M, cave_section_top, snap_height
from .worldgen_subt import (CAVE_WIDTH_M, CAVE_HEIGHT_M, build_course, check_slope)
from .worldgen_subt_urban import WALL_M
from .worldgen_mine import (LATTICE_DIRECTIONS, LEVEL_RISE_M, MinePlan, add_gallery,
                            add_upper_level, build_mine, mine_regions)

__all__ = ["tunnel_network", "cave", "subt_final", "from_mesh", "scanned_mine", "write_scanned_mine",
           "SCANNED_MINE_PATH"]

#: The "scanned mine" test asset: a small mine mesh with scan noise, Y-up, in centimetres.
SCANNED_MINE_PATH = Path(str(files("delve.scenarios"))) / "worlds" / "scanned_mine.ply"
#: How scanned_mine.ply is made (see write_scanned_mine) and must be loaded.
SCANNED_MINE_SEED = 2024
SCANNED_MINE_SCALE = 0.01
SCANNED_MINE_UP_AXIS = "y"
#: Allowed relative error of the total centreline length.
LENGTH_TOLERANCE = 0.10
#: Mine floors wander within +-(this x spacing x tan(max slope)) of the portal ...
MINE_FLOOR_BAND = 0.55
#: ... but within +-this on the lower level of a two-level mine (rock under level 1).
TWO_LEVEL_FLOOR_BAND_M = 1.5
#: Share of total_length_m given to the upper level (ramp included) of a two-level mine.
UPPER_LEVEL_SHARE = 0.3
#: Cave passages wander within about this radius (m) of the entrance, plus a share
#: of total_length_m ...
CAVE_RADIUS_M = 10.0
CAVE_RADIUS_PER_LENGTH = 0.12
#: ... and the passage above a cave shaft takes this share of it (8-40 m).
CAVE_UPPER_SHARE = 0.12
#: Widest and highest cavern of a SubT Final course (m).
CAVERN_MAX_M = 40.0


# ============================================================== validation
def _check_positive(name: str, value: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {value}")
    return value


def _check_range(name: str, rng_: tuple, voxel_size_m: float) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in rng_)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a (min, max) pair of numbers, got {rng_!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo <= 0 or lo > hi:
        raise ValueError(f"{name} must satisfy 0 < min <= max, got {rng_!r}")
    if lo < 2 * voxel_size_m:
        raise ValueError(f"{name} minimum {lo:g} m is under two voxels "
                         f"({2 * voxel_size_m:g} m): use a smaller voxel_size_m")
    return lo, hi


def _check_size(total: float, width: tuple[float, float], height: tuple[float, float], v: float,
                what: str) -> None:
    """ValueError before planning when the world would be too long, or when its
    passages alone (each at least the smallest width and height) would hold more
    voxels than a world may (sim/limits.py); the box is checked again when built."""
    check_total_length(total)
    volume = total * width[0] * height[0]
    check_voxels(volume / v ** 3, v, f"a {total:g} m {what} of passages at least {width[0]:g} x {height[0]:g} m",
                 "total_length_m", volume / DEFAULT_VOXEL_SIZE_M ** 3)


def region_sites(region_m: tuple, spacing_m: float) -> list:
    """Lattice index ranges [(i0, i1), (j0, j1)] of the sites within an area of
    ``region_m`` (x, y) metres: from the portal along +x, centred on it in y."""
    if not isinstance(region_m, (list, tuple)) or len(region_m) != 2:
        raise ValueError(f"region_m must be an (x, y) pair of metres, got {region_m!r}")
    x, y = (_check_positive("region_m", r) for r in region_m)
    ni, nj = int(x // spacing_m) + 1, int(y // spacing_m) + 1
    return [(0, ni), (-(nj // 2), nj - nj // 2)]


# ========================================================== generators
def tunnel_network(seed: int, *, total_length_m: float = 400.0, spacing_m: float = 20.0,
                   levels: int = 1, shaft: bool = False, ramp: bool = True, loops: int = 2,
                   max_slope_deg: float = 30.0, width_m: tuple = (3.0, 5.0),
                   height_m: tuple = (2.5, 3.5), voxel_size_m: float = 0.2,
                   region_m: tuple | None = None, name: str = "tunnel_network") -> World:
    """A seeded mine: a jittered-lattice network of flat-floored, arch-roofed tunnels.

    A random spanning tree grows on a lattice of ``spacing_m`` from the start
    node (the portal, at x = 0) until the centreline is ``total_length_m``
    long (within 10 %), leaving branches and dead ends; ``loops`` extra
    lattice edges then close loops. Floor heights follow a random walk
    (every edge's slope <= ``max_slope_deg``; with ``ramp`` some edges climb
    at 75-100 % of it and are marked kind "ramp"). A climbing tunnel is level
    for ``landing_m`` (0.7 x the widest tunnel, an edge attribute) at each end
    and climbs at its slope in between, and no two passages leave a junction
    less than 45 degrees apart, so a legged robot walks every passage.
    Junctions get round chambers. ``levels=2`` adds a second level 12-15 m above part of the
    first, joined by a long ramp (``ramp=True``) and/or a vertical shaft
    (``shaft=True``); ``levels=1, shaft=True`` adds a shaft up to a small
    dead-end gallery that only a flying robot can reach. Nodes carry ``level``
    0 or 1. ``region_m`` (x, y) is the area the lattice grows in, from the portal
    along +x and centred on it in y (default: a square roomy enough for
    ``total_length_m``); a network too long for it widens it. Raises ValueError
    for impossible parameters.
    """
    total = _check_positive("total_length_m", total_length_m)
    spacing = _check_positive("spacing_m", spacing_m)
    v = _check_positive("voxel_size_m", voxel_size_m)
    if levels not in (1, 2) or isinstance(levels, bool):
        raise ValueError(f"levels must be 1 or 2, got {levels!r}")
    if not isinstance(loops, (int, np.integer)) or isinstance(loops, bool) or loops < 0:
        raise ValueError(f"loops must be a non-negative integer, got {loops!r}")
    slope_deg = float(max_slope_deg)
    if not (math.isfinite(slope_deg) and 0.0 < slope_deg <= 60.0):
        raise ValueError(f"max_slope_deg must lie in (0, 60], got {max_slope_deg}")
    width = _check_range("width_m", width_m, v)
    height = _check_range("height_m", height_m, v)
    _check_size(total, width, height, v, "network")
    if spacing < 2 * width[1] + CLEARANCE_M:
        raise ValueError(f"spacing_m={spacing} is too small for tunnels up to {width[1]} m wide: "
                         f"use at least {2 * width[1] + CLEARANCE_M} m")
    if levels == 2 and not (ramp or shaft):
        raise ValueError("levels=2 needs ramp=True and/or shaft=True to join the two levels")
    sites = None if region_m is None else region_sites(region_m, spacing)

    rng = np.random.default_rng(seed)
    plan = MinePlan(rng, spacing, v, math.radians(slope_deg), width, height)
    tmax = math.tan(plan.max_slope)
    rise_up = snap_height(float(rng.uniform(*LEVEL_RISE_M)), v)
    half_band = (TWO_LEVEL_FLOOR_BAND_M if levels == 2
                 else max(2.0, MINE_FLOOR_BAND * spacing * tmax))
    band0 = (-half_band, half_band)
    ramp_run = rise_up / math.tan(0.95 * plan.max_slope) + 2.0 * plan.landing  # the steepest ramp

    extras = loops * 1.05 * spacing
    if levels == 2:
        upper_share = max(UPPER_LEVEL_SHARE * total, (ramp_run if ramp else 0.0) + spacing)
        extras += upper_share
    elif shaft:
        extras += 1.2 * spacing
    phase1 = max(total - extras - levels * spacing, min(total, 2.0 * spacing))

    plan.add_node([0.0, 0.0, 0.0], 0, (0, 0))
    region = mine_regions(int(math.ceil(total / spacing))) if sites is None else sites

    def compact(site):      # favour filling in, so lattice neighbours for loops exist
        near = sum(plan.sites[0].get((site[0] + d[0], site[1] + d[1]), -1) >= 0
                   for d in LATTICE_DIRECTIONS)
        return 1.0 + (4.0 * (near - 1) if loops else 0.0)

    steep = ramp and levels == 1
    plan.grow(0, region, phase1, band0, steep=steep, trim=False, site_weight=compact)
    if steep:
        plan.ensure_steep_edge()
    closed = plan.close_loops(loops)
    for _ in range(4 * loops):
        if closed >= loops:
            break
        plan.grow(0, region, math.inf, band0, steep=steep, trim=False, site_weight=compact,
                  max_edges=1)
        closed += plan.close_loops(loops - closed)
    if closed < loops:
        raise ValueError(f"cannot close {loops} loop(s) in a {total:g} m network with "
                         f"spacing_m={spacing:g}: raise total_length_m or lower loops")

    if levels == 2:
        add_upper_level(plan, rise_up, ramp, shaft, upper_share, region)
    elif shaft:
        add_gallery(plan, rise_up)

    plan.grow(0, region, total, band0, steep=steep, trim=True)
    plan.shrink_leaves(plan.walk_length() - total)
    got = plan.walk_length()
    if abs(got - total) > LENGTH_TOLERANCE * total:
        raise ValueError(f"cannot lay out a {total:g} m network with these features "
                         f"({loops} loop(s), levels={levels}, ramp={ramp}, shaft={shaft}): "
                         f"they took {got:.0f} m; raise total_length_m or lower spacing_m "
                         f"or loops")
    return build_mine(plan, name)


def cave(seed: int, *, total_length_m: float = 250.0, width_m: tuple = (1.0, 15.0),
         height_m: tuple = (2.0, 8.0), shaft: bool = True, shaft_height_m: float = 15.0,
         voxel_size_m: float = 0.2, name: str = "cave") -> World:
    """A seeded natural cave: a random tree of meandering passages of irregular section.

    Passages wander (curved polylines sampled every 2.5 m) and branch; their
    width varies along them across ``width_m`` (squeezes near the minimum,
    chambers near the maximum), the height with the width across
    ``height_m``; the cross-section is an ellipse distorted by a few random
    harmonics, with a flat floor a legged robot can walk. With ``shaft`` a
    vertical shaft rises ``shaft_height_m`` (floor to floor) from one passage
    to an upper passage that nothing else reaches. Centreline nodes are the
    samples (``level`` 0 below, 1 above the shaft); edges have kind "cave"
    or "shaft". Raises ValueError for impossible parameters.
    """
    total = _check_positive("total_length_m", total_length_m)
    v = _check_positive("voxel_size_m", voxel_size_m)
    width = _check_range("width_m", width_m, v)
    height = _check_range("height_m", height_m, v)
    _check_size(total, width, height, v, "cave")
    rng = np.random.default_rng(seed)
    plan = CavePlan(rng, width, height, radius=CAVE_RADIUS_M + CAVE_RADIUS_PER_LENGTH * total)
    band = (-CAVE_FLOOR_BAND_M, CAVE_FLOOR_BAND_M)
    upper_len = 0.0
    if shaft:
        shaft_h = _check_positive("shaft_height_m", shaft_height_m)
        need = cave_section_top(height[0]) + CLEARANCE_M + 1.0
        if shaft_h < need:
            raise ValueError(f"shaft_height_m={shaft_h:g} leaves no rock between the passages: "
                             f"use at least {need:.1f} m")
        upper_len = min(max(CAVE_UPPER_SHARE * total, 8.0), 40.0, 0.5 * total)
    lower_len = total - upper_len

    start_w = float(np.clip(rng.uniform(3.0, 6.0), *width))
    plan.grow(None, [0.0, 0.0, 0.0], float(rng.uniform(-math.pi, math.pi)),
              0.4 * lower_len, 0, width, height[1], band, first_w=start_w,
              force=("chamber",))
    add_cave_branches(plan, lower_len, band)
    if shaft:
        upper_len = add_cave_upper(plan, shaft_h, upper_len)
    add_cave_branches(plan, total, band)

    got = plan.walk_length()
    if abs(got - total) > LENGTH_TOLERANCE * total:
        raise ValueError(f"cannot fit a {total:g} m cave (only {got:.0f} m fitted): "
                         f"lower total_length_m or the widths")
    return build_cave(plan, name, v)


def subt_final(seed: int, *, scale: float = 1.0, tunnel_length_m: float = 700.0,
               urban_length_m: float = 450.0, cave_length_m: float = 550.0,
               entrance_slope_deg: float = 15.0, stair_slope_deg: float = 25.0,
               cavern_width_m: float = 20.0, cavern_height_m: float = 10.0,
               voxel_size_m: float = 0.2, name: str = "subt_final") -> World:
    """A seeded course like the DARPA SubT Final's (sim/worldgen_subt.py, docs/worlds.md).

    From the portal (the start) an inclined drift (``entrance_slope_deg``) with a
    sharp turn leads into a high hall with three breaches: east into a Tunnel
    section (parallel drifts, crosscuts, side cuts), north into an Urban section
    (two levels of square corridors and rooms with doors, a staircase at
    ``stair_slope_deg``), south into a Cave section (narrow meandering passages
    and a cavern ``cavern_width_m`` wide and up to ``cavern_height_m`` high). A
    descending staircase and a drift cross over from the upper urban level to the
    tunnel drifts, and a drift from the tunnel meets the cave. Each section's
    centreline is ``scale`` times its ``*_length_m`` (within 10 %); the entrance
    (about 43 m), the hall (40 m) and the crossovers come on top: about 1.8 km in
    all at the defaults. Nodes carry ``pos``, ``level`` (1 on the upper urban
    level) and ``section`` (entrance, hall, tunnel, urban, cave); edges
    ``width_m``, ``height_m``, ``kind`` (ramp, tunnel, hall, corridor, stairs,
    room, cave), ``length_m`` and ``section``. Raises ValueError for impossible
    parameters.
    """
    k = _check_positive("scale", scale)
    lengths = {s: k * _check_positive(f"{s}_length_m", value) for s, value in
               (("tunnel", tunnel_length_m), ("urban", urban_length_m), ("cave", cave_length_m))}
    v = _check_positive("voxel_size_m", voxel_size_m)
    if v > 0.5 * WALL_M:
        raise ValueError(f"voxel_size_m must be at most {0.5 * WALL_M:g} m (half the urban "
                         f"rooms' walls), got {v:g}")
    entrance = check_slope("entrance_slope_deg", entrance_slope_deg)
    stairs = check_slope("stair_slope_deg", stair_slope_deg)
    cw = _check_positive("cavern_width_m", cavern_width_m)
    ch = _check_positive("cavern_height_m", cavern_height_m)
    if not 2 * CAVE_WIDTH_M[1] <= cw <= CAVERN_MAX_M:
        raise ValueError(f"cavern_width_m must lie in [{2 * CAVE_WIDTH_M[1]:g}, {CAVERN_MAX_M:g}] "
                         f"(at least twice the widest passage), got {cw:g}")
    if not CAVE_HEIGHT_M[1] <= ch <= CAVERN_MAX_M:
        raise ValueError(f"cavern_height_m must lie in [{CAVE_HEIGHT_M[1]:g}, {CAVERN_MAX_M:g}], "
                         f"got {ch:g}")
    if sum(lengths.values()) > MAX_TOTAL_LENGTH_M:
        raise ValueError(f"scale: the sections add up to {sum(lengths.values()):g} m, more than "
                         f"{MAX_TOTAL_LENGTH_M:g} m, the longest world delve generates")
    return build_course(seed, lengths, entrance, stairs, cw, ch, v, name)


# ============================================================ test assets
def write_scanned_mine(path: str | Path = SCANNED_MINE_PATH, *, seed: int = SCANNED_MINE_SEED,
                       target_triangles: int = 80_000) -> Path:
    """(Re)write the "scanned mine" asset: a ~150 m mine mesh as a scanner would deliver it.

    A one-loop tunnel_network (with a steep ramp) is meshed, decimated to
    ``target_triangles``, given 2 cm of per-vertex noise and written as a
    binary PLY, Y-up and in centimetres: load it with
    ``from_mesh(path, scale=0.01, up_axis="y")`` (see :func:`scanned_mine`).
    """
    world = tunnel_network(seed, total_length_m=150.0, spacing_m=15.0, loops=1,
                           voxel_size_m=0.2, name="scanned_mine")
    return write_scan_mesh(world.mesh, path, noise_m=0.02, seed=seed,
                           target_triangles=target_triangles,
                           scale=SCANNED_MINE_SCALE, up_axis=SCANNED_MINE_UP_AXIS)


def scanned_mine(*, voxel_size_m: float = 0.2, path: str | Path = SCANNED_MINE_PATH) -> World:
    """Load the "scanned mine" asset (scenarios/worlds/scanned_mine.ply) as a World."""
    return from_mesh(path, scale=SCANNED_MINE_SCALE, up_axis=SCANNED_MINE_UP_AXIS,
                     voxel_size_m=voxel_size_m, name="scanned_mine")
