"""Small hand-made worlds shared by the COHORT hub tests: a fork of tunnels carved at
0.2 m, and submaps cut from it (what a robot would have mapped in an x range)."""
from __future__ import annotations

import numpy as np
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import UNKNOWN, Grid
from delve.sim.voxel_map import VoxelMap

T = syn.Tunnel
#: The fork's floor is at z = 1, its tunnels 4 m wide and 3 m high; body height 0.5.
Z = 1.5


def fork() -> Grid:
    """A trunk from x = 2 to 30 at y = 20, then two branches to (50, 5) and (50, 35)."""
    return syn.carve((60, 40, 6), 0.2, [T((2, 20, 1), (30, 20, 1)), T((30, 20, 1), (50, 5, 1)),
                                         T((30, 20, 1), (50, 35, 1))])


def parallel() -> Grid:
    """Two parallel tunnels along x at y = 5 and y = 11, 2 m of rock between them."""
    return syn.carve((30, 16, 6), 0.2, [T((2, 5, 1), (28, 5, 1)), T((2, 11, 1), (28, 11, 1))])


def cut(truth: Grid, x_lo: float, x_hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices and values of the truth's known voxels whose centres lie in
    ``x_lo <= x < x_hi``: a submap."""
    occ = truth.occupancy.reshape(-1)
    known = np.flatnonzero(occ != UNKNOWN)
    x = truth.to_world(np.stack(np.unravel_index(known, truth.shape), axis=1))[:, 0]
    flat = known[(x >= x_lo) & (x < x_hi)]
    return flat, occ[flat].copy()


def base_map(truth: Grid) -> tuple[VoxelMap, Grid]:
    """An empty base map of the truth's geometry and its planner grid (live arrays)."""
    m = VoxelMap(truth.shape, truth.origin, truth.voxel_size_m)
    return m, Grid(occupancy=m.occupancy, origin=m.origin, voxel_size_m=m.voxel_size_m)
