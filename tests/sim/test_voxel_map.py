import numpy as np

from delve.sim.voxel_map import FREE, OCCUPIED, UNKNOWN, VoxelMap


def test_scan_carves_free_space_and_marks_hits():
    m = VoxelMap((50, 10, 10), np.zeros(3), 0.2)
    sensor = np.array([0.1, 1.0, 1.0])
    dirs = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    ranges = np.array([5.0, np.inf])
    m.integrate_scan(sensor, dirs, ranges, max_range_m=0.9)
    row = m.occupancy[:, 5, 5]
    assert np.all(row[:24] == FREE)
    assert row[25] == OCCUPIED
    assert np.all(row[26:] == UNKNOWN)
    column = m.occupancy[0, :, 5]
    assert np.all(column[5:9] == FREE) and column[9] == UNKNOWN  # no return: free up to range
    assert m.version == 1


def test_scans_carve_the_same_with_int32_and_int64_voxel_indices():
    """Samples of rays leaving the grid on every side (negative indices, beyond its end) are
    dropped alike by the int32 path's unsigned bounds test and the int64 path's."""
    rng = np.random.default_rng(3)
    maps = [VoxelMap((30, 20, 10), np.zeros(3), 0.2) for _ in range(2)]
    maps[1]._axis_dtype = np.int64
    log = [m.change_log() for m in maps]
    for _ in range(5):
        sensor = rng.uniform([0.5, 0.5, 0.5], [5.5, 3.5, 1.5])
        dirs = rng.normal(size=(400, 3))
        dirs /= np.linalg.norm(dirs, axis=1)[:, None]
        ranges = np.where(rng.random(400) < 0.5, rng.uniform(0.1, 8.0, 400), np.inf).astype(np.float32)
        for m in maps:
            m.integrate_scan(sensor, dirs, ranges, 8.0)
    assert maps[0]._axis_dtype == np.int32
    np.testing.assert_array_equal(maps[0].occupancy, maps[1].occupancy)
    np.testing.assert_array_equal(maps[0].free_voxels(), maps[1].free_voxels())
    np.testing.assert_array_equal(log[0].take(), log[1].take())
    assert (maps[0].occupancy == FREE).any() and (maps[0].occupancy == OCCUPIED).any()


def test_free_never_overwrites_occupied():
    m = VoxelMap((20, 5, 5), np.zeros(3), 0.2)
    m.occupancy[10, 2, 2] = OCCUPIED
    m.integrate_scan(np.array([0.1, 0.5, 0.5]), np.array([[1.0, 0, 0]]), np.array([np.inf]), 3.5)
    assert m.occupancy[10, 2, 2] == OCCUPIED


def test_changes_are_taken_once_and_merge_keeps_occupied():
    a = VoxelMap((20, 5, 5), np.zeros(3), 0.2)
    a.integrate_scan(np.array([0.1, 0.5, 0.5]), np.array([[1.0, 0, 0]]), np.array([2.0]), 3.5)
    flat, values = a.take_changes()
    assert len(flat) > 0 and set(values) == {FREE, OCCUPIED}
    assert len(a.take_changes()[0]) == 0
    b = VoxelMap((20, 5, 5), np.zeros(3), 0.2)
    b.occupancy.reshape(-1)[flat] = OCCUPIED
    b.merge(flat, values)
    assert np.all(b.occupancy.reshape(-1)[flat] == OCCUPIED)
    c = VoxelMap((20, 5, 5), np.zeros(3), 0.2)
    c.merge(flat, values)
    assert np.array_equal(c.occupancy, a.occupancy)


def test_free_voxels_track_scans_resets_and_rescans_without_duplicates():
    m = VoxelMap((30, 10, 10), np.zeros(3), 0.2)
    sensor, ray = np.array([0.1, 1.0, 1.0]), np.array([[1.0, 0.0, 0.0]])
    m.integrate_scan(sensor, ray, np.array([4.0]), 5.0)
    first = m.free_voxels().copy()
    assert np.array_equal(np.sort(first), np.flatnonzero(m.occupancy.reshape(-1) == FREE))
    m.set_sphere(sensor + [1.0, 0, 0], 0.5, UNKNOWN)  # forget part of it
    assert len(m.free_voxels()) < len(first)
    m.integrate_scan(sensor, ray, np.array([4.0]), 5.0)  # and map it again
    again = m.free_voxels()
    assert len(np.unique(again)) == len(again)
    assert np.array_equal(np.sort(again), np.sort(first))


class _DenseChanges(VoxelMap):
    """The change log as it was: one bool per voxel (the reference for the bit log)."""

    def __init__(self, *args):
        super().__init__(*args)
        self._dense = np.zeros(self.occupancy.size, dtype=bool)

    def _touch(self, flat):
        self._dense[flat] = True

    def take_changes(self):
        flat = np.flatnonzero(self._dense)
        self._dense[flat] = False
        return flat, self.occupancy.reshape(-1)[flat].copy()


