"""delve.planners.cops.extraction_incremental: the COPS topology updated from the changed
voxels equals the full extraction, after every sweep of a recorded mapping run and on a
hand-made map where one cell changes."""
import numpy as np

from delve.planners.cops.extraction import extract_topology
from delve.planners.cops.extraction_incremental import ExtractionUpdater
from delve.planners.cops.topology import Topology
from delve.planners.navgraph import legged_graph
from delve.planners.occupancy import FREE, Grid

from .recorded_mapping import grid_of, mine, sweeps, walk
from .test_navgraph_incremental import LEGGED

#: The lattice's corner: a cell centred on the start of the recorded walk.
CELL_M = 8.0


def standable_voxels(grid: Grid) -> np.ndarray:
    """Flat indices of the free voxels under the legged graph's nodes (as the COPS view)."""
    graph = legged_graph(grid, **LEGGED)
    idx = grid.to_index(graph.positions - [0.0, 0.0, LEGGED["body_height_m"] - 0.5 * grid.voxel_size_m])
    flat = np.unique(np.ravel_multi_index(tuple(idx.T), grid.shape))
    return flat[grid.occupancy.reshape(-1)[flat] == FREE]


def full(grid: Grid, standable: np.ndarray, **kw) -> Topology:
    mask = np.zeros(grid.shape, dtype=bool)
    mask.reshape(-1)[standable] = True
    return extract_topology(grid.occupancy, grid.origin, grid.voxel_size_m, standable=mask,
                            passable=grid.occupancy == FREE, free=grid.free, **kw)


def test_updates_equal_the_full_extraction_after_every_sweep_of_a_recorded_run():
    corner = walk(mine())[0] - 0.5 * CELL_M
    params = dict(cell_m=CELL_M, lattice_origin=corner, sight_height_m=0.4)
    updater = ExtractionUpdater(**params)
    prior, sizes = {}, []
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine()))):
        grid = grid_of(m)
        stand = standable_voxels(grid)
        visited = walk(mine())[: i + 1]
        got = updater.update(grid, None if i == 0 else changed, standable=stand, visited=visited, prior=prior,
                             keep=("c0_0_0",))
        want = full(grid, stand, visited=visited, prior=prior, keep=("c0_0_0",), **params)
        assert got == want, i
        prior = got.merged
        sizes.append(len(got.locations))
    assert sizes[-1] > 3 * sizes[0] > 0          # the network grew along the run
