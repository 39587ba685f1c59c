"""Synthetic test worlds."""
import numpy as np
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN


def test_straight_tunnel_is_free_inside_rock_on_the_walls_unknown_beyond_the_map():
    g, a, _b = s.straight_tunnel(length_m=20, width_m=4, height_m=3, mapped_to_m=12)
    mid = a + np.array([4.0, 0, 1.5])
    assert g.value_at(mid)[0] == FREE
    assert g.value_at(mid + [0, 2.1, 0])[0] == OCCUPIED  # wall surface
    assert g.value_at(mid + [0, 3.0, 0])[0] == UNKNOWN  # rock behind the surface
    assert g.value_at(mid - [0, 0, 1.6])[0] == OCCUPIED  # floor
    assert g.value_at(a + np.array([15.0, 0, 1.5]))[0] == UNKNOWN  # beyond the mapped part
    assert g.value_at(a + np.array([-0.1, 0, 1.5]))[0] == OCCUPIED  # closed start


def test_shaft_hole_is_unknown_and_slope_rises():
    g, _west, hole = s.shaft_tunnel()
    c = (np.array(hole.lo) + np.array(hole.hi)) / 2
    assert g.value_at(np.array([c[0], c[1], hole.hi[2] - 0.1]))[0] == UNKNOWN
    g2, bottom, top = s.slope_tunnel(20.0)
    assert top[2] - bottom[2] > 2.5
    assert g2.value_at(top + [1.0, 0, 0.5])[0] == FREE
    assert g2.value_at(top + [1.0, 0, -0.1])[0] == OCCUPIED


def test_tunnel_network_has_hundreds_of_metres_of_tunnel():
    g, tunnels = s.tunnel_network(voxel_size_m=0.5, extent_m=120.0, spacing_m=40.0)
    length = sum(np.linalg.norm(np.subtract(t.end, t.start)) for t in tunnels)
    assert length > 300
    assert (g.occupancy == FREE).sum() * 0.125 > 0.5 * length * 4 * 3
