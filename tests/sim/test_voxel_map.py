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
    assert 0 < c.known_fraction_of(np.arange(c.occupancy.size)) < 1


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
