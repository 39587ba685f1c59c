"""delve.planners.cops.extraction: the COPS topology of a voxel map, on synthetic grids
and on a generated mine."""
from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from delve.planners.cops import extraction
from delve.planners.cops.extraction import cell_name, extract_topology, lattice_cells, line_of_sight
from delve.planners.cops.topology import Topology
from delve.planners.occupancy import FREE, OCCUPIED, UNKNOWN, Grid

V = 0.5            # voxel size (m)
CELL = 8.0         # lattice cell (m)
FLOOR, ROOF = 1, 7  # corridor floors and roofs (voxel layers): 0.5 m to 3.5 m


def rock(x_m: float, y_m: float, z_m: float = 5.0) -> np.ndarray:
    return np.full((round(x_m / V), round(y_m / V), round(z_m / V)), OCCUPIED, dtype=np.int8)


def carve(occ: np.ndarray, x: tuple[float, float], y: tuple[float, float]) -> None:
    """Make the box x0..x1, y0..y1 (m), between FLOOR and ROOF, free."""
    occ[round(x[0] / V):round(x[1] / V), round(y[0] / V):round(y[1] / V), FLOOR:ROOF] = FREE


def corridor() -> np.ndarray:
    """A straight corridor 4 m wide along x from 0.5 m to 40 m: five cells in a row."""
    occ = rock(42, 8)
    carve(occ, (0.5, 40), (2, 6))
    return occ


def floor_of(occ: np.ndarray) -> np.ndarray:
    """Free voxels with rock right below them: where a legged robot stands."""
    st = np.zeros(occ.shape, dtype=bool)
    st[:, :, 1:] = (occ[:, :, 1:] == FREE) & (occ[:, :, :-1] == OCCUPIED)
    return st


def mobility_graph(topo: Topology) -> nx.Graph:
    g = nx.Graph()
    g.add_nodes_from(topo.locations)
    g.add_edges_from(topo.mobility)
    return g


@pytest.mark.parametrize("standable", ["all", "floor"])
def test_straight_corridor_is_an_explored_chain(standable):
    occ = corridor()
    topo = extract_topology(occ, np.zeros(3), V, standable=None if standable == "all" else floor_of(occ))
    names = [f"c{i}_0_0" for i in range(5)]
    assert sorted(topo.locations) == names
    assert topo.explored == set(names)
    assert set(topo.mobility) == {(names[i], names[i + 1]) for i in range(4)}
    assert topo.mobility[("c1_0_0", "c2_0_0")] == pytest.approx(CELL)
    assert ("c0_0_0", "c4_0_0") in topo.communication   # 32 m of straight corridor
    assert topo.frontiers() == set()
    for name, pos in topo.locations.items():
        assert lattice_cells(np.array([pos]), CELL)[0].tolist() == [int(name[1]), 0, 0]


def test_fork_has_three_neighbours():
    occ = rock(42, 32)
    carve(occ, (0.5, 40), (2, 6))
    carve(occ, (18, 22), (6, 31.5))          # a branch north from the middle cell
    topo = extract_topology(occ, np.zeros(3), V)
    g = mobility_graph(topo)
    assert sorted(g.neighbors("c2_0_0")) == ["c1_0_0", "c2_1_0", "c3_0_0"]
    assert nx.is_tree(g) and len(g) == 8


def test_partly_mapped_corridor_has_its_frontier_at_the_mapped_edge():
    occ = corridor()
    occ[round(26 / V):] = UNKNOWN             # not mapped beyond x = 26 m
    topo = extract_topology(occ, np.zeros(3), V)
    assert sorted(topo.locations) == ["c0_0_0", "c1_0_0", "c2_0_0", "c3_0_0"]
    assert topo.explored == {"c0_0_0", "c1_0_0", "c2_0_0"}
    assert topo.frontiers() == {"c2_0_0"}
    assert topo.unexplored_exits("c2_0_0") == ["c3_0_0"]


def test_visited_cells_count_as_explored():
    occ = corridor()
    occ[:, :, ROOF - 1:] = UNKNOWN             # a roof nobody has seen
    assert extract_topology(occ, np.zeros(3), V).explored == set()
    topo = extract_topology(occ, np.zeros(3), V, visited=np.array([[3.0, 4.0, 0.6], [11.0, 4.0, 0.6]]))
    assert topo.explored == {"c0_0_0", "c1_0_0"} and topo.frontiers() == {"c1_0_0"}


