"""Where a robot's start lands in a voxel world.

A start names the ground point under the robot (the robot stands, or hovers, its
platform's body height above it). A **legged** robot's start is placed on the floor
below the given point: the rock surface straight down, within ``SNAP_DOWN_M``. A
start within one voxel of that floor (above it, or in the voxel the floor passes
through) stands as given; higher, it is moved down onto the floor. An **aerial**
robot's start stays where it is given; its body must be in free space, with its
radius clear of rock.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .world import World

#: How far below a legged robot's given start its floor is looked for.
SNAP_DOWN_M = 2.0
#: Half the height of the box a hovering robot's planner keeps free of rock (GBPlanner2's
#: aerial robot boxes are 0.2-0.4 m high).
HOVER_BOX_HALF_HEIGHT_M = 0.2
#: A start in a free region of less than this share of the largest region's volume gets a warning.
SMALL_REGION_SHARE = 0.1


@dataclass
class Landing:
    """Where a start landed.

    Fields:
        given: the point asked for.
        start: the ground point used (None when ``problem``).
        moved_m: how far the start was moved down onto the floor (0 when it stands as given).
        problem: why the robot cannot start there (the start is an error), else None.
        warnings: what is doubtful about it (one line each).
        region_m3: the free volume of the region the robot starts in.
    """

    given: np.ndarray
    start: np.ndarray | None = None
    moved_m: float = 0.0
    problem: str | None = None
    warnings: list[str] = field(default_factory=list)
    region_m3: float = 0.0


def land(world: "World", point: np.ndarray, *, aerial: bool, body_height_m: float, radius_m: float,
         max_drop_m: float = SNAP_DOWN_M) -> Landing:
    """Where a start given as ``point`` lands (see the module notes)."""
    p = np.asarray(point, dtype=float).reshape(3)
    out = Landing(given=p)
    problem = world.start_problem(p)
    if problem:
        out.problem = problem
        return out
    if aerial:
        body = p + np.array([0.0, 0.0, body_height_m])
        if not world.is_free(body[None])[0]:
            out.problem = (f"under rock: an aerial robot hovers {body_height_m:g} m above its start, and "
                           f"{np.round(body, 2).tolist()} is rock{world.nearest_floor_hint(p)}")
            return out
        if not hover_clear(world, body, radius_m):
            clear = clearance_m(world, body, radius_m + world.voxel_size_m)
            out.warnings.append(f"hovers {clear:.2f} m from rock at its start, within its radius and a voxel "
                                f"({radius_m + world.voxel_size_m:g} m) in some direction: its planner may find "
                                "rock inside the robot's box there")
        out.start = p
    else:
        out.start = _on_floor(world, p, max_drop_m)
        if out.start is None:
            out.problem = (f"{max_drop_m:g} m or more above the floor (a legged robot's start is placed on "
                           f"the floor below it, at most {max_drop_m:g} m down){world.nearest_floor_hint(p)}")
            return out
        out.moved_m = float(p[2] - out.start[2])
    _check_region(world, out)
    return out


def _on_floor(world: "World", p: np.ndarray, max_drop_m: float) -> np.ndarray | None:
    """The start on the floor below ``p``: ``p`` itself when within a voxel of the
    floor, else the floor point straight below; None when no floor is near enough."""
    v = world.voxel_size_m
    for lift in (v, 0.0):                     # look down from just above, unless that is rock
        probe = p + np.array([0.0, 0.0, lift])
        if world.is_free(probe[None])[0]:
            break
    else:
        probe = p
    d = float(world.cast_rays(probe[None], np.array([[0.0, 0.0, -1.0]]), max_drop_m + lift)[0])
    if not np.isfinite(d):
        return None
    floor_z = probe[2] - d
    if abs(p[2] - floor_z) <= v:
        return p.copy()
    return np.array([p[0], p[1], floor_z])


def hover_clear(world: "World", body: np.ndarray, radius_m: float) -> bool:
    """Whether every voxel of the box a robot hovering at ``body`` keeps free (``radius_m``
    to each side, :data:`HOVER_BOX_HALF_HEIGHT_M` up and down), grown by a voxel, is free:
    on the robot's map a wall's voxels reach up to a voxel nearer than the wall, and
    GBPlanner2 does not plan from a start with rock inside the robot's box."""
    v = world.voxel_size_m
    half = np.array([radius_m + v, radius_m + v, HOVER_BOX_HALF_HEIGHT_M + v])
    lo, hi = world.to_index(np.stack([body - half, body + half]))
    if not world.in_bounds(np.stack([lo, hi])).all():
        return False
    return bool(world.free[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1, lo[2]:hi[2] + 1].all())


def clearance_m(world: "World", point: np.ndarray, up_to_m: float) -> float:
    """Distance from ``point`` to the nearest rock (voxel centres, less half a voxel;
    the outside of the grid is rock), looked for up to ``up_to_m`` (and that much
    when none is nearer)."""
    v = world.voxel_size_m
    r = int(np.ceil(up_to_m / v)) + 1
    c = world.to_index(point)[0]
    rng = np.arange(-r, r + 1)
    off = np.stack(np.meshgrid(rng, rng, rng, indexing="ij"), -1).reshape(-1, 3)
    idx = c + off
    rock = ~world.in_bounds(idx)
    inside = ~rock
    rock[inside] = ~world.free[idx[inside, 0], idx[inside, 1], idx[inside, 2]]
    if not rock.any():
        return float(up_to_m)
    d = np.linalg.norm(world.index_to_center(idx[rock]) - np.asarray(point, float), axis=1).min() - 0.5 * v
    return float(min(max(d, 0.0), up_to_m))


def _check_region(world: "World", out: Landing) -> None:
    """The volume of the start's free region, and a warning when it is much smaller
    than the largest region."""
    sizes = world.free_regions()[1]
    try:
        label = world.region_label(out.start + np.array([0.0, 0.0, 0.5 * world.voxel_size_m]))
    except ValueError:
        return
    v3 = world.voxel_size_m ** 3
    n, largest = int(sizes[label]), int(sizes.max())
    out.region_m3 = n * v3
    if n < SMALL_REGION_SHARE * largest:
        out.warnings.append(f"starts in a free region of {n * v3:.0f} m³, {n / largest:.0%} of the largest "
                            f"({largest * v3:.0f} m³): robots explore only the region they start in")
