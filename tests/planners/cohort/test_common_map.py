"""delve.planners.cohort.common_map: the common map at r_C, pooled from the fine map."""
import numpy as np
from delve.planners.cohort import CommonMap, align_submap
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN

from .worlds import cut, fork


def test_the_block_size_is_the_multiple_of_the_fine_voxel_nearest_r_c():
    assert CommonMap((10, 10, 10), np.zeros(3), 0.2, 0.4).factor == 2
    assert CommonMap((10, 10, 10), np.zeros(3), 0.3, 0.4).voxel_size_m == 0.3
    m = CommonMap((9, 10, 11), np.zeros(3), 0.1, 0.4)
    assert m.factor == 4 and m.shape == (3, 3, 3)


def test_a_block_is_rock_if_any_voxel_is_then_free_if_any_is():
    m = CommonMap((4, 2, 2), np.zeros(3), 0.2, 0.4)
    flat = np.ravel_multi_index(([0, 1, 2], [0, 1, 0], [0, 0, 1]), (4, 2, 2))
    blocks = m.merge(flat, np.array([FREE, OCCUPIED, FREE], np.int8))
    assert list(blocks) == [0, 1]
    assert list(m.occupancy.reshape(-1)) == [OCCUPIED, FREE]
    blocks, pooled = m.pool(flat[2:], np.array([UNKNOWN], np.int8))
    assert list(pooled) == [UNKNOWN]


def test_incremental_merges_equal_pooling_the_whole_fine_map():
    truth = fork()
    m = CommonMap(truth.shape, truth.origin, truth.voxel_size_m, 0.4)
    fine = np.full(truth.shape, UNKNOWN, np.int8).reshape(-1)
    for lo, hi in [(0, 20), (15, 40), (35, 60)]:
        flat, values = align_submap(*cut(truth, lo, hi))
        fine[flat] = np.maximum(fine[flat], values)
        m.merge(flat, fine[flat])
    nx, ny, nz = m.shape
    padded = np.full((nx * 2, ny * 2, nz * 2), UNKNOWN, np.int8)
    padded[: truth.shape[0], : truth.shape[1], : truth.shape[2]] = fine.reshape(truth.shape)
    expected = padded.reshape(nx, 2, ny, 2, nz, 2).max(axis=(1, 3, 5))
    assert np.array_equal(m.occupancy, expected)
    assert (m.occupancy == FREE).any() and (m.occupancy == OCCUPIED).any()


def test_submaps_merged_in_any_order_give_the_same_map():
    """Submaps queued while the link was down arrive late and out of order: a newer
    submap's rock (seen where an older one saw free space) stays rock either way."""
    import itertools

    truth = fork()
    submaps = [align_submap(*cut(truth, lo, hi)) for lo, hi in [(0, 20), (15, 40), (35, 60)]]
    older_flat, older_values = submaps[1]
    seen_free = older_values.copy()
    seen_free[older_values == OCCUPIED] = FREE   # the older look: rock not yet told apart from free
    submaps.insert(1, (older_flat, seen_free))
    maps = []
    for order in itertools.permutations(range(len(submaps))):
        m = CommonMap(truth.shape, truth.origin, truth.voxel_size_m, 0.4)
        for i in order:
            m.merge(*submaps[i])
        maps.append(m.occupancy)
    assert all(np.array_equal(maps[0], other) for other in maps[1:])
    assert (maps[0] == OCCUPIED).any()
