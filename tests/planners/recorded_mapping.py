"""A recorded mapping run for the incremental-versus-full tests: the legged robot's
LiDAR and terrain cameras swept every metre along the centreline of a small generated
mine (depth first from the portal, as an explorer walks it), each sweep integrated
into an onboard :class:`~delve.sim.voxel_map.VoxelMap`, and the voxels each sweep
changed taken from the map's change log."""

from __future__ import annotations

from collections.abc import Iterator
from functools import lru_cache

import networkx as nx
import numpy as np

from delve.planners.occupancy import Grid
from delve.sim import worldgen
from delve.sim.platforms import LEGGED
from delve.sim.voxel_map import VoxelMap
from delve.sim.world import World

#: Metres walked between sweeps (a robot at 1 m/s integrates one sweep a second).
STEP_M = 1.0


@lru_cache(maxsize=1)
def mine() -> World:
    """A 100 m tunnel network with forks and dead ends, no loops, flat floors."""
    return worldgen.tunnel_network(1, total_length_m=100.0, loops=0, ramp=False)


def walk(world: World, step_m: float = STEP_M) -> np.ndarray:
    """(N, 3) floor points every ``step_m`` along the centreline, depth first from node 0
    (back along each dead end to the fork, as an explorer walks)."""
    g = world.centreline
    points = []
    for a, b in nx.dfs_edges(g, 0):
        pa, pb = g.nodes[a]["pos"], g.nodes[b]["pos"]
        n = max(1, int(np.linalg.norm(pb - pa) // step_m))
        points.append(pa + (pb - pa) * (np.arange(n + 1) / n)[:, None])
    return np.concatenate(points)


def sweeps(world: World, points: np.ndarray) -> Iterator[tuple[VoxelMap, np.ndarray]]:
    """After each sweep from ``points`` (floor points): the map and the flat indices of
    the voxels the sweep changed."""
    m = VoxelMap(world.free.shape, world.origin, world.voxel_size_m)
    log = m.change_log()
    for i, floor in enumerate(points):
        for spec in (LEGGED.lidar, LEGGED.terrain):
            sensor = floor + [0.0, 0.0, LEGGED.body_height_m + spec.mount_height_m]
            dirs = spec.beam_directions(0.37 * i)
            ranges = world.cast_rays(np.broadcast_to(sensor, dirs.shape), dirs, spec.range_m)
            m.integrate_scan(sensor, dirs, ranges, spec.range_m)
        yield m, log.take()


def grid_of(m: VoxelMap) -> Grid:
    """The planners' view of the map (as the navigator makes it)."""
    return Grid(m.occupancy, m.origin, m.voxel_size_m, m.free_voxels())
