"""The visible mesh from one viewpoint by direct point-cloud visibility (Section III-A2, A3).

The observed points plus the sphere points S(a, d_max) (equation 2) are transformed by the
exponential inversion (equation 3); the convex hull of the transformed points and the viewpoint
(qhull, equation 5) gives the visible points and, through the same indices, a watertight mesh of
what the agent sees. Visible sphere points are frontier points (equation 6); edges longer than
eta_disc are split at their middle, which becomes a discontinuity frontier point (equations 7-8),
unless that middle lies within a voxel's diagonal of an observed point (see :func:`split_long_edges`).

Where delve departs from the paper: the sphere points are limited to the sensor's elevations, as the
paper says, but a sensor that sees a narrow band (a legged robot's +-15 deg) leaves the hull open
over the blind cones above and below, and every point at the rim of that opening lies on the hull:
sphere points behind the walls and the middles of long edges from them to the walls' tops became
frontiers outside the drift, never to be seen again. Sphere points in the blind cones
(:func:`blind_sphere_points`) close the hull; they are no frontier points, and the triangles that
touch one are dropped from the mesh (the sensor sees nothing there), unless ``blind_frontiers``
(a flying robot) makes the visible ones frontier points like the others.
scipy's ConvexHull is used rather than open3d's hidden_point_removal, which hard-codes the
spherical-flipping kernel, not the paper's exponential one.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.spatial import ConvexHull, QhullError, cKDTree

from .frontier_types import FrontierMesh
from .params import CsiroFrontierParams

#: A hull in three dimensions needs four points that span a volume.
MIN_POINTS = 4
#: The middle of a long edge lies on seen surface when an observed point is within a voxel's
#: diagonal (sqrt 3 d_vox, the farthest apart two points of one voxel can be) of it.
SURFACE_VOXELS = np.sqrt(3.0)


def _sphere_rows(agent: np.ndarray, params: CsiroFrontierParams, lo_deg: float, hi_deg: float) -> np.ndarray:
    """Points on the sphere of radius d_max around ``agent`` between elevations ``lo_deg`` and
    ``hi_deg`` (both rows included), about eta_disc / 2 apart; rows by elevation then azimuth."""
    return np.asarray(agent, float) + params.d_max_m * _unit_rows(params.sphere_spacing_rad, lo_deg, hi_deg)


@lru_cache(maxsize=8)
def _unit_rows(step: float, lo_deg: float, hi_deg: float) -> np.ndarray:
    """The unit directions of :func:`_sphere_rows`, made once per spacing and band (every
    frontier update asks for the same ones)."""
    lo, hi = np.radians(lo_deg), np.radians(hi_deg)
    rows = max(int(np.ceil((hi - lo) / step)), 1)
    out = []
    for el in np.linspace(lo, hi, rows + 1):
        n = max(int(np.ceil(2 * np.pi * np.cos(el) / step)), 1)
        az = np.arange(n) * (2 * np.pi / n)
        out.append(np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.full(n, np.sin(el))], axis=1))
    units = np.concatenate(out)
    units.setflags(write=False)
    return units


def sphere_points(agent: np.ndarray, params: CsiroFrontierParams) -> np.ndarray:
    """S(a, d_max): points on the sphere of radius d_max around ``agent``, about eta_disc / 2
    apart, at the elevations the sensor sees (elevation_min_deg..elevation_max_deg).
    Returns (M, 3), rows by elevation then azimuth."""
    return _sphere_rows(agent, params, params.elevation_min_deg, params.elevation_max_deg)


def blind_sphere_points(agent: np.ndarray, params: CsiroFrontierParams) -> np.ndarray:
    """Points on the same sphere in the cones the sensor does not see (above elevation_max_deg,
    below elevation_min_deg; none for a sensor that sees every elevation), as far apart as
    those of :func:`sphere_points`, the rows nearest the sensor's view one step outside it.
    They close the hull over the blind cones (see :func:`visible_mesh`). Returns (M, 3)."""
    step = np.degrees(params.sphere_spacing_rad)
    parts = [np.zeros((0, 3))]
    if params.elevation_max_deg + step < 90.0:
        parts.append(_sphere_rows(agent, params, params.elevation_max_deg + step, 90.0))
    if params.elevation_min_deg - step > -90.0:
        parts.append(_sphere_rows(agent, params, -90.0, params.elevation_min_deg - step))
    return np.concatenate(parts)


def exponential_inversion(points: np.ndarray, agent: np.ndarray, gamma: float) -> np.ndarray:
    """Equation 3: t(p - a) = (p - a) / ||p - a|| * ||p - a||^gamma. Points at the agent itself
    must have been removed."""
    d = np.asarray(points, float) - np.asarray(agent, float)
    r = np.linalg.norm(d, axis=1)
    return d * (r ** (gamma - 1.0))[:, None]


class CloudDirections:
    """The observed points as seen from the agent: their ranges and a kd-tree of their unit
    directions, made once for every :func:`behind_observed` test of one view."""

    def __init__(self, cloud: np.ndarray, agent: np.ndarray) -> None:
        d = cloud - agent
        self.range_m = np.linalg.norm(d, axis=1)
        self.tree = cKDTree(d / self.range_m[:, None])


def behind_observed(sphere: np.ndarray, seen: CloudDirections, agent: np.ndarray, width_m: float) -> np.ndarray:
    """(M,) bool: sphere points straight behind an observed point (``seen``: the observed
    points' directions from ``agent``), within the angle that half of ``width_m`` subtends at
    the range of the cloud point nearest in direction. With the width of a voxel they are
    hidden (give or take half a voxel at the rim of an opening), so leaving them out of the
    hull changes little but its cost: in a drift most of the sphere is behind the walls, and
    qhull takes about a third less time without it. With eta_disc, gaps narrower than a
    discontinuity in the observed surface count as closed."""
    r = seen.range_m
    u = (sphere - agent) / np.linalg.norm(sphere - agent, axis=1)[:, None]
    gap, near = seen.tree.query(u, distance_upper_bound=0.5 * width_m / r.min())
    hit = np.isfinite(gap)
    out = np.zeros(len(sphere), dtype=bool)
    out[hit] = gap[hit] <= 0.5 * width_m / r[near[hit]]
    return out


def split_long_edges(vertices: np.ndarray, triangles: np.ndarray, frontier_vertex: np.ndarray,
                     eta_disc_m: float, surface: cKDTree | None = None,
                     surface_m: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Disc (equations 7-8): every edge longer than ``eta_disc_m`` gets a new vertex at its middle,
    a frontier point shared by the two triangles on the edge; a triangle with one, two or three
    long edges becomes two, three or four triangles of the same orientation. Returns the new
    (vertices, triangles, frontier_vertex).

    With a ``surface`` (kd-tree of the observed points), a long edge whose middle lies within
    ``surface_m`` of an observed point is no depth discontinuity and is left whole. This departs
    from the paper: at grazing angles and in concave corners (a floor meeting a wall) the hull of
    the transformed points skips observed points and spans them with long thin triangles whose
    middles lie on seen surface, and splitting them would make frontiers along every corner."""
    tri = np.asarray(triangles, dtype=np.int64)
    if len(tri) == 0:
        return vertices, tri, frontier_vertex
    ends = np.stack([tri, np.roll(tri, -1, axis=1)], axis=2)        # (T, 3, 2): edge j = (v_j, v_j+1)
    lo, hi = ends.min(axis=2).reshape(-1), ends.max(axis=2).reshape(-1)
    long_edge = np.linalg.norm(vertices[lo] - vertices[hi], axis=1) > eta_disc_m
    if surface is not None and long_edge.any():
        at = np.flatnonzero(long_edge)
        near, _ = surface.query(0.5 * (vertices[lo[at]] + vertices[hi[at]]), distance_upper_bound=surface_m)
        long_edge[at[np.isfinite(near)]] = False
    if not long_edge.any():
        return vertices, tri, frontier_vertex
    key = lo * len(vertices) + hi
    ukeys, inv = np.unique(key[long_edge], return_inverse=True)
    ua, ub = ukeys // len(vertices), ukeys % len(vertices)
    mid = np.full(len(key), -1, dtype=np.int64)
    mid[long_edge] = len(vertices) + inv
    mid = mid.reshape(-1, 3)                                         # mid[t, j]: middle of edge j
    new_vertices = np.concatenate([vertices, 0.5 * (vertices[ua] + vertices[ub])])
    new_frontier = np.concatenate([frontier_vertex, np.ones(len(ukeys), dtype=bool)])

    is_long = mid >= 0
    count = is_long.sum(axis=1)
    parts = [tri[count == 0]]
    # rotate each split triangle so that its pattern of long edges is a canonical one:
    # one long edge -> edge 0; two -> edges 0 and 1 (edge 2 short); three -> any.
    for c, first in ((1, lambda m: np.argmax(m, axis=1)), (2, lambda m: (np.argmin(m, axis=1) + 1) % 3),
                     (3, lambda m: np.zeros(len(m), dtype=np.int64))):
        sel = np.flatnonzero(count == c)
        if len(sel) == 0:
            continue
        r = first(is_long[sel])[:, None]
        cols = (r + np.arange(3)) % 3
        v = np.take_along_axis(tri[sel], cols, axis=1)
        m = np.take_along_axis(mid[sel], cols, axis=1)
        v0, v1, v2, m0, m1, m2 = v[:, 0], v[:, 1], v[:, 2], m[:, 0], m[:, 1], m[:, 2]
        if c == 1:
            new = [(v0, m0, v2), (m0, v1, v2)]
        elif c == 2:
            new = [(m0, v1, m1), (v0, m0, m1), (v0, m1, v2)]
        else:
            new = [(v0, m0, m2), (m0, v1, m1), (m2, m1, v2), (m0, m1, m2)]
        parts.extend(np.stack(t, axis=1) for t in new)
    return new_vertices, np.concatenate(parts), new_frontier


def visible_mesh(cloud: np.ndarray, agent: np.ndarray,
                 params: CsiroFrontierParams) -> tuple[FrontierMesh | None, str | None]:
    """The mesh of what an agent at ``agent`` sees of the observed points ``cloud`` (N, 3), with its
    frontier triangles (those with a frontier point: a visible sphere point or the middle of a long
    edge). Triangles are oriented with their normals away from the agent, out of the known space.

    Returns (mesh, None), or (None, reason) for a degenerate cloud: fewer than four points within
    d_max, or all of them on one plane or line (then the agent sees no frontier)."""
    a = np.asarray(agent, dtype=float)
    cloud = np.asarray(cloud, dtype=float).reshape(-1, 3)
    dist = np.linalg.norm(cloud - a, axis=1)
    cloud = cloud[(dist > 0) & (dist <= params.d_max_m)]
    if len(cloud) < MIN_POINTS:
        return None, f"too few points in range: {len(cloud)} within {params.d_max_m} m (need {MIN_POINTS})"
    if np.linalg.matrix_rank(cloud - cloud.mean(axis=0)) < 3:
        return None, f"degenerate point cloud: the {len(cloud)} points in range lie on one plane"
    # the sensor looked along the sphere points of its view; in its blind cones only a gap in the
    # cached surface wider than a discontinuity (eta_disc) is an opening
    directions = CloudDirections(cloud, a)
    sphere = sphere_points(a, params)
    sphere = sphere[~behind_observed(sphere, directions, a, params.d_vox_m)]
    blind = blind_sphere_points(a, params)
    blind = blind[~behind_observed(blind, directions, a, params.eta_disc_m)]
    points = np.concatenate([cloud, sphere, blind])
    transformed = np.concatenate([exponential_inversion(points, a, params.gamma), np.zeros((1, 3))])
    try:
        hull = ConvexHull(transformed)
    except QhullError as err:     # a cloud that defeats qhull is a degenerate view, not an error
        return None, f"degenerate point cloud: qhull failed ({str(err).splitlines()[0]})"
    # drop the faces at the viewpoint, and those over the sensor's blind cones unless they are frontier
    seen = len(points) if params.blind_frontiers else len(cloud) + len(sphere)
    tri = hull.simplices[~np.any(hull.simplices >= seen, axis=1)]
    used, tri = np.unique(tri, return_inverse=True)
    tri = tri.reshape(-1, 3).astype(np.int64)
    vertices = points[used]
    frontier_vertex = used >= len(cloud)                                  # equation 6
    vertices, tri, frontier_vertex = split_long_edges(vertices, tri, frontier_vertex, params.eta_disc_m,
                                                      cKDTree(cloud), SURFACE_VOXELS * params.d_vox_m)
    tri = _orient_away(vertices, tri, a)
    return FrontierMesh(vertices=vertices, triangles=tri, frontier=frontier_vertex[tri].any(axis=1),
                        viewpoint=a.copy()), None


def _orient_away(vertices: np.ndarray, tri: np.ndarray, agent: np.ndarray) -> np.ndarray:
    """``tri`` with the vertex order of each triangle flipped where its normal faces the agent."""
    p = vertices[tri]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    flip = np.einsum("ij,ij->i", n, p.mean(axis=1) - agent) < 0
    out = tri.copy()
    out[flip, 1], out[flip, 2] = tri[flip, 2], tri[flip, 1]
    return out


def triangle_geometry(mesh: FrontierMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(centroids (T, 3), unit normals (T, 3) away from the viewpoint (whatever the vertex order),
    areas (T,)) of the mesh's triangles; a triangle of no area gets the direction from the viewpoint
    as its normal."""
    p = mesh.vertices[mesh.triangles]
    centroids = p.mean(axis=1)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    twice_area = np.linalg.norm(n, axis=1)
    away = centroids - mesh.viewpoint
    n = np.where(twice_area[:, None] > 0, n, away)
    n *= np.where(np.einsum("ij,ij->i", n, away) < 0, -1.0, 1.0)[:, None]
    n /= np.maximum(np.linalg.norm(n, axis=1), np.finfo(float).tiny)[:, None]
    return centroids, n, 0.5 * twice_area


__all__ = ["MIN_POINTS", "CloudDirections", "behind_observed", "blind_sphere_points", "exponential_inversion",
           "sphere_points", "split_long_edges", "triangle_geometry", "visible_mesh"]
