"""delve.planners.cohort.global_graph: G_C's subgraphs, collision-free edges, links."""
import networkx as nx
import numpy as np
from delve.planners.cohort import CommonMap, GlobalGraph, segments_free, submap_rng, thin_trajectory
from delve.planners.frontier import FrontierCluster
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import FREE, OCCUPIED
from scipy.sparse.csgraph import dijkstra

from .worlds import Z, T, base_map, cut, fork, parallel


def build(truth, lo, hi, trajectory, robot="a", index=0, n_vertices=200):
    """A base map and common map holding the submap [lo, hi) of ``truth``, and G_C of it."""
    m, fine = base_map(truth)
    common = CommonMap(truth.shape, truth.origin, truth.voxel_size_m, 0.4)
    flat, values = cut(truth, lo, hi)
    m.merge(flat, values)
    common.merge(flat, fine.occupancy.reshape(-1)[flat])
    blocks, pooled = common.pool(flat, values)
    graph = GlobalGraph()
    ids = graph.add_submap((robot, index), fine, common, blocks[pooled == FREE], trajectory, n_vertices, 4.0,
                           submap_rng(robot, index))
    return graph, ids, fine, common


def cluster_at(common, point):
    """A one-point frontier cluster at ``point``."""
    block = np.ravel_multi_index(tuple(common.grid.to_index(np.array([point])).T), common.shape)
    return FrontierCluster(voxels=block, centroid=np.array(point, float))


def test_edges_never_cross_rock():
    truth = parallel()
    solid = syn.carve((30, 16, 6), 0.2, [T((2, 5, 1), (28, 5, 1)), T((2, 11, 1), (28, 11, 1))], shell_only=False)
    graph, ids, _, _ = build(truth, 0, 30, np.array([[3, 5, Z], [25, 5, Z]]))
    assert len(ids) == len(graph) > 200 and graph.num_edges > 500
    a, b = graph.positions[graph.edge_u], graph.positions[graph.edge_v]
    t = np.linspace(0, 1, 200)[None, :, None]
    pts = (a[:, None] + (b - a)[:, None] * t).reshape(-1, 3)
    assert np.all(solid.value_at(pts) != OCCUPIED)
    assert np.all((a[:, 1] < 8) == (b[:, 1] < 8))                          # never through the wall
    assert np.any(a[:, 1] > 8)                                               # the other tunnel has its edges
    on_traj = graph.vertex_on_trajectory
    assert np.all((graph.edge_w <= 4.0 + 1e-9) | (on_traj[graph.edge_u] & on_traj[graph.edge_v]))


def test_a_segment_through_unseen_space_or_rock_is_not_free():
    truth = fork()
    _, _, fine, common = build(truth, 0, 20, np.zeros((0, 3)))
    a = np.array([[5, 20, Z], [5, 20, Z], [18, 20, Z]])
    b = np.array([[9, 20, Z], [5, 24, Z], [22, 20, Z]])                    # along / into the wall / past the map
    assert list(segments_free(fine, common, a, b)) == [True, False, False]


def test_the_trajectory_is_a_chain_of_vertices():
    traj = np.column_stack([np.linspace(3, 18, 61), np.full(61, 20.0), np.full(61, Z)])
    kept = thin_trajectory(traj, 2.0)
    assert np.array_equal(kept[[0, -1]], traj[[0, -1]])
    assert np.all(np.diff(kept[:, 0]) <= 2.0 + 1e-9) and len(kept) == 9
    graph, ids, _, _ = build(fork(), 0, 20, traj, n_vertices=0)
    assert len(graph) == len(kept)
    dist = dijkstra(graph.adjacency(), indices=0)
    assert np.isclose(dist[len(kept) - 1], 15.0)


def test_the_same_submap_gives_the_same_graph_and_another_robot_other_samples():
    traj = np.array([[3, 20, Z], [18, 20, Z]])
    g1, _, _, _ = build(fork(), 0, 20, traj)
    g2, _, _, _ = build(fork(), 0, 20, traj)
    g3, _, _, _ = build(fork(), 0, 20, traj, robot="b")
    assert np.array_equal(g1.positions, g2.positions) and np.array_equal(g1.edge_u, g2.edge_u)
    assert np.array_equal(g1.edge_v, g2.edge_v) and np.array_equal(g1.edge_w, g2.edge_w)
    assert not np.array_equal(g1.positions, g3.positions)


def test_frontier_clusters_link_to_the_vertices_near_their_centroids_and_networkx_agrees():
    graph, _, _, common = build(fork(), 0, 20, np.array([[3, 20, Z], [18, 20, Z]]))
    near, far = cluster_at(common, [20.2, 20, 2.6]), cluster_at(common, [45.0, 5, 2])
    links = graph.link_frontiers([near, far], common, 4.0)
    assert len(links[0]) and np.all(np.linalg.norm(graph.positions[links[0]] - near.centroid, axis=1) <= 4.0)
    assert len(links[1]) == 0
    g = graph.to_networkx()
    assert g.number_of_nodes() == len(graph) and g.number_of_edges() == graph.num_edges
    v = int(links[0][0])
    assert np.isclose(nx.dijkstra_path_length(g, 0, v), dijkstra(graph.adjacency(), indices=0)[v])
