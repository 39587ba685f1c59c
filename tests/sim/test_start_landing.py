"""Where starts land (delve.sim.start_landing) and what a world's survey warns about
(delve.sim.world_survey), on a closed corridor 10 x 4 x 3 m (floor at z = 0) and a
small closet apart from it."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from delve.sim.platforms import AERIAL, LEGGED
from delve.sim.start_landing import SNAP_DOWN_M, land
from delve.sim.worldfile import from_file
from delve.sim.world_survey import survey, world_warnings

from .mine_models import closed_corridor

V = 0.2


@pytest.fixture(scope="module")
def rooms(tmp_path_factory):
    """The corridor, and a 2 x 2 x 2 m closet 10 m beside it."""
    closet = closed_corridor(2.0, 2.0, 2.0)
    closet.apply_translation((0.0, 10.0, 0.0))
    path = tmp_path_factory.mktemp("rooms") / "rooms.ply"
    trimesh.util.concatenate([closed_corridor(), closet]).export(path)
    return from_file(path, voxel_size_m=V)


def legged(world, point):
    return land(world, point, aerial=False, body_height_m=LEGGED.body_height_m, radius_m=LEGGED.radius_m)


def aerial(world, point):
    return land(world, point, aerial=True, body_height_m=AERIAL.body_height_m, radius_m=AERIAL.radius_m)


def test_a_legged_start_above_the_floor_snaps_onto_it(rooms):
    ld = legged(rooms, [5.0, 0.0, 0.5])
    assert ld.problem is None
    np.testing.assert_allclose(ld.start, [5.0, 0.0, 0.0], atol=0.05)
    assert ld.moved_m == pytest.approx(0.5, abs=0.05)
    ld = legged(rooms, [5.0, 0.0, 1.9])                    # within SNAP_DOWN_M
    assert ld.start[2] == pytest.approx(0.0, abs=0.05)


def test_a_legged_start_on_the_floor_stands_as_given(rooms):
    for z in (0.0, 0.1, -0.05):                            # on it, a little above, in the voxel it passes
        ld = legged(rooms, [5.0, 0.0, z])
        assert ld.problem is None and ld.moved_m == 0.0
        np.testing.assert_array_equal(ld.start, [5.0, 0.0, z])


def test_starts_that_cannot_be_used(rooms):
    high = legged(rooms, [5.0, 0.0, 2.9])
    assert high.start is None
    assert high.problem.startswith(f"{SNAP_DOWN_M:g} m or more above the floor")
    assert high.problem.endswith("(nearest free floor: [4.9, -0.1, 0.0], 2.9 m away)")
    rock = legged(rooms, [5.0, 2.1, 1.0])                  # in the wall
    assert rock.problem == "inside rock (nearest free floor: [4.9, 1.9, 0.0], 1.0 m away)"
    outside = legged(rooms, [50.0, 0.0, 1.0])
    assert outside.problem.startswith("outside the world") and "nearest free floor" in outside.problem


def test_an_aerial_start_is_checked_for_clearance(rooms):
    ok = aerial(rooms, [5.0, 0.0, 0.5])
    assert ok.problem is None and not ok.warnings
    np.testing.assert_array_equal(ok.start, [5.0, 0.0, 0.5])      # no snapping: it hovers
    tight = aerial(rooms, [5.0, 1.85, 0.0])
    assert tight.problem is None
    assert tight.warnings and "within its radius and a voxel (0.6 m)" in tight.warnings[0]
    near = aerial(rooms, [5.0, 1.5, 0.0])        # about 0.5 m from the wall: beyond its radius, not a voxel more
    assert near.problem is None and near.warnings and near.warnings[0].startswith("hovers 0.52 m from rock")
    under = aerial(rooms, [5.0, 0.0, 2.5])
    assert under.problem.startswith("under rock: an aerial robot hovers 1 m above its start")


def test_a_start_in_a_small_region_warns(rooms):
    assert not legged(rooms, [5.0, 0.0, 0.0]).warnings
    ld = legged(rooms, [1.0, 10.0, 0.0])
    assert ld.region_m3 == pytest.approx(8.0, rel=0.05)
    assert ld.warnings == ["starts in a free region of 8 m³, 7% of the largest (120 m³): robots explore "
                           "only the region they start in"]


def test_the_survey_of_two_rooms(rooms):
    figures = survey(rooms)
    assert figures.free_volume_m3 == pytest.approx(128.0, rel=0.02)
    assert figures.regions_m3 == pytest.approx([120.0, 8.0], rel=0.02)
    assert figures.largest_share == pytest.approx(120 / 128, rel=0.01)
    [several] = world_warnings(rooms, figures)
    assert several.key is None
    assert several.message.startswith("2 disconnected free regions (120, 8 m³; the largest 94% of the free "
                                      "volume)")


def test_a_tiny_free_share_warns(tmp_path):
    # a 1 m cube of air, and a speck 100 m away and 20 m up: a model 100 m wide
    speck = trimesh.creation.box((0.2, 0.2, 0.2))
    speck.apply_translation((100.0, 100.0, 20.0))
    mesh = trimesh.util.concatenate([closed_corridor(1.0, 1.0, 1.0), speck])
    path = tmp_path / "speck.stl"
    mesh.export(path)
    w = from_file(path, voxel_size_m=V)
    messages = [x.message for x in world_warnings(w, survey(w))]
    assert any(m.startswith("free volume 1.0 m³ is 0.000") and "of the 101 × 101 × 21 m bounding box" in m
               for m in messages), messages
