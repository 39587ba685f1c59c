"""A synthetic onboard map whose unseen part a narrow-view LiDAR cannot observe from
where a legged robot stands (issue 16, item 7)."""
from __future__ import annotations

import numpy as np
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid


def drift_with_an_unseen_roof(length_m: float, roof_from_m: float, roof_to_m: float, stub: bool) -> Grid:
    """A closed drift along x, 2.6 m wide, floor at z = 0.4 m, roof at 3.0 m, all known
    except the top 0.6 m of air over ``roof_from_m``..``roof_to_m``: in a 2 m deep side
    stub there (``stub``), else over the drift itself (0.2 m voxels)."""
    v = 0.2
    nx, ny = int(length_m / v) + 2, 26
    occ = np.full((nx, ny, 17), OCCUPIED, dtype=np.int8)
    occ[1:-1, 1:14, 2:15] = FREE
    i0, i1 = int(roof_from_m / v) + 1, int(roof_to_m / v) + 1
    if stub:
        occ[i0:i1, 14:24, 2:15] = FREE
        occ[i0:i1, 14:24, 12:15] = UNKNOWN
    else:
        occ[i0:i1, 1:14, 12:15] = UNKNOWN
    return Grid(occ, np.zeros(3), v)
