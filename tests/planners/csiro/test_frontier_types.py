import dataclasses

import numpy as np
import pytest

from delve.planners.csiro.frontier_types import Frontier


def test_a_frontiers_area_is_the_sum_of_its_triangles_and_it_is_frozen():
    f = Frontier(id=1, points=np.zeros((2, 3)), normals=np.tile([1.0, 0, 0], (2, 1)), areas=np.array([0.25, 0.5]),
                 mean=np.zeros(3), cov=np.eye(3))
    assert f.area == 0.75 and isinstance(f.area, float)
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.id = 2
