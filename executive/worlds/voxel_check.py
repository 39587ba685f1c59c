"""A voxel world looked at before a run: where each robot starts, the world's
figures, and what looks wrong, with the scenario's file and line (``delve world``,
and the first lines of ``delve run``)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...sim.platforms import PLATFORMS, Platform
from ...sim.start_landing import Landing, hover_clear, land
from ...sim.world import World
from ...sim.world_survey import Survey, survey, world_warnings
from ...skills.base import short_repr
from ..errors import DelveError
from .base import WorldDescription

if TYPE_CHECKING:
    from ..scenario import Scenario

#: Where robots without a ``start`` stand, around the world's start (m), in order.
START_OFFSETS_M = [(0, 0), (1.2, 0), (-1.2, 0), (0, 1.2), (0, -1.2), (2.4, 0), (-2.4, 0), (2.4, 1.2),
                   (-2.4, 1.2), (2.4, -1.2), (-2.4, -1.2), (3.6, 0), (-3.6, 0),
                   # then rows along a narrow passage (a portal in y, or in x)
                   (1.2, 1.2), (-1.2, 1.2), (1.2, -1.2), (-1.2, -1.2), (0, 2.4), (0, -2.4), (1.2, 2.4),
                   (-1.2, 2.4), (1.2, -2.4), (-1.2, -2.4), (0, 3.6), (0, -3.6)]
#: A default start needs free space this far above it.
DEFAULT_START_CLEAR_M = 0.3
#: A default start closer than this (horizontally) to a given one is not used.
GIVEN_START_SPACING_M = 1.0


@dataclass
class StartPlacement:
    """Where one robot starts: its ``landing`` (see :mod:`delve.sim.start_landing`),
    whether the scenario gave the start (``given``), and the error it is, if any."""

    name: str
    platform: str
    given: bool
    landing: Landing
    line: int | None
    error: DelveError | None = None


def place_starts(scenario: "Scenario", world: World) -> list[StartPlacement]:
    """Each robot's start: a given one placed on the floor (legged) or checked for
    clearance (aerial); a default one near the world's start, a little apart for each
    robot. Problems are the placements' ``error``s, not raised."""
    defaults = [np.asarray(world.start, float) + np.array([dx, dy, 0.0]) for dx, dy in START_OFFSETS_M]
    lift = np.array([0.0, 0.0, DEFAULT_START_CLEAR_M])
    defaults = [p for p in defaults if world.is_free((p + lift)[None])[0]]
    given = [np.asarray(s.start, float) for s in scenario.robots if s.start is not None]
    used = {j for j, p in enumerate(defaults)
            if any(np.hypot(*(p - g)[:2]) < GIVEN_START_SPACING_M for g in given)}
    out = []
    for i, spec in enumerate(scenario.robots):
        platform = PLATFORMS[spec.platform]
        j = _default_start(world, defaults, i, used, platform) if spec.start is None else None
        if spec.start is None and j is None:
            landing = Landing(given=np.asarray(world.start, float), problem="no free start pose")
            out.append(StartPlacement(spec.name, spec.platform, False, landing, spec.line, DelveError(
                f"no free start pose near the world's start for robot #{i + 1}", scenario.path, spec.line)))
            continue
        point = np.asarray(spec.start, float) if spec.start is not None else defaults[j]
        landing = land(world, point, aerial=platform.aerial, body_height_m=platform.body_height_m,
                       radius_m=platform.radius_m)
        line = spec.start_line if spec.start is not None else spec.line
        error = None
        if landing.problem:
            shown = spec.start if spec.start is not None else _xyz(point)      # as check_starts shows it
            error = DelveError(f"robot {short_repr(spec.name)}: start pose {shown} is {landing.problem}",
                               scenario.path, line)
        out.append(StartPlacement(spec.name, spec.platform, spec.start is not None, landing, line, error))
    return out


def _default_start(world: World, defaults: list[np.ndarray], i: int, used: set[int],
                   platform: Platform) -> int | None:
    """The default start of robot #``i`` (an index into ``defaults``, marked ``used``):
    the first from the ``i``-th on that no robot before took and, for an aerial robot,
    where it hovers clear of rock (:func:`~delve.sim.start_landing.hover_clear`; else
    the first not taken, with a warning); None when none is left."""
    left = [j for j in range(i, len(defaults)) if j not in used]
    body = np.array([0.0, 0.0, platform.body_height_m])
    r = platform.radius_m
    j = next((j for j in left if not platform.aerial or hover_clear(world, defaults[j] + body, r)),
             left[0] if left else None)
    if j is not None:
        used.add(j)
    return j


