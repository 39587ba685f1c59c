"""The frontier voxels of a map kept up to date from the voxels that changed.

Whether a voxel is a frontier (:func:`delve.planners.frontier.frontier_voxels`: free,
with ``depth`` unknown voxels in a row along one of the six face directions) depends
only on the voxel and the ``depth`` voxels along each face direction. A voxel that is
no frontier becomes one only if it becomes free, or if a voxel along one of its face
directions becomes unknown again (a local map reset); a scan only makes voxels known.
So :class:`FrontierUpdater` tests again the frontier voxels it has, the changed voxels
that are free, and the voxels that see a voxel that became unknown; its result equals
``frontier_voxels(grid)`` exactly, in the same order (the map's order of free voxels).
"""
from __future__ import annotations

import numpy as np

from .frontier import FRONTIER_DEPTH, frontier_voxels
from .navgraph import FACES, around
from .occupancy import FREE, UNKNOWN, Grid


class FrontierUpdater:
    """The frontier voxels of one map, updated from its changed voxels. Memory: one
    byte per voxel of the grid (zero-filled: only pages near the frontier are backed)."""

    def __init__(self, depth: int = FRONTIER_DEPTH):
        self.depth = depth
        self._flag: np.ndarray | None = None
        self._shape: tuple[int, int, int] | None = None
        self._frontiers = np.zeros(0, dtype=np.int64)
        #: Voxels that see a changed voxel: it and the ``depth`` voxels before it along each face.
        self._seen_from = [(0, 0, 0)] + [(-a * k, -b * k, -c * k) for a, b, c in FACES for k in range(1, depth + 1)]

    def update(self, grid: Grid, changed: np.ndarray | None = None) -> np.ndarray:
        """Flat indices of the frontier voxels of ``grid`` (as ``frontier_voxels(grid)``)
        after the voxels ``changed`` (flat indices) changed since the last update; every
        known voxel is tested when ``changed`` is None, on the first update, or for a
        grid of another shape."""
        occ = grid.occupancy.reshape(-1)
        if changed is None or self._shape != grid.shape:
            self._shape, self._flag = grid.shape, np.zeros(occ.size, dtype=np.uint8)
            self._frontiers = np.zeros(0, dtype=np.int64)
            changed = np.flatnonzero(occ != UNKNOWN)
        changed = np.asarray(changed, dtype=np.int64)
        retest = np.concatenate([self._frontiers, changed[occ[changed] == FREE],
                                 around(changed[occ[changed] == UNKNOWN], grid.shape, self._seen_from)])
        self._flag[retest] = 0
        self._flag[frontier_voxels(grid, among=retest, depth=self.depth)] = 1
        free = grid.free_voxels()
        self._frontiers = free[self._flag[free] > 0]
        return self._frontiers