def test_a_corner_blocks_the_line_of_sight():
    occ = rock(26, 42)
    carve(occ, (0.5, 22), (2, 6))
    carve(occ, (18, 22), (6, 40))             # an L: east, then north
    topo = extract_topology(occ, np.zeros(3), V)
    assert ("c2_0_0", "c2_3_0") in topo.communication        # along the north leg
    assert ("c0_0_0", "c2_3_0") not in topo.communication    # round the corner
    assert ("c0_0_0", "c2_3_0") not in topo.mobility
    grid = Grid(occ, np.zeros(3), V)
    a, b = np.array(topo.locations["c0_0_0"]), np.array(topo.locations["c2_3_0"])
    assert not line_of_sight(grid, a, b)[0] and line_of_sight(grid, a, a + [4.0, 0, 0])[0]


def test_communication_needs_range():
    topo = extract_topology(corridor(), np.zeros(3), V, comm_range_m=10.0)
    assert ("c0_0_0", "c1_0_0") in topo.communication and ("c0_0_0", "c2_0_0") not in topo.communication


def test_names_do_not_depend_on_the_map_origin():
    occ = corridor()
    ref = extract_topology(occ, np.zeros(3), V).to_dict()
    pad = 7                                   # the same world in a larger map with another origin
    bigger = np.pad(occ, ((pad, 3), (pad, 0), (pad, 1)), constant_values=UNKNOWN)
    assert extract_topology(bigger, -pad * V * np.ones(3), V).to_dict() == ref
    shifted = extract_topology(occ, np.array([0.2, -0.1, 0.05]), V)   # voxels not aligned
    assert sorted(shifted.locations) == sorted(ref["locations"])


def test_negative_lattice_indices():
    topo = extract_topology(corridor(), np.array([-20.0, -9.0, 0.0]), V)
    assert sorted(topo.locations) == sorted(f"c{i}_-1_0" for i in range(-3, 3))
    assert cell_name((-1, 3, 0)) == "c-1_3_0"


def test_small_pieces_are_no_locations_but_still_join_their_neighbours():
    occ = rock(24, 8)
    carve(occ, (0.5, 8), (2, 6))
    carve(occ, (16, 23.5), (2, 6))
    occ[16:32, 8, 2] = FREE                   # a 1-voxel crawlway through the middle cell
    topo = extract_topology(occ, np.zeros(3), V, min_free_voxels=20)
    assert sorted(topo.locations) == ["c0_0_0", "c2_0_0"]
    assert set(topo.mobility) == {("c0_0_0", "c2_0_0")}


def test_unconnected_parallel_rooms_in_neighbouring_cells_are_not_joined():
    occ = rock(24, 8)
    carve(occ, (0.5, 7.5), (2, 6))
    carve(occ, (8.5, 15.5), (2, 6))           # a 1 m wall between the two cells
    topo = extract_topology(occ, np.zeros(3), V)
    assert sorted(topo.locations) == ["c0_0_0", "c1_0_0"] and not topo.mobility
    assert not topo.communication


def test_empty_map_has_no_locations():
    occ = np.full((10, 10, 10), UNKNOWN, dtype=np.int8)
    assert extract_topology(occ, np.zeros(3), V).size() == (0,) * 6


@pytest.mark.parametrize("kwargs, message", [
    ({"cell_m": 0.0}, "cell_m"), ({"cell_m": -8.0}, "cell_m"), ({"cell_m": float("nan")}, "cell_m"),
    ({"voxel_size_m": 0.0}, "voxel_size_m"), ({"comm_range_m": -1.0}, "comm_range_m"),
    ({"min_free_voxels": 0}, "min_free_voxels"), ({"min_free_voxels": 2.5}, "min_free_voxels"),
    ({"sight_height_m": -0.5}, "sight_height_m"), ({"origin": [0.0, 0.0]}, "origin"),
    ({"occupancy": np.zeros((4, 4), np.int8)}, "occupancy"),
    ({"occupancy": np.zeros((4, 4, 4))}, "occupancy"),
    ({"standable": np.ones((4, 4, 4), bool)}, "standable"),
    ({"standable": np.ones((84, 16, 10), np.int8)}, "standable"),
    ({"visited": np.zeros((2, 2))}, "visited"), ({"visited": [[0.0, 0.0, float("inf")]]}, "visited"),
])
def test_bad_inputs_raise_value_error(kwargs, message):
    args = {"occupancy": corridor(), "origin": np.zeros(3), "voxel_size_m": V} | kwargs
    occ, origin, vox = args.pop("occupancy"), args.pop("origin"), args.pop("voxel_size_m")
    with pytest.raises(ValueError, match=message):
        extract_topology(occ, origin, vox, **args)


