"""Sequential frontier updating (Section III-B, Algorithm 2).

Every d_min of motion, at least T_min apart, the frontiers of the current viewpoint are made
(:func:`.visibility_mesh.visible_mesh`, Algorithm 1); new frontier triangles already seen from a
kept viewpoint are removed, and old frontier triangles now seen from the current viewpoint are
removed (NotVis, equation 9: a point is seen when it lies at least eta_vis in front of the
viewpoint's mesh along the ray from the viewpoint, by open3d ray casting). The new frontiers and
the old ones that changed are clustered again (kd-tree neighbours within eta_disc, grown like
Algorithm 1), and the old ones' ids pass to the new clusters by an optimal assignment (scipy's
linear_sum_assignment, Jonker-Volgenant) on the KL divergence of their Gaussians, so that a frontier
keeps its id while it is being explored. A viewpoint is kept every d_vp of motion.

Where delve departs from the paper: NotVis tests a frontier's triangle centroids
(:attr:`Frontier.points`), not its frontier vertices, because a Frontier carries its triangles as
centroids; the KL divergence adds the variance of a voxel (d_vox^2 / 12) to both covariances, as a
segment's centroids may lie on one plane.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import open3d as o3d
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.spatial import cKDTree

from .frontier_types import Frontier, FrontierMesh
from .params import CsiroFrontierParams
from .segmentation import grow_regions, make_frontier, segment_frontiers
from .visibility_mesh import SURFACE_VOXELS, visible_mesh


@dataclass(frozen=True)
class Viewpoint:
    """A kept viewpoint (tau, a, V, T): the time and the visible mesh (whose ``viewpoint`` is a)."""

    t_s: float
    mesh: FrontierMesh

    @property
    def position(self) -> np.ndarray:
        return self.mesh.viewpoint


@dataclass(frozen=True)
class FrontierUpdate:
    """What one update did: all frontiers now (by id), the current viewpoint's mesh (None with a
    ``reason`` when the cloud was degenerate: nothing changed then), the ids created and removed,
    and whether the viewpoint was kept."""

    frontiers: tuple[Frontier, ...]
    mesh: FrontierMesh | None
    reason: str | None
    new_ids: tuple[int, ...]
    removed_ids: tuple[int, ...]
    viewpoint_kept: bool


def mesh_scene(mesh: FrontierMesh) -> o3d.t.geometry.RaycastingScene:
    """An open3d ray-casting scene of ``mesh`` in coordinates relative to its viewpoint (float32
    then keeps millimetres far from the world origin)."""
    scene = o3d.t.geometry.RaycastingScene()
    if len(mesh.triangles):
        scene.add_triangles(o3d.core.Tensor((mesh.vertices - mesh.viewpoint).astype(np.float32)),
                            o3d.core.Tensor(mesh.triangles.astype(np.uint32)))
    return scene


def seen_from(points: np.ndarray, mesh: FrontierMesh, scene: o3d.t.geometry.RaycastingScene,
              params: CsiroFrontierParams) -> np.ndarray:
    """Vis(p) of equation 9 for each of ``points`` (K, 3): within d_max of the mesh's viewpoint and at
    least eta_vis in front of the first triangle that the ray from the viewpoint through p meets (a ray
    that meets none, out through the mesh's hole over the sensor's blind cones, has no surface in
    front of p: seen)."""
    d = np.asarray(points, float) - mesh.viewpoint
    r = np.linalg.norm(d, axis=1)
    test = np.flatnonzero((r > 0) & (r <= params.d_max_m))
    out = np.zeros(len(d), dtype=bool)
    if len(test) == 0 or len(mesh.triangles) == 0:
        return out
    rays = np.concatenate([np.zeros((len(test), 3)), d[test] / r[test, None]], axis=1).astype(np.float32)
    t_hit = scene.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy()
    out[test] = t_hit >= r[test] + params.eta_vis_m
    return out


def on_surface(points: np.ndarray, surface: cKDTree, agent: np.ndarray,
               params: CsiroFrontierParams) -> np.ndarray:
    """(K,) bool: frontier ``points`` within d_max of ``agent`` that now lie on observed surface,
    within a voxel's diagonal of a point of ``surface`` (the kd-tree of the cloud). Not in the
    paper: the middle of a long edge lies on the surface it spanned (a floor seen in rings far
    apart), and once the gap is filled the ray test of equation 9 finds it as often behind the
    surface as in front; the same rule keeps such middles from being frontier points in the first
    place (:func:`.visibility_mesh.split_long_edges`)."""
    points = np.asarray(points, float)
    near = np.linalg.norm(points - agent, axis=1) <= params.d_max_m
    out = np.zeros(len(points), dtype=bool)
    if near.any() and surface.n:
        gap, _ = surface.query(points[near], distance_upper_bound=SURFACE_VOXELS * params.d_vox_m)
        out[near] = np.isfinite(gap)
    return out


def gaussian_kl(means0: np.ndarray, covs0: np.ndarray, means1: np.ndarray, covs1: np.ndarray) -> np.ndarray:
    """D(N0_i || N1_j), the KL divergence (nats) of every Gaussian of the first set (means (m, 3),
    covariances (m, 3, 3)) from every one of the second set (n, ...): an (m, n) array."""
    inv1 = np.linalg.inv(covs1)
    logdet0 = np.linalg.slogdet(covs0)[1]
    logdet1 = np.linalg.slogdet(covs1)[1]
    dm = means1[None, :, :] - means0[:, None, :]
    trace = np.einsum("nij,mji->mn", inv1, covs0)
    mahalanobis = np.einsum("mni,nij,mnj->mn", dm, inv1, dm)
    return 0.5 * (trace + mahalanobis - 3 + logdet1[None, :] - logdet0[:, None])


def _split(values: np.ndarray, frontiers: list[Frontier]) -> list[np.ndarray]:
    """``values`` of the frontiers' points taken together, cut back into one array per frontier."""
    return np.split(values, np.cumsum([len(f.points) for f in frontiers])[:-1])


