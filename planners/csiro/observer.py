"""Observer planning (Williams et al., Section III-C): where to stand to observe a frontier.

Traversable mesh vertices (equations 10-11), sub-sampled to one per neighbourhood and
kept only if reachable from the agent; the reward of observing each frontier triangle
from each candidate (equation 12) and the observer position of a frontier (equation 13).

Departures from the paper: a vertex's normal is the area-weighted mean of the normals of
its observed (non-frontier) triangles, each turned towards the viewpoint, instead of the
eigenvector of the voxel it came from; turning it towards the viewpoint tells a floor
(normal up) from a ceiling (normal down), which the paper's |e_z . xi| accepts alike.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import networkx as nx
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .frontier_types import Frontier, FrontierMesh
from .selection_params import CsiroSelectionParams


@dataclass(frozen=True)
class ObserverCandidates:
    """The set A: candidate observer positions (N, 3) and the graph (nodes 0..N-1, edge
    attribute ``weight`` in m) that joins neighbourhoods whose vertices the mesh joins."""

    positions: np.ndarray
    graph: nx.Graph

    def __len__(self) -> int:
        return len(self.positions)


@dataclass(frozen=True)
class Observer:
    """A frontier's observer: position o_f, reward r_f (equation 13) and the index of the
    candidate."""

    position: np.ndarray
    reward: float
    index: int


def surface_normals(mesh: FrontierMesh) -> np.ndarray:
    """(V, 3) unit vertex normals from the mesh's observed (non-frontier) triangles, each
    triangle's normal turned towards ``mesh.viewpoint`` and weighted by its area; zero
    for a vertex of frontier triangles only."""
    # Hand-written rather than trimesh's vertex_normals: the hull's triangles need not be
    # consistently wound, so each is oriented towards the viewpoint first.
    tri = mesh.triangles[~np.asarray(mesh.frontier, bool)]
    corners = mesh.vertices[tri]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])  # |cross| = 2 area
    towards = np.asarray(mesh.viewpoint, float) - corners.mean(axis=1)
    cross[np.einsum("ij,ij->i", cross, towards) < 0] *= -1.0
    corner_of = tri.reshape(-1)  # each triangle's sum goes to its three corners
    normals = np.column_stack([np.bincount(corner_of, weights=np.repeat(cross[:, k], 3),
                                           minlength=len(mesh.vertices)) for k in range(3)])
    length = np.linalg.norm(normals, axis=1)
    ok = length > 0
    normals[ok] /= length[ok, None]
    return normals


def traversable_vertices(mesh: FrontierMesh, params: CsiroSelectionParams,
                         vertex_normals: np.ndarray | None = None) -> np.ndarray:
    """(V,) bool: the set A'' of equations 10-11, vertices whose normal is within
    ``eta_norm_deg`` of the z axis with no non-traversable vertex of a triangle within
    ``eta_trav_m`` (a vertex of frontier triangles only is not traversable).
    ``vertex_normals`` (default :func:`surface_normals`) must point towards the known side."""
    normals = surface_normals(mesh) if vertex_normals is None else np.asarray(vertex_normals, float)
    used = np.zeros(len(mesh.vertices), bool)
    used[mesh.triangles.reshape(-1)] = True
    flat = used & (normals[:, 2] >= math.cos(math.radians(params.eta_norm_deg)))  # equation 10
    steep = mesh.vertices[used & ~flat]
    if len(steep) == 0:
        return flat
    near = cKDTree(steep).query_ball_point(mesh.vertices[flat], r=params.eta_trav_m, return_length=True)
    out = flat.copy()
    out[np.flatnonzero(flat)[near > 0]] = False  # equation 11
    return out


def _observed_edges(mesh: FrontierMesh, keep: np.ndarray) -> np.ndarray:
    """(E, 2) edges of observed (non-frontier) triangles between vertices in ``keep``
    (an edge of two triangles twice)."""
    tri = mesh.triangles[~np.asarray(mesh.frontier, bool)]
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    return edges[keep[edges[:, 0]] & keep[edges[:, 1]]]


def _subsample(points: np.ndarray, piece: np.ndarray, spacing_m: float) -> np.ndarray:
    """(P,) group of each point: one group per cell of ``spacing_m`` and connected piece,
    numbered in the order of (cell, piece)."""
    cell = np.floor(points / spacing_m).astype(np.int64)
    cell -= cell.min(axis=0)
    key = np.ravel_multi_index((*cell.T, piece), (*(cell.max(axis=0) + 1), int(piece.max()) + 1))
    return np.unique(key, return_inverse=True)[1].reshape(-1)


def _nearest_to_mean(points: np.ndarray, group: np.ndarray) -> np.ndarray:
    """Index of the point of each group nearest to the group's mean (the first of equals)."""
    mean = np.column_stack([np.bincount(group, weights=points[:, k]) for k in range(3)])
    mean /= np.bincount(group)[:, None]
    order = np.lexsort((np.linalg.norm(points - mean[group], axis=1), group))
    return order[np.r_[True, np.diff(group[order]) != 0]]


