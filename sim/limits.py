"""Limits on the size of a world, checked before its grid is allocated.

A typo (``voxel_size_m: 0.0005``, ``scale: 1000`` on a mesh in millimetres,
``total_length_m: 1e9``) would otherwise ask for terabytes or plan for hours. Each
check raises a ValueError that names the one parameter at fault, so that the
executive points at its line (docs/scenarios.md, "Limits").
"""
from __future__ import annotations

import math
from typing import Sequence

#: Most voxels a world's grid may hold: a 300 x 500 m mine at 0.2 m up to 26 m tall
#: (the largest shipped world, demo's 400 m tunnel network, has 16 million). A run
#: keeps about 3 bytes per voxel for the world (free space, region labels, the space
#: reachable from the start) and one in each robot's onboard map and in the base
#: station's; building the world peaks at about 10 bytes a voxel (a generated
#: mine) or 16 (a closed mesh file). So 500 million voxels: 1.5 GB for the world,
#: 0.5 GB per robot, at most 8 GB while loading (docs/benchmarks.md, "Memory and
#: scale").
MAX_WORLD_VOXELS = 500_000_000
#: Longest centreline a generator lays out (m): 50 times the largest shipped world
#: (400 m); planning grows with it and the box with its square.
MAX_TOTAL_LENGTH_M = 20_000.0
#: The voxel size the procedural generators default to (m), used to tell whether a
#: world is too large because of its length or because of its voxels.
DEFAULT_VOXEL_SIZE_M = 0.2


def voxel_count(extent_m: Sequence[float], voxel_size_m: float) -> float:
    """Voxels of a grid of ``voxel_size_m`` covering a box of ``extent_m`` (a float,
    so that absurd sizes do not overflow)."""
    return math.prod(math.floor(max(float(e), 0.0) / voxel_size_m) + 1.0 for e in extent_m)


def check_total_length(total_length_m: float) -> None:
    """ValueError when a generator's centreline is longer than delve plans."""
    if total_length_m > MAX_TOTAL_LENGTH_M:
        raise ValueError(f"total_length_m {total_length_m:g} is more than {MAX_TOTAL_LENGTH_M:g} m, "
                         "the longest world delve generates")


def check_voxels(count: float, voxel_size_m: float, what: str, other_key: str | None = None,
                 other_count: float | None = None) -> None:
    """ValueError when a world of ``count`` voxels (``what`` says of what) is over
    :data:`MAX_WORLD_VOXELS`. The message names ``other_key`` (the world's length
    or a mesh's scale) when ``other_count``, the voxels at the default voxel size,
    is over the limit too; else ``voxel_size_m`` (and ``other_key`` after it when
    ``other_count`` is not known)."""
    if count <= MAX_WORLD_VOXELS:
        return
    if other_key is not None and other_count is not None and other_count > MAX_WORLD_VOXELS:
        fix = f"lower {other_key}"
    else:
        fix = f"raise voxel_size_m (now {voxel_size_m:g} m)" + (f" or lower {other_key}" if other_key and other_count is None else "")
    raise ValueError(f"{what} needs {count:.2g} voxels, more than the limit of {MAX_WORLD_VOXELS:.0e}: {fix}")
