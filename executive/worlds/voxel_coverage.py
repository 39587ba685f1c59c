"""Coverage of a voxel world's ground truth by the maps of a mission, kept up to date
from the maps' change logs.

Reading every map at every truth voxel for each coverage sample (every few seconds
of sim time) cost 5 % of a six-robot mission on a 1 km course; a map changes in a
few thousand voxels between samples, so only those are read again.
"""
from __future__ import annotations

import numpy as np

from ...sim.voxel_map import FREE, ChangeLog, VoxelMap


class _Known:
    """Which truth voxels one map knows as FREE (its change log and a flag per voxel)."""

    def __init__(self, voxel_map: VoxelMap, truth: np.ndarray):
        self.map = voxel_map
        self.log: ChangeLog = voxel_map.change_log()
        self.flags = voxel_map.occupancy.reshape(-1)[truth] == FREE
        self.count = int(np.count_nonzero(self.flags))


class TruthCoverage:
    """The share of the truth voxels (flat indices, ascending) that each map knows as
    FREE, and the team's: those known to any robot's map."""

    def __init__(self, truth: np.ndarray):
        self.truth = truth
        self._known: dict[str, _Known] = {}
        #: How many team maps know each truth voxel, and how many voxels one at least.
        self._seers = np.zeros(len(truth), dtype=np.uint16)
        self._team = 0

    def fraction(self, name: str, voxel_map: VoxelMap, in_team: bool = True) -> float:
        """The share of the truth that the map ``name`` knows as FREE now (the whole
        truth is read the first time, or when ``name`` has a new map object); a map
        ``in_team`` counts towards :attr:`team_fraction`."""
        kept = self._known.get(name)
        if kept is None or kept.map is not voxel_map:
            new = _Known(voxel_map, self.truth)
            if in_team:
                old = kept.flags if kept is not None else np.zeros(len(self.truth), dtype=bool)
                self._count(np.arange(len(self.truth)), old, new.flags)
            self._known[name] = kept = new
        else:
            changed = kept.log.take()
            at = np.searchsorted(self.truth, changed)
            inside = at < len(self.truth)
            hit = at[inside][self.truth[at[inside]] == changed[inside]]
            now = voxel_map.occupancy.reshape(-1)[self.truth[hit]] == FREE
            if in_team:
                self._count(hit, kept.flags[hit], now)
            kept.count += int(np.count_nonzero(now)) - int(np.count_nonzero(kept.flags[hit]))
            kept.flags[hit] = now
        return kept.count / len(self.truth) if len(self.truth) else 0.0

    @property
    def team_fraction(self) -> float:
        """The share of the truth known to at least one team map."""
        return self._team / len(self.truth) if len(self.truth) else 0.0

    def _count(self, at: np.ndarray, before: np.ndarray, after: np.ndarray) -> None:
        """Move the team's counts of the voxels ``at`` (distinct) from ``before`` to ``after``."""
        gained, lost = at[after & ~before], at[before & ~after]
        self._team -= int(np.count_nonzero(self._seers[lost] == 1))
        self._seers[lost] -= 1
        self._team += int(np.count_nonzero(self._seers[gained] == 0))
        self._seers[gained] += 1