def observer_candidates(mesh: FrontierMesh, agent_position: np.ndarray, params: CsiroSelectionParams,
                        vertex_normals: np.ndarray | None = None) -> ObserverCandidates:
    """The set A: traversable vertices of ``mesh`` (:func:`traversable_vertices`), one per
    neighbourhood of ``observer_spacing_m`` and connected piece of the mesh (the vertex
    nearest the neighbourhood's mean), kept when the mesh joins them to the candidate
    nearest ``agent_position``; two candidates are joined where any of their vertices are."""
    keep = traversable_vertices(mesh, params, vertex_normals)
    idx = np.flatnonzero(keep)
    if len(idx) == 0:
        return ObserverCandidates(np.zeros((0, 3)), nx.Graph())
    local = np.full(len(mesh.vertices), -1)
    local[idx] = np.arange(len(idx))
    edges = local[_observed_edges(mesh, keep)]
    points = mesh.vertices[idx]
    adjacency = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(len(idx), len(idx)))
    piece = connected_components(adjacency, directed=False)[1]
    group = _subsample(points, piece, params.observer_spacing_m)
    first = _nearest_to_mean(points, group)
    source = int(np.argmin(np.linalg.norm(points[first] - np.asarray(agent_position, float), axis=1)))
    reached = piece[first] == piece[first[source]]  # a piece's groups are joined through its edges
    edges = edges[reached[group[edges[:, 0]]]]
    pairs = (np.cumsum(reached) - 1)[group[edges]]  # candidates renumbered among the reached
    return ObserverCandidates(points[first[reached]], _candidate_graph(points[first[reached]], pairs))


def _candidate_graph(positions: np.ndarray, pairs: np.ndarray) -> nx.Graph:
    """Nodes 0..N-1 joined by each pair (k, 2) of different nodes, weighted by distance (m)."""
    pairs = np.sort(pairs[pairs[:, 0] != pairs[:, 1]], axis=1)
    a, b = np.divmod(np.unique(pairs[:, 0] * len(positions) + pairs[:, 1]), len(positions))
    graph = nx.Graph()
    graph.add_nodes_from(range(len(positions)))
    graph.add_weighted_edges_from(zip(a.tolist(), b.tolist(),
                                      np.linalg.norm(positions[a] - positions[b], axis=1).tolist()))
    return graph


#: A sensor that sees every elevation (the paper's spinning, tilted LiDAR, nearly).
ALL_ELEVATIONS_DEG = (-90.0, 90.0)


def within_elevations(directions: np.ndarray, elevations_deg: tuple[float, float]) -> np.ndarray:
    """Bool mask over ``directions`` (..., 3): whether each lies within the sensor's
    ``elevations_deg`` (min, max) above the horizontal."""
    d = np.asarray(directions, float)
    elevation = np.degrees(np.arctan2(d[..., 2], np.linalg.norm(d[..., :2], axis=-1)))
    return (elevation >= elevations_deg[0]) & (elevation <= elevations_deg[1])


def observation_rewards(candidates: np.ndarray, frontier: Frontier, d_max_m: float,
                        params: CsiroSelectionParams, *, sensor_height_m: float = 0.0,
                        elevations_deg: tuple[float, float] = ALL_ELEVATIONS_DEG) -> np.ndarray:
    """(N, K) reward r(a, R) of observing each of the frontier's K triangles from each of N
    candidate positions (equation 12; with ``reduced_dynamic_range``, d_max^3 / r^2 is
    replaced by d_max^2 / r). The view is from the sensor, ``sensor_height_m`` above the
    candidate (a floor point). The angle is between the triangle's normal (out of the
    known space) and the view from the sensor through the triangle; triangles beyond
    d_max, seen from behind or outside the sensor's ``elevations_deg`` (min, max) give 0:
    the paper's "if viewed from agent position a" is a view with the sensor's field."""
    sensors = np.asarray(candidates, float) + np.array([0.0, 0.0, sensor_height_m])
    view = frontier.points[None, :, :] - sensors[:, None, :]
    distance = np.linalg.norm(view, axis=2)
    cos_plus = np.maximum(np.einsum("nkj,kj->nk", view, frontier.normals) / np.maximum(distance, 1e-12), 0.0)
    cos_plus[~within_elevations(view, elevations_deg)] = 0.0
    r = np.maximum(distance, params.reward_min_range_m)
    reach = d_max_m ** 2 / r if params.reduced_dynamic_range else d_max_m ** 3 / r ** 2
    return frontier.areas[None, :] * cos_plus / 3.0 * np.maximum(reach - r, 0.0)


def plan_observer(candidates: ObserverCandidates, frontier: Frontier, d_max_m: float,
                  params: CsiroSelectionParams, *, sensor_height_m: float = 0.0,
                  elevations_deg: tuple[float, float] = ALL_ELEVATIONS_DEG) -> Observer | None:
    """The candidate that observes the most of ``frontier`` and its total reward
    (equation 13, with the sensor of :func:`observation_rewards`; the first of equals), or
    None when there is no candidate. A reward of 0 means that no candidate sees any of the
    frontier's triangles: no useful frontier for this robot."""
    if len(candidates) == 0:
        return None
    total = observation_rewards(candidates.positions, frontier, d_max_m, params,
                                sensor_height_m=sensor_height_m, elevations_deg=elevations_deg).sum(axis=1)
    best = int(np.argmax(total))
    return Observer(position=candidates.positions[best].copy(), reward=float(total[best]), index=best)


__all__ = ["ALL_ELEVATIONS_DEG", "Observer", "ObserverCandidates", "observation_rewards",
           "observer_candidates", "plan_observer", "surface_normals", "traversable_vertices"]