def _subset(f: Frontier, keep: np.ndarray) -> Frontier:
    return make_frontier(f.id, f.points[keep], f.normals[keep], f.areas[keep])


class SequentialFrontiers:
    """Algorithm 2: the frontiers and kept viewpoints of one agent, updated view by view.

    Frontier ids are stable: a frontier keeps its id until it changes; a changed one hands its id
    to the new frontier that the assignment matches it with; new ids count up from 0."""

    def __init__(self, params: CsiroFrontierParams | None = None) -> None:
        self.params = params or CsiroFrontierParams()
        self._frontiers: dict[int, Frontier] = {}
        self._viewpoints: list[Viewpoint] = []
        self._scenes: dict[int, o3d.t.geometry.RaycastingScene] = {}
        self._next_id = 0
        self._last: tuple[float, np.ndarray] | None = None

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state["_scenes"] = {}            # open3d scenes do not pickle; rebuilt on demand
        return state

    @property
    def frontiers(self) -> tuple[Frontier, ...]:
        """The current frontiers, by id."""
        return tuple(self._frontiers[k] for k in sorted(self._frontiers))

    @property
    def viewpoints(self) -> tuple[Viewpoint, ...]:
        """The kept viewpoints H, oldest first."""
        return tuple(self._viewpoints)

    @property
    def last_viewpoint(self) -> np.ndarray | None:
        """Where the last update was seen from (None before the first)."""
        return None if self._last is None else self._last[1].copy()

    def due(self, t_s: float, position: np.ndarray) -> bool:
        """Whether an update is due: never updated yet, or moved at least d_min since the last
        update and at least T_min later."""
        if self._last is None:
            return True
        t0, p0 = self._last
        return (t_s - t0 >= self.params.t_min_s
                and float(np.linalg.norm(np.asarray(position, float) - p0)) >= self.params.d_min_m)

    def update(self, t_s: float, agent: np.ndarray, cloud: np.ndarray) -> FrontierUpdate:
        """One pass of Algorithm 2 for an agent at ``agent`` at time ``t_s`` with the observed points
        ``cloud`` (N, 3; :meth:`.PointCache.cloud`). A degenerate cloud leaves everything as it was
        and says why in ``reason``."""
        p = self.params
        a = np.asarray(agent, dtype=float).copy()
        self._last = (float(t_s), a)
        mesh, reason = visible_mesh(cloud, a, p)
        if mesh is None:
            return FrontierUpdate(self.frontiers, None, reason, (), (), False)
        scene = mesh_scene(mesh)
        fresh = self._not_seen_before(segment_frontiers(mesh, p), a)

        changed_old: list[Frontier] = []       # the old frontiers as they were (for the assignment)
        changed_rest: list[Frontier] = []      # what is left of them (for the clustering)
        old = [self._frontiers[k] for k in sorted(self._frontiers)]
        surface = cKDTree(np.asarray(cloud, float).reshape(-1, 3))
        on = _split(on_surface(np.concatenate([f.points for f in old]), surface, a, p), old) if old else []
        for f, seen, lying in zip(old, self._seen(old, mesh, scene), on):
            seen = seen | lying
            if not seen.any():
                continue
            changed_old.append(f)
            del self._frontiers[f.id]
            if not seen.all():
                changed_rest.append(_subset(f, ~seen))

        clusters = self._cluster(fresh + changed_rest)
        ids = self._assign(changed_old, clusters)
        new_ids = []
        for fid, c in zip(ids, clusters):
            if c.area > p.eta_area_m2:
                self._frontiers[fid] = dataclasses.replace(c, id=fid)
                new_ids.append(fid)
        removed = tuple(sorted({f.id for f in changed_old} - set(self._frontiers)))
        created = tuple(sorted(i for i in new_ids if i not in {f.id for f in changed_old}))

        kept = not self._viewpoints or bool(np.linalg.norm(a - self._viewpoints[-1].position) >= p.d_vp_m)
        if kept:
            self._scenes[len(self._viewpoints)] = scene
            self._viewpoints.append(Viewpoint(float(t_s), mesh))
        for k in [k for k in self._scenes if np.linalg.norm(self._viewpoints[k].position - a) > 2 * p.d_max_m]:
            del self._scenes[k]          # out of reach: the memory back; rebuilt if the agent returns
        return FrontierUpdate(self.frontiers, mesh, None, created, removed, kept)

    def discard(self, ids: list[int]) -> None:
        """Forget the frontiers ``ids`` (no observer can see them: no useful frontier, Section
        III-C)."""
        for fid in ids:
            self._frontiers.pop(fid, None)

    def _scene(self, k: int) -> o3d.t.geometry.RaycastingScene:
        if k not in self._scenes:
            self._scenes[k] = mesh_scene(self._viewpoints[k].mesh)
        return self._scenes[k]

    def _seen(self, frontiers: list[Frontier], mesh: FrontierMesh,
              scene: o3d.t.geometry.RaycastingScene) -> list[np.ndarray]:
        """Vis of every triangle of ``frontiers`` from one viewpoint, in one batch of rays; the
        test is skipped (all False) for frontiers with no point within d_max of it."""
        seen = [np.zeros(len(f.points), dtype=bool) for f in frontiers]
        near = [k for k, f in enumerate(frontiers)
                if np.min(np.linalg.norm(f.points - mesh.viewpoint, axis=1)) <= self.params.d_max_m]
        if near:
            vis = seen_from(np.concatenate([frontiers[k].points for k in near]), mesh, scene, self.params)
            for k, part in zip(near, _split(vis, [frontiers[k] for k in near])):
                seen[k] = part
        return seen

    def _not_seen_before(self, frontiers: list[Frontier], agent: np.ndarray) -> list[Frontier]:
        """``frontiers`` (seen from ``agent``, so within d_max of it) without the triangles that a
        kept viewpoint already saw (NotVis); those left with no triangle are dropped."""
        keep = [np.ones(len(f.points), dtype=bool) for f in frontiers]
        for k, vp in enumerate(self._viewpoints):
            if not frontiers or np.linalg.norm(vp.position - agent) > 2 * self.params.d_max_m:
                continue
            for kept, seen in zip(keep, self._seen(frontiers, vp.mesh, self._scene(k))):
                kept &= ~seen
        return [f if kept.all() else _subset(f, kept) for f, kept in zip(frontiers, keep) if kept.any()]

    def _cluster(self, frontiers: list[Frontier]) -> list[Frontier]:
        """Cluster: the triangles of ``frontiers`` regrown into frontiers (provisional id -1);
        triangles join when their centroids are within eta_disc (kd-tree) or they came from the
        same frontier, within eta_dia of the anchor."""
        if not frontiers:
            return []
        points = np.concatenate([f.points for f in frontiers])
        normals = np.concatenate([f.normals for f in frontiers])
        areas = np.concatenate([f.areas for f in frontiers])
        source = np.repeat(np.arange(len(frontiers)), [len(f.points) for f in frontiers])
        pairs = cKDTree(points).query_pairs(self.params.eta_disc_m, output_type="ndarray")
        first = np.searchsorted(source, source)                    # each triangle's frontier's first
        rows = np.concatenate([pairs[:, 0], np.arange(len(points))])
        cols = np.concatenate([pairs[:, 1], first])
        n = len(points)
        adj = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
        adj = (adj + adj.T).tocsr()
        regions = grow_regions(adj, points, self.params.eta_dia_m)
        return [make_frontier(-1, points[r], normals[r], areas[r]) for r in regions]

    def _assign(self, old: list[Frontier], new: list[Frontier]) -> list[int]:
        """Assign: ids for the ``new`` clusters, the old ids where the optimal assignment on
        D(N(old) || N(new)) pairs them (within assignment_max_kl), fresh ids for the rest."""
        ids = [-1] * len(new)
        if old and new:
            reg = np.eye(3) * self.params.d_vox_m ** 2 / 12.0
            cost = gaussian_kl(np.array([f.mean for f in old]), np.array([f.cov for f in old]) + reg,
                               np.array([g.mean for g in new]), np.array([g.cov for g in new]) + reg)
            rows, cols = linear_sum_assignment(cost)
            for r, c in zip(rows, cols):
                if cost[r, c] <= self.params.assignment_max_kl:
                    ids[c] = old[r].id
        for k in range(len(ids)):
            if ids[k] < 0:
                ids[k] = self._next_id
                self._next_id += 1
        return ids


__all__ = ["FrontierUpdate", "SequentialFrontiers", "Viewpoint", "gaussian_kl", "mesh_scene", "on_surface",
           "seen_from"]
