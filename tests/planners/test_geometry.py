"""delve.planners.geometry: path lengths, cuts, the nearest segment, rounded points."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.geometry import cut_path, nearest_segment, path_length, xyz

L_PATH = np.array([[0.0, 0.0, 1.0], [3.0, 0.0, 1.0], [3.0, 4.0, 1.0]])


def test_path_length():
    assert path_length(L_PATH) == pytest.approx(7.0)
    assert path_length(L_PATH[:1]) == 0.0
    assert path_length(np.zeros((0, 3))) == 0.0
    assert path_length([[0, 0, 0], [0, 0, 2]]) == pytest.approx(2.0)


def test_cut_path_ends_on_the_point_that_far_along():
    cut = cut_path(L_PATH, 5.0)
    assert np.allclose(cut, [[0, 0, 1], [3, 0, 1], [3, 2, 1]])
    assert path_length(cut) == pytest.approx(5.0)
    assert cut_path(L_PATH, None) is L_PATH
    assert cut_path(L_PATH, 100.0) is L_PATH
    at_corner = cut_path(L_PATH, 3.0)
    assert np.allclose(at_corner[-1], L_PATH[1]) and path_length(at_corner) == pytest.approx(3.0)


def test_nearest_segment():
    assert nearest_segment(L_PATH, np.array([1.0, 0.5, 1.0])) == 0
    assert nearest_segment(L_PATH, np.array([3.5, 3.0, 1.0])) == 1
    assert nearest_segment(L_PATH, np.array([3.0, 0.0, 1.0])) == 0  # the first of equals


def test_xyz_rounds_to_plain_floats():
    out = xyz(np.array([1.23456, -2.0, 3.00049]))
    assert out == [1.235, -2.0, 3.0] and all(type(v) is float for v in out)
    assert xyz(np.array([1.23456, 0, 0]), 2) == [1.23, 0.0, 0.0]