@pytest.fixture(scope="module")
def mine():
    from delve.sim import worldgen
    return worldgen.tunnel_network(1, total_length_m=200.0, voxel_size_m=V)


@pytest.mark.parametrize("standable", ["all", "floor"])
def test_generated_mine_gives_a_connected_network_with_forks(mine, standable):
    occ = np.where(mine.free, FREE, OCCUPIED).astype(np.int8)
    topo = extract_topology(occ, mine.origin, mine.voxel_size_m,
                            standable=None if standable == "all" else floor_of(occ))
    g = mobility_graph(topo)
    assert len(g) > 10 and nx.is_connected(g)
    assert topo.explored == set(topo.locations)
    assert max(d for _, d in g.degree()) >= 3
    junctions = [n for n, d in mine.centreline.degree() if d >= 3]
    assert junctions
    for n in junctions:                        # the cell of a junction of tunnels is a fork
        cell = lattice_cells(np.array([mine.centreline.nodes[n]["pos"]]) + [0, 0, 1.0], CELL)[0]
        assert g.degree(cell_name(cell)) >= 3
    net = topo.network(min(topo.explored), spacing_m=CELL)
    assert len(net) == len(g) and not net.frontiers


def test_the_lattice_origin_moves_the_cells():
    """Cells from x = -4 m, 4 m, 12 m, ...: the corridor from 0.5 m to 40 m spans c0..c5."""
    occ = corridor()
    topo = extract_topology(occ, np.zeros(3), V, lattice_origin=np.array([-4.0, 0.0, 0.0]))
    assert sorted(topo.locations) == [f"c{i}_0_0" for i in range(6)]
    assert topo.locations["c1_0_0"][0] == pytest.approx(7.75)   # the voxel centre nearest x = 8 m
    assert lattice_cells(np.array([[3.9, 3.0, 1.0]]), CELL, np.array([-4.0, 0.0, 0.0]))[0].tolist() == [0, 0, 0]
    with pytest.raises(ValueError, match="lattice_origin"):
        extract_topology(occ, np.zeros(3), V, lattice_origin=np.array([0.0, np.nan, 0.0]))


def test_free_space_joins_floor_seen_in_rings():
    """A LiDAR sees the floor in rings: standable strips with unseen floor between them.
    Through the free space above (``passable``) the cells are still joined."""
    occ = corridor()
    rings = floor_of(occ)
    for x0 in range(6, 80, 8):          # every 4 m, a 2 m gap in the seen floor
        rings[x0:x0 + 4] = False
    alone = extract_topology(occ, np.zeros(3), V, standable=rings)
    assert len(alone.mobility) < 4
    joined = extract_topology(occ, np.zeros(3), V, standable=rings, passable=occ == FREE)
    names = [f"c{i}_0_0" for i in range(5)]
    assert set(joined.mobility) == {(names[i], names[i + 1]) for i in range(4)}
    for pos in joined.locations.values():     # positions stay on the seen floor
        i, j, k = (np.asarray(pos) / V).astype(int)
        assert rings[i, j, k]


def test_touching_components_are_found_across_cell_boundaries_as_by_comparing_every_neighbour():
    rng = np.random.default_rng(7)
    mask = rng.random((23, 17, 9)) < 0.5
    partition = [np.arange(n) // 4 for n in mask.shape]  # cells of 4 voxels a side
    labels = extraction._components_within_cells(mask, partition)
    found = {tuple(p) for p in extraction._touching_components(labels, partition).tolist()}
    every = set()
    for d in extraction._HALF_NEIGHBOURS_26:
        src = tuple(slice(max(0, -o), n - max(0, o)) for o, n in zip(d, labels.shape))
        dst = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(d, labels.shape))
        a, b = labels[src], labels[dst]
        hit = (a != b) & (a > 0) & (b > 0)
        every |= {(min(x, y) - 1, max(x, y) - 1) for x, y in zip(a[hit].tolist(), b[hit].tolist())}
    assert found == every and len(every) > 50