def test_bit_change_log_takes_what_a_bool_grid_would_on_random_updates():
    rng = np.random.default_rng(5)
    shape, origin = (23, 17, 11), np.array([-1.0, -2.0, 0.5])   # 4301 voxels: not a multiple of 8
    bits, dense = VoxelMap(shape, origin, 0.2), _DenseChanges(shape, origin, 0.2)
    lo, hi = origin, origin + np.array(shape) * 0.2
    taken = 0
    for step in range(60):
        kind = rng.integers(4)
        if kind < 2:
            sensor = rng.uniform(lo - 0.5, hi + 0.5)          # sometimes outside the grid
            dirs = rng.normal(size=(40, 3))
            dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
            ranges = np.where(rng.random(40) < 0.7, rng.uniform(0.1, 4.0, 40), np.inf)
            for m in (bits, dense):
                m.integrate_scan(sensor, dirs, ranges, 3.0)
        elif kind == 2:
            centre, value = rng.uniform(lo, hi), int(rng.integers(-1, 2))
            for m in (bits, dense):
                m.set_sphere(centre, 0.5, value)
        else:
            (fa, va), (fd, vd) = bits.take_changes(), dense.take_changes()
            np.testing.assert_array_equal(fa, fd)
            np.testing.assert_array_equal(va, vd)
            taken += len(fa)
        np.testing.assert_array_equal(bits.occupancy, dense.occupancy)
    (fa, va), (fd, vd) = bits.take_changes(), dense.take_changes()
    np.testing.assert_array_equal(fa, fd)
    np.testing.assert_array_equal(va, vd)
    assert taken + len(fa) > 100 and bits.occupancy.size - 1 in range(bits._dirty.size * 8)
    assert len(bits.take_changes()[0]) == 0


def test_change_log_holds_the_last_voxel_of_the_grid():
    m = VoxelMap((3, 3, 3), np.zeros(3), 1.0)
    m.set_sphere(np.array([2.5, 2.5, 2.5]), 0.1, OCCUPIED)
    flat, values = m.take_changes()
    assert flat.tolist() == [26] and values.tolist() == [OCCUPIED]
    assert m._dirty.nbytes == 8                      # 27 voxels, one bit each, in a 64-bit word


def test_each_consumers_change_log_holds_scans_resets_and_merges_since_its_last_take():
    m = VoxelMap((20, 5, 5), np.zeros(3), 0.2)
    early = m.change_log()
    m.integrate_scan(np.array([0.1, 0.5, 0.5]), np.array([[1.0, 0, 0]]), np.array([2.0]), 3.5)
    late = m.change_log()
    first = early.take()
    assert np.array_equal(first, np.sort(np.flatnonzero(m.occupancy.reshape(-1) != UNKNOWN)))
    assert len(late.take()) == 0 and len(early.take()) == 0       # taken once; late came after the scan
    before = m.occupancy.copy()
    m.set_sphere(np.array([1.0, 0.5, 0.5]), 0.3, UNKNOWN)
    m.merge(np.array([0, 99]), np.array([OCCUPIED, FREE], np.int8))
    m.take_changes()                                               # map sharing does not empty the logs
    changed = np.flatnonzero((m.occupancy != before).reshape(-1))
    for log in (early, late):
        got = log.take()
        assert np.all(np.isin(changed, got)) and np.array_equal(got, np.unique(got))


def test_the_free_list_is_filtered_again_only_when_a_free_voxel_turns_to_rock():
    """A sweep whose hits fall only in unknown voxels leaves the list of free voxels as
    it is; one that hits a free voxel drops just that voxel from the list."""
    m = VoxelMap((20, 20, 20), np.zeros(3), 0.2)
    sensor = np.array([0.5, 2.0, 2.0])
    along_x = np.array([[1.0, 0.0, 0.0]])
    m.integrate_scan(sensor, along_x, np.array([2.0]), 3.0)
    m.integrate_scan(sensor, np.array([[0.0, 1.0, 0.0]]), np.array([1.0]), 3.0)
    assert not m._free_stale   # rock where the map knew nothing
    before = m.free_voxels().copy()
    m.integrate_scan(sensor, along_x, np.array([1.0]), 3.0)   # rock inside the carved run
    assert m._free_stale
    hit = int(np.ravel_multi_index((7, 10, 10), m.shape))
    assert hit in before and m.occupancy.reshape(-1)[hit] == OCCUPIED
    np.testing.assert_array_equal(m.free_voxels(), before[before != hit])
