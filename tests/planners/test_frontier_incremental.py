import numpy as np

from delve.planners.frontier import frontier_voxels
from delve.planners.frontier_incremental import FrontierUpdater
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

from .recorded_mapping import grid_of, mine, sweeps, walk


def test_updates_equal_the_full_search_after_every_sweep_of_a_recorded_run():
    updater = FrontierUpdater()
    counts = []
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine()))):
        got = updater.update(grid_of(m), None if i == 0 else changed)
        assert np.array_equal(got, frontier_voxels(grid_of(m)))
        counts.append(len(got))
    assert max(counts) > 0 and len(set(counts)) > 10       # frontiers appeared and went


def test_a_voxel_stops_being_a_frontier_when_the_unknown_run_beside_it_is_seen():
    occ = np.full((12, 5, 5), UNKNOWN, dtype=np.int8)
    occ[:6, 2, 2] = FREE
    grid = Grid(occ, np.zeros(3), 0.2)
    updater = FrontierUpdater()
    assert 5 * 25 + 2 * 5 + 2 in updater.update(grid)            # (5, 2, 2) looks at unknown along +x
    occ[8, 2, 2] = OCCUPIED                                      # the run of three unknown voxels is broken
    assert 5 * 25 + 2 * 5 + 2 not in updater.update(grid, np.array([8 * 25 + 2 * 5 + 2]))
    assert np.array_equal(updater.update(grid, np.zeros(0, np.int64)), frontier_voxels(grid))
