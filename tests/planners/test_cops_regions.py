"""delve.planners.cops.regions: lattice cells merged into the locations of open areas,
on synthetic grids (with the extraction that uses them) and on their own."""
from __future__ import annotations

import numpy as np
import pytest
from delve.planners.cops.extraction import extract_topology
from delve.planners.cops.regions import (cell_of_name, group_cells, open_space, region_name,
                                         region_order)
from delve.planners.cops.topology import Topology
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN

V = 0.5            # voxel size (m)
CELL = 8.0
FLOOR, ROOF = 1, 7  # free layers: 0.5 m to 3.5 m


def rock(x_m: float, y_m: float, z_m: float = 5.0) -> np.ndarray:
    return np.full((round(x_m / V), round(y_m / V), round(z_m / V)), OCCUPIED, dtype=np.int8)


def carve(occ: np.ndarray, x: tuple[float, float], y: tuple[float, float]) -> None:
    occ[round(x[0] / V):round(x[1] / V), round(y[0] / V):round(y[1] / V), FLOOR:ROOF] = FREE


def yard(offset_m: float = 0.0) -> np.ndarray:
    """A 30 m x 30 m room entered from -x by a corridor 4 m wide along y = 16..20 m
    (x from 0.5 m); the room spans x from 9 + offset to 39 + offset."""
    occ = rock(48, 36)
    carve(occ, (0.5, 9 + offset_m), (16, 20))
    carve(occ, (9 + offset_m, 39 + offset_m), (3, 33))
    return occ


def corridor() -> np.ndarray:
    occ = rock(42, 8)
    carve(occ, (0.5, 40), (2, 6))
    return occ


def extract(occ: np.ndarray, **kw) -> Topology:
    return extract_topology(occ, np.zeros(3), V, lattice_origin=np.array([0.0, 16.0 - CELL / 2, 0.0]), **kw)


@pytest.mark.parametrize("offset_m", [0.0, 3.0])
def test_a_30_m_room_is_one_location(offset_m):
    topo = extract(yard(offset_m))
    plain = extract(yard(offset_m), open_radius_m=None)
    in_room = [n for n in plain.locations if cell_of_name(n)[0] >= 1]   # the corridor holds cell x 0
    assert len(in_room) >= 16                                  # the lattice cuts it into many
    rooms = {topo.resolve(n) for n in in_room}
    assert len(rooms) == 1                                     # one location
    room = rooms.pop()
    assert room == region_name(in_room) and room in topo.locations
    assert set(topo.members(room)) == set(in_room)
    corridor_cells = {n for n in plain.locations if n not in in_room}
    assert corridor_cells <= topo.locations.keys()              # the corridor's cells stay
    assert topo.neighbours("c0_0_0") == [room]
    assert topo.frontiers() == set()


def test_a_corridor_stays_a_chain():
    topo = extract_topology(corridor(), np.zeros(3), V)
    names = [f"c{i}_0_0" for i in range(5)]
    assert sorted(topo.locations) == names and topo.merged == {}
    assert set(topo.mobility) == {(names[i], names[i + 1]) for i in range(4)}


def test_open_space_is_wider_than_a_tunnel():
    occ = yard()
    free = occ == FREE
    opened = open_space(free, V)
    assert not opened[:round(4.5 / V)].any()                   # the 4 m corridor, off the room's mouth
    middle = free.copy()
    middle[:round(9 / V)] = False
    assert opened[middle].mean() > 0.95                         # the room, but for its corners


def test_names_stay_as_the_map_grows():
    """The room seen from the corridor first (its far half unknown), then all of it:
    every name used before still resolves, and the room keeps its name."""
    full = yard()
    part = full.copy()
    part[round(25 / V):] = np.where(part[round(25 / V):] == FREE, UNKNOWN, part[round(25 / V):])
    first = extract(part)
    second = extract(full, prior=first.merged)
    room = first.resolve("c2_1_0")
    assert room in first.locations
    assert second.resolve(room) == room
    for name in first.locations:
        assert second.resolve(name) in second.locations
    assert first.merged.items() <= second.merged.items()
    assert room in first.frontiers()        # its explored cells, next to the cells not yet explored
    assert second.frontiers() == set()


def test_kept_cells_are_never_merged():
    topo = extract(yard(), keep=("c2_1_0",))
    assert "c2_1_0" in topo.locations and "c2_1_0" not in topo.merged
    assert not any(n == "c2_1_0" for n in topo.merged.values())


def test_a_region_spans_at_most_max_region_m():
    topo = extract(yard(3.0), max_region_m=16.0)
    spans = {}
    for member, name in topo.merged.items():
        spans.setdefault(name, {cell_of_name(name)}).add(cell_of_name(member))
    assert spans
    for cells in spans.values():
        c = np.array(sorted(cells))
        assert np.all(c.max(axis=0) - c.min(axis=0) + 1 <= 2)


def test_group_cells_keeps_prior_merges_and_names_by_order():
    names = ["c3_0_0", "c4_0_0", "c5_0_0"]
    cells = np.array([[3, 0, 0], [4, 0, 0], [5, 0, 0]])
    merged = group_cells(names, cells, np.array([[1, 2]]), cell_m=CELL, prior={"c9_0_0": "c2_0_0"})
    assert merged == {"c5_0_0": "c4_0_0", "c9_0_0": "c2_0_0"}
    assert region_order("c-1_0_0") < region_order("c2_0_0") < region_order("room")


def test_topologies_merge_regions_that_share_a_cell_whatever_the_order():
    a, b = Topology(), Topology()
    for t, merged in ((a, {"c2_0_0": "c1_0_0"}), (b, {"c3_0_0": "c2_0_0"})):
        for i in range(5):
            t.add_location(f"c{i}_0_0", (8.0 * i, 0, 0), explored=i < 3)
        for i in range(4):
            t.add_mobility_edge(f"c{i}_0_0", f"c{i + 1}_0_0")
        t.merged = dict(merged)
    b.unreachable = {"c3_0_0"}
    ab, ba = Topology(), Topology()
    for t, order in ((ab, (a, b)), (ba, (b, a))):
        for other in order:
            t.merge(Topology.from_dict(other.to_dict()))
    assert ab.to_dict() == ba.to_dict()
    assert ab.merged == {"c2_0_0": "c1_0_0", "c3_0_0": "c1_0_0"}
    assert sorted(ab.locations) == ["c0_0_0", "c1_0_0", "c4_0_0"]
    assert set(ab.mobility) == {("c0_0_0", "c1_0_0"), ("c1_0_0", "c4_0_0")}
    assert ab.explored == {"c0_0_0", "c1_0_0"} and ab.frontiers() == {"c1_0_0"}
    assert ab.members("c3_0_0") == ["c1_0_0", "c2_0_0", "c3_0_0"]
    assert ab.unreachable == set()      # a cell one robot could not reach does not make its region unreachable
