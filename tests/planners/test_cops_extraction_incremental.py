"""delve.planners.cops.extraction_incremental: the COPS topology updated from the changed
voxels equals the full extraction, after every sweep of a recorded mapping run and on a
hand-made map where one cell changes."""
import numpy as np

from delve.planners.cops import extraction_incremental
from delve.planners.cops.extraction import extract_topology
from delve.planners.cops.extraction_incremental import ExtractionUpdater
from delve.planners.cops.topology import Topology
from delve.planners.navgraph import NavGraph, legged_graph
from delve.planners.navgraph_incremental import LeggedGraphUpdater
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

from .recorded_mapping import grid_of, mine, sweeps, walk
from .test_navgraph_incremental import LEGGED

CELL_M = 8.0                                     # the lattice's cells (m)


def standable_voxels(grid: Grid, graph: NavGraph) -> np.ndarray:
    """Flat indices of the free voxels under the legged graph's nodes (as the COPS view)."""
    idx = grid.to_index(graph.positions - [0.0, 0.0, LEGGED["body_height_m"] - 0.5 * grid.voxel_size_m])
    flat = np.unique(np.ravel_multi_index(tuple(idx.T), grid.shape))
    return flat[grid.occupancy.reshape(-1)[flat] == FREE]


def full(grid: Grid, standable: np.ndarray, **kw) -> Topology:
    """``extract_topology`` as the COPS view called it: standable voxels, all free passable."""
    mask = np.zeros(grid.shape, dtype=bool)
    mask.reshape(-1)[standable] = True
    return extract_topology(grid.occupancy, grid.origin, grid.voxel_size_m, standable=mask,
                            passable=grid.occupancy == FREE, free=grid.free_voxels(), **kw)


def recorded_params() -> dict:
    """The extraction's parameters for the recorded run: a cell centred on its start, the
    radio at the legged robot's body height."""
    return dict(cell_m=CELL_M, lattice_origin=walk(mine())[0] - 0.5 * CELL_M,
                sight_height_m=LEGGED["body_height_m"] - 0.5 * mine().voxel_size_m)


def test_updates_equal_the_full_extraction_after_every_sweep_of_a_recorded_run():
    params = recorded_params()
    updater, graphs = ExtractionUpdater(**params), LeggedGraphUpdater(**LEGGED)
    prior, sizes = {}, []
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine()))):
        grid = grid_of(m)
        stand = standable_voxels(grid, graphs.update(grid, None if i == 0 else changed))
        visited = walk(mine())[: i + 1]
        got = updater.update(grid, None if i == 0 else changed, standable=stand, visited=visited, prior=prior,
                             keep=("c0_0_0",))
        want = full(grid, stand, visited=visited, prior=prior, keep=("c0_0_0",), **params)
        assert got == want, i
        prior = got.merged
        sizes.append(len(got.locations))
    assert sizes[-1] > 3 * sizes[0] > 0          # the network grew along the run


def test_changes_gathered_over_several_sweeps_and_a_cleared_sphere_give_the_full_extraction():
    params = recorded_params()
    updater = ExtractionUpdater(**params)
    pending, topo = [], None
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine())[:40])):
        pending.append(changed)
        if i == 25:   # a local map reset, as after a fault: the ball around the robot is unknown again
            last = np.array(np.unravel_index(m.free_voxels()[-1], m.shape))
            centre = m.origin + (last + 0.5) * m.voxel_size_m
            log = m.change_log()
            m.set_sphere(centre, 3.0, -1)
            pending.append(log.take())
        if i % 7 == 6 or i == 25:
            grid = grid_of(m)
            stand = standable_voxels(grid, legged_graph(grid, **LEGGED))
            topo = updater.update(grid, np.unique(np.concatenate(pending)) if topo is not None else None,
                                  standable=stand)
            pending = []
            assert topo == full(grid, stand, **params)


V = 0.5                                          # the hand-made map's voxels (m)
ROOM_CORNER = np.array([0.0, 12.0, 0.0])         # cell (0, 0, 0) holds the corridor's mouth


def room() -> np.ndarray:
    """A 30 m x 30 m room (x 9..39 m, y 3..33 m) entered from -x by a corridor 4 m wide,
    free between 0.5 m and 3.5 m, in rock."""
    occ = np.full((96, 72, 10), OCCUPIED, dtype=np.int8)
    occ[1:18, 32:40, 1:7] = FREE
    occ[18:78, 6:66, 1:7] = FREE
    return occ


def floor_of(occ: np.ndarray) -> np.ndarray:
    """Flat indices of the free voxels with rock right below."""
    st = np.zeros(occ.shape, dtype=bool)
    st[:, :, 1:] = (occ[:, :, 1:] == FREE) & (occ[:, :, :-1] == OCCUPIED)
    return np.flatnonzero(st)


