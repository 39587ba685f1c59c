"""The hub's common map M_C at COHORT's resolution r_C, kept beside the fine base map.

The base station's map and every robot's onboard map share the world's voxel grid
(voxel size ``v``, often 0.2 or 0.3 m); COHORT computes frontiers at r_C (0.4 m in the
paper). The common map pools the fine voxels in blocks of ``factor`` = round(r_C / v)
(at least 1) per axis, so its voxel size is ``factor * v``, the nearest multiple of
``v`` to r_C.

Rule for a block (coarse voxel): OCCUPIED if any of its fine voxels is OCCUPIED, else
FREE if any is FREE, else UNKNOWN. With the values UNKNOWN = -1 < FREE = 0 <
OCCUPIED = 1 this is the maximum over the block, and since merging into the base map
only ever raises a voxel's value (``VoxelMap.merge``: OCCUPIED wins over FREE, nothing
is forgotten), the common map is updated exactly and incrementally from each delta
with ``np.maximum.at``, never by re-pooling the whole grid. One free fine voxel makes
its block free, so the small holes that sparse far-range LiDAR rays leave in observed
space do not become frontiers; one occupied fine voxel makes it rock, so edges checked
on it keep a margin from the walls.

Alignment: localisation is perfect in the simulator, so a submap's pose in the common
frame I_C is the identity (:func:`align_submap`); a map-alignment step (Voxgraph in the
paper) would go there.
"""
from __future__ import annotations

import numpy as np

from ..occupancy import UNKNOWN, Grid


def align_submap(flat: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The seam of the paper's map alignment: a submap's fine voxels (flat indices over
    the world grid, values) expressed in the common frame. Identity here (perfect
    localisation in the simulator)."""
    return flat, values


class CommonMap:
    """The common map at r_C over a fine world grid.

    ``occupancy`` (coarse int8 grid), ``origin`` (same as the fine grid's),
    ``voxel_size_m`` (``factor`` fine voxels), ``factor``, ``fine_shape``,
    ``fine_voxel_size_m``.
    """

    def __init__(self, fine_shape: tuple[int, int, int], origin: np.ndarray, fine_voxel_size_m: float,
                 resolution_m: float) -> None:
        self.fine_shape = tuple(int(s) for s in fine_shape)
        self.fine_voxel_size_m = float(fine_voxel_size_m)
        self.factor = max(1, int(round(resolution_m / self.fine_voxel_size_m)))
        self.origin = np.asarray(origin, dtype=float)
        self.voxel_size_m = self.factor * self.fine_voxel_size_m
        shape = tuple(-(-s // self.factor) for s in self.fine_shape)
        self.occupancy = np.full(shape, UNKNOWN, dtype=np.int8)

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.occupancy.shape  # type: ignore[return-value]

    @property
    def grid(self) -> Grid:
        """The common map as a planner :class:`Grid` (a view, not a copy)."""
        return Grid(occupancy=self.occupancy, origin=self.origin, voxel_size_m=self.voxel_size_m)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """World corners (min, max) of the fine grid: the world the map can hold."""
        return self.origin, self.origin + np.asarray(self.fine_shape, float) * self.fine_voxel_size_m

    def coarse_of(self, flat: np.ndarray) -> np.ndarray:
        """Fine flat indices -> flat indices of their blocks in the common map."""
        i, j, k = np.unravel_index(np.asarray(flat, dtype=np.int64), self.fine_shape)
        return np.ravel_multi_index((i // self.factor, j // self.factor, k // self.factor), self.shape)

    def pool(self, flat: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The blocks that fine voxels ``flat`` fall in (ascending, unique) and the block
        rule applied to ``values`` alone (the maximum per block): a submap at r_C."""
        coarse = self.coarse_of(flat)
        blocks, inverse = np.unique(coarse, return_inverse=True)
        pooled = np.full(len(blocks), UNKNOWN, dtype=np.int8)
        np.maximum.at(pooled, inverse.reshape(-1), np.asarray(values, dtype=np.int8))
        return blocks, pooled

    def merge(self, flat: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Raise the blocks of fine voxels ``flat`` to ``values`` (the fine map's values
        after its own merge); returns the blocks touched (ascending, unique)."""
        blocks, pooled = self.pool(flat, values)
        occ = self.occupancy.reshape(-1)
        occ[blocks] = np.maximum(occ[blocks], pooled)
        return blocks

    def values(self, blocks: np.ndarray) -> np.ndarray:
        """Values of blocks (flat indices of the common map)."""
        return self.occupancy.reshape(-1)[np.asarray(blocks, dtype=np.int64)]

    def centres(self, blocks: np.ndarray) -> np.ndarray:
        """World centres (N, 3) of blocks (flat indices of the common map)."""
        return self.grid.to_world(np.stack(np.unravel_index(np.asarray(blocks, np.int64), self.shape), axis=1))