def describe_voxel_world(scenario: "Scenario", world: World) -> WorldDescription:
    """The world's figures, each start, and the warnings (see :mod:`delve.sim.world_survey`)."""
    figures = survey(world)
    where = scenario.doc["world"]
    out = WorldDescription(lines=[_headline(scenario, world)] + _figure_lines(figures))
    for w in world_warnings(world, figures):
        line = where.key_line(w.key) if w.key and w.key in where else where.line
        out.warnings.append(str(DelveError(w.message, scenario.path, line)))
    for i, p in enumerate(place_starts(scenario, world)):
        label = "start" if i == 0 else ""
        out.lines.append(f"  {label:<9} {p.name} ({p.platform}): {_landing_text(p)}")
        if p.error is not None:
            out.errors.append(p.error)
        else:
            out.starts[p.name] = [round(float(c), 3) for c in p.landing.start]
        for w in p.landing.warnings:
            out.warnings.append(str(DelveError(f"robot {short_repr(p.name)} {w}", scenario.path, p.line)))
    if scenario.base_position is not None:
        problem = world.start_problem(scenario.base_position)
        out.lines.append(f"  {'':<9} base station: {_xyz(scenario.base_position)}"
                         + (f", {problem}" if problem else ""))
        if problem:
            out.errors.append(DelveError(f"base station position is {problem}", scenario.path,
                                         scenario.doc["base_station"].key_line("position")))
    return out


def _xyz(p) -> str:
    return "[" + ", ".join(f"{float(c):.2f}".rstrip("0").rstrip(".") for c in np.asarray(p, float)) + "]"


def _landing_text(p: StartPlacement) -> str:
    ld = p.landing
    if ld.problem:
        return f"{_xyz(ld.given)} is {ld.problem}"
    if ld.moved_m > 0:
        text = f"on the floor at {_xyz(ld.start)}, moved {ld.moved_m:.2f} m down from {_xyz(ld.given)}"
    elif p.given:
        text = f"at {_xyz(ld.start)}, " + ("hovering above it" if p.platform == "aerial" else "on the floor")
    else:
        text = f"at {_xyz(ld.start)}, near the world's start"
    return text + f" (in a free region of {ld.region_m3:.0f} m³)"


def _headline(scenario: "Scenario", world: World) -> str:
    src, spec = world.source, scenario.world
    if src is None:
        params = ", ".join(f"{k} {v}" for k, v in {"seed": scenario.seed, **spec}.items() if k != "generator")
        return f"world {scenario.name}: generator {spec.get('generator')} ({params})"
    by = "ceiling_m" if src.ceiling_from == "scenario" else "the model top"
    ceiling = "" if src.ceiling_z is None else f"a ceiling at z = {src.ceiling_z:.1f} m ({by})"
    if src.free_space == "closed":
        how = "a closed inner surface: free space is its inside (exact)"
    elif src.free_space == "surface":
        kind = "an open mesh" if src.closure == "open" else "a mesh of closed solids"
        how = f"{kind}: rock where its surface passes, {ceiling}, free space the floored regions below"
    elif src.free_space == "points":
        how = (f"a point cloud: rock within {src.inflation_m:g} m of a point, {ceiling}, free space the "
               f"floored regions below")
    else:
        how = f"a point cloud: free space what {src.scan_origins} scan origin(s) saw, rock within " \
              f"{src.inflation_m:g} m of a point"
    said = {"scenario": "from the scenario", "file": "from the file's header", "default": "by default"}
    axis, scale = said[src.up_axis_from], said[src.scale_from].replace("header", "unit")
    return (f"world {scenario.name}: {src.file} ({src.format}), up axis {src.up_axis} {axis}, "
            f"scale {src.scale:g} {scale}\n  {'built':<9} {how}")


def _figure_lines(f: Survey) -> list[str]:
    lo, hi, ext = f.bounds_min, f.bounds_max, f.extent_m
    share = f.free_volume_m3 / f.box_volume_m3 if f.box_volume_m3 > 0 else 0.0
    regions = f.significant_regions
    n_small = len(f.regions_m3) - len(regions)
    small = f" and {n_small} speck(s) under 1% of it" if n_small else ""
    return [f"  {'extent':<9} x {lo[0]:.1f} … {hi[0]:.1f}, y {lo[1]:.1f} … {hi[1]:.1f}, "
            f"z {lo[2]:.1f} … {hi[2]:.1f} m ({ext[0]:.1f} × {ext[1]:.1f} × {ext[2]:.1f} m)",
            f"  {'voxels':<9} {f.shape[0]} × {f.shape[1]} × {f.shape[2]} of {f.voxel_size_m:g} m = "
            f"{int(np.prod(f.shape)):,}; {f.free_voxels:,} free",
            f"  {'free':<9} {f.free_volume_m3:.0f} m³, {share:.1%} of the bounding box; "
            f"{len(regions)} region(s){small}, the largest {f.largest_share:.0%} of the free volume"]