def test_a_changed_cell_is_the_one_labelled_again_and_the_result_equals_the_full_extraction():
    occ = room()
    grid = Grid(occ, np.zeros(3), V)
    params = dict(cell_m=CELL_M, lattice_origin=ROOM_CORNER)
    updater = ExtractionUpdater(**params)

    def check(changed):
        got = updater.update(grid, changed, standable=floor_of(occ), keep=("c0_0_0",))
        assert got == full(grid, floor_of(occ), keep=("c0_0_0",), **params)
        return got

    whole = check(None)
    assert len(set(whole.merged.values())) == 1 and whole.resolve("c2_0_0") != "c2_0_0"   # one room
    assert len(updater._probed_flat) > 0                    # the room holds centres of open space
    before = {c: cell.ids for c, cell in updater._cells.items()}
    block = np.zeros(occ.shape, dtype=bool)
    block[32:48, 24:40, 1:7] = True                          # rock fills cell (2, 0, 0) ...
    block[32:44, 31:33] = False                              # ... but for a blind passage 1 m wide from -x
    occ[block] = OCCUPIED
    narrowed = check(np.flatnonzero(block))
    assert [c for c in before if updater._cells[c].ids is not before[c]] == [(2, 0, 0)]
    assert narrowed.resolve("c2_0_0") == "c2_0_0" != whole.resolve("c2_0_0")   # no longer in the room
    occ[block] = FREE                                        # mapped again as it was
    assert check(np.flatnonzero(block)) == whole


def test_two_cells_of_a_small_room_merge_when_its_last_wall_is_mapped():
    occ = np.full((60, 60, 10), OCCUPIED, dtype=np.int8)
    occ[25:40, 25:40, 1:7] = FREE                 # 7.5 m square across the face x = 16 m of cells 1 and 2
    occ[39, 25:40, 1:7] = UNKNOWN                 # its +x wall not seen yet: no disc of 4 m fits
    grid = Grid(occ, np.zeros(3), V)
    params = dict(cell_m=CELL_M, lattice_origin=ROOM_CORNER)
    updater = ExtractionUpdater(**params)
    unknown = np.flatnonzero(occ == UNKNOWN)
    assert updater.update(grid, standable=floor_of(occ)) == full(grid, floor_of(occ), **params)
    occ[39, 25:40, 1:7] = FREE                    # now one fits, centred at x = 16.25 m: its probes were
    whole = updater.update(grid, unknown, standable=floor_of(occ))   # mapped, not the centre
    assert whole == full(grid, floor_of(occ), **params) and whole.merged == {"c2_0_0": "c1_0_0"}


def test_a_change_of_the_standable_voxels_alone_is_followed():
    occ = room()
    grid = Grid(occ, np.zeros(3), V)
    params = dict(cell_m=CELL_M, lattice_origin=ROOM_CORNER)
    updater = ExtractionUpdater(**params)
    stand = floor_of(occ)
    whole = updater.update(grid, standable=stand)
    x, y, _ = np.unravel_index(stand, occ.shape)
    fewer = stand[~((x >= 32) & (x < 40) & (y >= 24) & (y < 40))]      # half of cell (2, 0, 0)'s floor
    got = updater.update(grid, np.zeros(0, np.int64), standable=fewer)
    assert got == full(grid, fewer, **params)
    assert got.merged == whole.merged                       # the room's region, its position moved
    assert got.locations[got.resolve("c2_0_0")] != whole.locations[whole.resolve("c2_0_0")]


def test_where_a_layer_falls_in_another_cell_counted_from_the_crop_the_update_is_the_full_one(monkeypatch):
    occ = room()
    # the free voxels given by a function, as a robot's navigator gives them
    grid = Grid(occ, np.zeros(3), V, lambda: np.flatnonzero(occ.reshape(-1) == FREE))
    params = dict(cell_m=CELL_M, lattice_origin=ROOM_CORNER)
    updater = ExtractionUpdater(**params)
    updater.update(grid, standable=floor_of(occ))
    own = extraction_incremental._partition

    def shifted(g, cell_m, corner):   # as if a voxel centre lay on a cell boundary, to the last bit
        parts = own(g, cell_m, corner)
        parts[0] = parts[0] + (np.arange(len(parts[0])) == 30)
        return parts

    monkeypatch.setattr(extraction_incremental, "_partition", shifted)
    pillar = np.zeros(occ.shape, dtype=bool)
    pillar[40:44, 40:44, 1:7] = True
    occ[pillar] = OCCUPIED
    got = updater.update(grid, np.flatnonzero(pillar), standable=floor_of(occ))
    assert got == full(grid, floor_of(occ), **params) and updater._key is None   # afresh next time
