"""delve.executive.worlds.voxel_coverage: the maps' coverage of the ground truth, kept
up to date from their change logs, equals reading every map at every truth voxel."""
from __future__ import annotations

import numpy as np

from delve.executive.worlds.voxel_coverage import TruthCoverage
from delve.sim.voxel_map import FREE, OCCUPIED, UNKNOWN, VoxelMap

SHAPE = (30, 12, 8)


def _scan(m: VoxelMap, rng: np.random.Generator) -> None:
    sensor = rng.uniform([0.2, 0.2, 0.2], [5.8, 2.2, 1.4])
    dirs = rng.normal(size=(40, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    m.integrate_scan(sensor, dirs, rng.uniform(0.2, 4.0, 40), 3.5)


def _read(m: VoxelMap, truth: np.ndarray) -> np.ndarray:
    return m.occupancy.reshape(-1)[truth] == FREE


def test_coverage_follows_scans_merges_resets_and_new_maps():
    rng = np.random.default_rng(5)
    truth = np.sort(rng.choice(np.prod(SHAPE), size=900, replace=False))
    maps = {n: VoxelMap(SHAPE, np.zeros(3), 0.2) for n in ("a", "b")}
    base = VoxelMap(SHAPE, np.zeros(3), 0.2)
    cov = TruthCoverage(truth)
    for step in range(30):
        for m in maps.values():
            _scan(m, rng)
        if step % 7 == 3:   # a local map reset: voxels become unknown again
            maps["a"].set_sphere(rng.uniform(0.5, 5.5, 3), 1.0, UNKNOWN)
        if step % 5 == 4:   # rock turns free and free turns rock, as later scans do
            flat = rng.choice(np.prod(SHAPE), 30, replace=False)
            maps["b"].merge(flat, np.full(30, OCCUPIED, np.int8))
        if step == 20:      # a robot's map replaced by a new one
            maps["b"] = VoxelMap(SHAPE, np.zeros(3), 0.2)
        flat, values = maps["a"].take_changes()
        base.merge(flat, values)
        for name, m in maps.items():
            assert cov.fraction(name, m) == _read(m, truth).mean()
        assert cov.fraction("base", base, in_team=False) == _read(base, truth).mean()
        team = _read(maps["a"], truth) | _read(maps["b"], truth)
        assert cov.team_fraction == team.mean()   # the base's map is not the team's
    assert 0 < cov.team_fraction < 1


def test_no_truth_no_coverage():
    cov = TruthCoverage(np.zeros(0, dtype=np.int64))
    assert cov.fraction("a", VoxelMap(SHAPE, np.zeros(3), 0.2)) == 0.0 and cov.team_fraction == 0.0
