"""Collision checks and ground projection of one planning iteration."""
import math

import numpy as np
from delve.planners.gbplanner2 import synthetic as s
from delve.planners.gbplanner2.config import GBPlannerConfig
from delve.planners.gbplanner2.local_map import (
    GROUND_ATTACHED,
    GROUND_BLOCKED,
    GROUND_NONE,
    LocalMap,
    box_half_voxels,
    erode,
)
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid
from scipy import ndimage

LEGGED = GBPlannerConfig.anymal_c()
AERIAL = GBPlannerConfig.rmf_obelix()


def whole(grid: Grid, cfg: GBPlannerConfig, **kw) -> LocalMap:
    hi = grid.origin + np.array(grid.shape) * grid.voxel_size_m
    return LocalMap(grid, grid.origin, hi, cfg, **kw)


def test_erode_matches_scipy_minimum_filter():
    rng = np.random.default_rng(0)
    for _ in range(20):
        shape = tuple(int(v) for v in rng.integers(1, 10, 3))
        m = rng.random(shape) < 0.8
        h = rng.integers(0, 4, 3)
        ref = ndimage.minimum_filter(m.view(np.uint8), size=tuple(2 * h + 1), mode="constant", cval=0)
        assert np.array_equal(erode(m, h), ref.view(bool))


def test_box_free_matches_brute_force_and_unknown_is_not_free():
    rng = np.random.default_rng(1)
    occ = rng.choice(np.array([FREE, FREE, FREE, FREE, OCCUPIED, UNKNOWN], np.int8), size=(14, 12, 10))
    grid = Grid(occ, np.zeros(3), 0.3)
    lm = whole(grid, AERIAL)
    half = box_half_voxels(AERIAL.robot_box_size_m, 0.3)
    pts = rng.uniform(0.0, 3.0, size=(300, 3))
    got = lm.is_box_free(pts)
    idx = grid.to_index(pts)
    for p, i, g in zip(pts, idx, got):
        lo, hi = i - half, i + half + 1
        if np.any(lo < 0) or np.any(hi > np.array(grid.shape)):
            assert not g
            continue
        box = occ[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        assert g == bool(np.all(box == FREE))
    # a box touching only unknown voxels is not free
    unknown = Grid(np.full((10, 10, 10), UNKNOWN, np.int8), np.zeros(3), 0.3)
    assert not whole(unknown, AERIAL).is_box_free(np.array([[1.5, 1.5, 1.5]]))[0]


def test_clearing_the_start_box_frees_only_unknown_voxels():
    occ = np.full((20, 20, 20), UNKNOWN, np.int8)
    grid = Grid(occ, np.zeros(3), 0.3)
    p = np.array([3.0, 3.0, 3.0])
    lm = whole(grid, AERIAL, clear_box_at=p)
    assert lm.is_box_free(p[None])[0]
    assert not lm.box_has_occupied(p)
    occ2 = occ.copy()
    occ2[10, 10, 10] = OCCUPIED
    lm2 = whole(Grid(occ2, np.zeros(3), 0.3), AERIAL, clear_box_at=p)
    assert lm2.box_has_occupied(p)


def test_ground_projection_attached_hanging_and_blocked():
    g, west, hole = s.shaft_tunnel()
    lm = whole(g, LEGGED)
    floor = west[2]
    on_floor = np.array([west[0] + 3.0, west[1], floor + 1.7])
    c = (np.array(hole.lo) + np.array(hole.hi)) / 2
    over_shaft = np.array([c[0], c[1], floor + 1.0])
    in_rock = np.array([west[0] + 3.0, west[1], floor - 0.5])
    gz, st = lm.project_to_ground(np.stack([on_floor, over_shaft, in_rock]))
    assert st.tolist() == [GROUND_ATTACHED, GROUND_NONE, GROUND_BLOCKED]
    assert abs(gz[0] - floor) < 1e-9
    # Near the shaft's rim the circle around the point finds the floor beside it.
    rim = np.array([hole.lo[0] + 0.2, c[1], floor + 1.0])
    gz, st = lm.project_to_ground(rim[None])
    assert st[0] == GROUND_ATTACHED and abs(gz[0] - floor) < 1e-9
    no_circle = LocalMap(g, g.origin, g.origin + np.array(g.shape) * g.voxel_size_m,
                         LEGGED.replace(ground_circle_points=0))
    assert no_circle.project_to_ground(rim[None])[1][0] == GROUND_NONE


def test_aerial_edges_through_rock_are_refused():
    g, a, _b = s.straight_tunnel(length_m=20, width_m=4, height_m=3, voxel_size_m=0.3)
    lm = whole(g, AERIAL)
    p = a + np.array([5.0, 0, 1.5])
    along = lm.check_edges(p[None], (p + [4.0, 0, 0])[None])
    across = lm.check_edges(p[None], (p + [0, 4.0, 0])[None])
    assert along.admissible[0] and not across.admissible[0]
    assert math.isclose(along.length_m[0], 4.0)


def test_legged_edges_refuse_steep_slopes_and_steps():
    cfg = LEGGED
    for angle, ok in ((15.0, True), (45.0, False)):
        g, bottom, _top = s.slope_tunnel(angle)
        lm = whole(g, cfg)
        a = bottom + np.array([-1.0, 0, cfg.body_height_m])
        rise = 2.0 * math.tan(math.radians(angle))
        gz, st = lm.project_to_ground((bottom + np.array([2.0, 0, rise + 1.0]))[None])
        assert st[0] == GROUND_ATTACHED
        b = np.array([bottom[0] + 2.0, bottom[1], gz[0] + cfg.body_height_m])
        assert lm.check_edges(a[None], b[None]).admissible[0] == ok
    # a flat edge on the floor is fine
    g, bottom, _top = s.slope_tunnel(15.0)
    lm = whole(g, cfg)
    a = bottom + np.array([-5.0, 0, cfg.body_height_m])
    assert lm.check_edges(a[None], (a + [2.5, 0, 0])[None]).admissible[0]


def test_edge_to_a_hanging_vertex_needs_only_a_free_gentle_segment():
    g, west, hole = s.shaft_tunnel()
    lm = whole(g, LEGGED)
    floor = west[2]
    c = (np.array(hole.lo) + np.array(hole.hi)) / 2
    a = np.array([hole.lo[0] - 1.0, c[1], floor + LEGGED.body_height_m])
    h = np.array([c[0], c[1], floor + LEGGED.body_height_m])
    assert not lm.check_edges(a[None], h[None]).admissible[0]
    assert lm.check_edges(a[None], h[None], hanging_end=np.array([True])).admissible[0]
    steep = h + np.array([0, 0, 2.0])
    assert not lm.check_edges(a[None], steep[None], hanging_end=np.array([True])).admissible[0]
