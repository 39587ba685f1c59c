"""Frontier segmentation by region growing (Section III-A4, Algorithm 1), and the Gaussian of a
frontier that the sequential update and the sharing use.

Frontier triangles that share a vertex grow into one frontier from an anchor, taking no triangle
whose centroid is farther than eta_dia from the anchor's; frontiers of area eta_area or less are
dropped. The same growth over a kd-tree neighbourhood clusters triangles of several frontiers
(:mod:`.sequential`).
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components

from .frontier_types import Frontier, FrontierMesh
from .params import CsiroFrontierParams
from .visibility_mesh import triangle_geometry


def grow_regions(adjacency: csr_matrix, centroids: np.ndarray, eta_dia_m: float) -> list[np.ndarray]:
    """Algorithm 1's region growing over items (triangles) 0..n-1: the lowest unassigned item is
    the anchor; from it the region takes, over ``adjacency``, every unassigned item reachable
    through items whose centroids lie within ``eta_dia_m`` of the anchor's. Returns the regions as
    sorted index arrays, in order of their anchors (deterministic).

    As the test on an item does not depend on the path to it, a region is the anchor's connected
    component among the unassigned items near the anchor (scipy's breadth-first order, rather than
    a Python loop over the open list); a connected component that lies wholly within eta_dia of its
    lowest item is one region."""
    n = len(centroids)
    n_comp, comp = connected_components(adjacency, directed=False)
    free = np.ones(n, dtype=bool)
    regions = []
    order = np.argsort(comp, kind="stable")
    bounds = np.searchsorted(comp[order], np.arange(n_comp + 1))
    for c in range(n_comp):
        members = order[bounds[c]:bounds[c + 1]]             # ascending, as the sort is stable
        local = None                                          # the component's own adjacency
        while len(members):
            anchor = members[0]
            near = members[np.linalg.norm(centroids[members] - centroids[anchor], axis=1) <= eta_dia_m]
            if len(near) == len(members):
                region = members
            else:
                if local is None:
                    component = members
                    local = adjacency[component][:, component]
                pick = np.searchsorted(component, near)
                bfs = breadth_first_order(local[pick][:, pick], 0, directed=False, return_predecessors=False)
                region = near[np.sort(bfs)]
            free[region] = False
            regions.append(region)
            members = members[free[members]]
    regions.sort(key=lambda r: int(r[0]))
    return regions


def shared_vertex_adjacency(triangles: np.ndarray) -> csr_matrix:
    """(T, T) adjacency of triangles that share at least one vertex (|X intersect R| >= 1)."""
    t = len(triangles)
    rows = np.repeat(np.arange(t), 3)
    incidence = coo_matrix((np.ones(3 * t), (rows, triangles.reshape(-1))),
                           shape=(t, int(triangles.max()) + 1 if t else 0)).tocsr()
    return (incidence @ incidence.T).tocsr()


def make_frontier(frontier_id: int, points: np.ndarray, normals: np.ndarray, areas: np.ndarray) -> Frontier:
    """A Frontier of triangles (centroids ``points``, unit ``normals``, ``areas``) with the
    area-weighted mean and covariance of the centroids (equal weights if all areas are zero)."""
    w = areas if areas.sum() > 0 else np.ones(len(areas))
    mean = np.average(points, axis=0, weights=w)
    d = points - mean
    cov = (w[:, None, None] * d[:, :, None] * d[:, None, :]).sum(axis=0) / w.sum()
    return Frontier(id=int(frontier_id), points=points, normals=normals, areas=areas, mean=mean, cov=cov)


def segment_frontiers(mesh: FrontierMesh, params: CsiroFrontierParams, first_id: int = 0) -> list[Frontier]:
    """Algorithm 1: the frontier triangles of ``mesh`` grown into frontiers (shared-vertex
    neighbours, eta_dia from the anchor), those of area above eta_area kept, numbered from
    ``first_id`` in order of their anchors."""
    idx = np.flatnonzero(mesh.frontier)
    if len(idx) == 0:
        return []
    centroids, normals, areas = (a[idx] for a in triangle_geometry(mesh))
    regions = grow_regions(shared_vertex_adjacency(mesh.triangles[idx]), centroids, params.eta_dia_m)
    kept = [r for r in regions if areas[r].sum() > params.eta_area_m2]
    return [make_frontier(first_id + k, centroids[r], normals[r], areas[r]) for k, r in enumerate(kept)]


__all__ = ["grow_regions", "make_frontier", "segment_frontiers", "shared_vertex_adjacency"]
