"""Ground-truth worlds: a voxel grid of free space plus the rock surface mesh.

A :class:`World` is what the simulator knows and the robots do not: which
voxels are air (``free``), the rock surface (``mesh``) that LiDAR rays hit,
the passages' centreline graph and a default start point on the floor.
Worlds come from :mod:`delve.sim.worldgen` (procedural mines and caves, or a
mesh file); this module only queries them.

Conventions: world coordinates in metres, +z up; voxel ``(i, j, k)`` spans
``origin + [i, i+1) * voxel_size_m`` (and likewise in y and z); everything
outside the grid counts as rock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import networkx as nx
import numpy as np
import open3d as o3d
from scipy import ndimage

#: 26-connectivity structuring element for scipy.ndimage.label.
_CONNECTIVITY_26 = np.ones((3, 3, 3), dtype=bool)
#: Radius within which reachable_free looks for a free voxel near the start.
_START_SEARCH_RADIUS_M = 1.0
#: Default start points sit this far above the floor surface, inside the first free voxel.
START_ABOVE_FLOOR_M = 0.01
#: Mesh file suffixes that save_mesh and worldgen.from_mesh understand.
MESH_SUFFIXES = (".ply", ".obj", ".stl")
#: A floor point offered in a message has this much air above it.
FLOOR_HEADROOM_M = 1.0


@dataclass(frozen=True)
class WorldSource:
    """How a world was loaded from a file (see :mod:`delve.sim.worldfile`).

    Fields:
        file: the file's name.
        format: "Collada", "PLY", "PCD point cloud", ...
        free_space: how free space was built: "closed" (parity inside a closed
            inner surface), "surface" (rock where the surface passes, a ceiling,
            the floored regions), "points" (inflated points, the floored regions)
            or "scans" (rays from scan origins).
        closure: "inner", "solids" or "open" for meshes (see
            :class:`delve.sim.freespace.Closure`), None for point clouds.
        boundary_edges: edges of the mesh that only one triangle uses.
        up_axis: the file's axis that became +z; ``up_axis_from``: "scenario",
            "file" (what the file declares) or "default".
        file_up_axis: what the file declares, or None.
        scale: metres per file unit; ``scale_from``: "scenario", "file" or "default".
        ceiling_z: the ceiling closing the world (z, m), or None; ``ceiling_from``:
            "scenario" or "model top".
        inflation_m: how far rock reaches around each point (point clouds).
        scan_origins: scan origins used (point clouds with origins).
    """

    file: str
    format: str
    free_space: str
    closure: str | None = None
    boundary_edges: int = 0
    up_axis: str = "z"
    up_axis_from: str = "default"
    file_up_axis: str | None = None
    scale: float = 1.0
    scale_from: str = "default"
    ceiling_z: float | None = None
    ceiling_from: str | None = None
    inflation_m: float | None = None
    scan_origins: int = 0


@dataclass(kw_only=True, eq=False)
class World:
    """A ground-truth world: voxel free space, rock mesh, centreline, start.

    Fields:
        name: a short label (scenario files and reports use it).
        voxel_size_m: edge length of a voxel.
        origin: (3,) world coordinates of the lower corner of voxel (0, 0, 0).
        free: bool (nx, ny, nz); True = air, False = rock (or outside).
        mesh: the rock surface (legacy open3d TriangleMesh), for ray casting
            and plots; in generated worlds its normals point into free space.
        centreline: networkx.Graph; nodes carry ``pos`` (a point on the floor)
            and ``level``; edges carry ``width_m``, ``height_m``, ``kind``
            ("tunnel", "cave", "ramp" or "shaft") and ``length_m``. Empty for
            worlds loaded from a mesh.
        start: (3,) default start point on the floor.
        source: how the world was loaded from a file (None for generated worlds).
    """

    name: str
    voxel_size_m: float = 0.2
    origin: np.ndarray
    free: np.ndarray
    mesh: o3d.geometry.TriangleMesh
    centreline: nx.Graph = field(default_factory=nx.Graph)
    start: np.ndarray
    source: WorldSource | None = None

    _scene: o3d.t.geometry.RaycastingScene | None = field(
        default=None, init=False, repr=False)
    _labels: np.ndarray | None = field(default=None, init=False, repr=False)
    _reachable: dict = field(default_factory=dict, init=False, repr=False)
    #: One downward ray (float32 (1, 6)) and the open3d tensor that shares its memory.
    _down_ray: tuple[np.ndarray, o3d.core.Tensor] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.voxel_size_m = float(self.voxel_size_m)
        if not np.isfinite(self.voxel_size_m) or self.voxel_size_m <= 0:
            raise ValueError(f"voxel_size_m must be > 0, got {self.voxel_size_m}")
        self.origin = np.asarray(self.origin, dtype=float).reshape(3)
        self.start = np.asarray(self.start, dtype=float).reshape(3)
        self.free = np.asarray(self.free, dtype=bool)
        if self.free.ndim != 3:
            raise ValueError(f"free must be a 3-D grid, got shape {self.free.shape}")

    def __getstate__(self) -> dict:
        """Pickle / deepcopy support: the mesh travels as arrays, caches are dropped."""
        state = self.__dict__.copy()
        mesh = state.pop("mesh")
        state["_mesh_arrays"] = (np.asarray(mesh.vertices).copy(),
                                 np.asarray(mesh.triangles).copy())
        state.update(_scene=None, _labels=None, _reachable={}, _down_ray=None)
        return state

    def __setstate__(self, state: dict) -> None:
        """Rebuild the open3d mesh from the pickled arrays."""
        state = dict(state)
        verts, tris = state.pop("_mesh_arrays")
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                         o3d.utility.Vector3iVector(tris))
        if len(tris):
            mesh.compute_vertex_normals()
        state["mesh"] = mesh
        self.__dict__.update(state)

    def __repr__(self) -> str:
        return (f"World(name={self.name!r}, voxel_size_m={self.voxel_size_m}, "
                f"shape={self.shape}, free_voxels={int(self.free.sum())}, "
                f"triangles={len(self.mesh.triangles)}, "
                f"centreline={self.centreline.number_of_nodes()} nodes)")

    # ------------------------------------------------------------------ grid
    @property
    def shape(self) -> tuple[int, int, int]:
        """Grid shape (nx, ny, nz) in voxels."""
        return tuple(int(n) for n in self.free.shape)

    @property
    def bounds_min(self) -> np.ndarray:
        """World coordinates of the grid's lower corner."""
        return self.origin.copy()

    @property
    def bounds_max(self) -> np.ndarray:
        """World coordinates of the grid's upper corner."""
        return self.origin + np.asarray(self.shape, dtype=float) * self.voxel_size_m

    @property
    def free_volume_m3(self) -> float:
        """Total free (air) volume of the grid in cubic metres."""
        return float(np.count_nonzero(self.free)) * self.voxel_size_m ** 3

    def to_index(self, points: np.ndarray) -> np.ndarray:
        """Voxel indices (N, 3) int of world points (N, 3): floor((p - origin) / voxel)."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.floor((p - self.origin) / self.voxel_size_m).astype(np.int64)

    def in_bounds(self, idx: np.ndarray) -> np.ndarray:
        """(N,) bool: which voxel indices (N, 3) lie inside the grid."""
        i = np.asarray(idx).reshape(-1, 3)
        return np.all((i >= 0) & (i < np.asarray(self.shape)), axis=1)

    def index_to_center(self, idx: np.ndarray) -> np.ndarray:
        """World coordinates (N, 3) of the centres of voxels (N, 3)."""
        i = np.asarray(idx, dtype=float).reshape(-1, 3)
        return self.origin + (i + 0.5) * self.voxel_size_m

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which world points (N, 3) lie in free space (False outside the grid)."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        if len(p) == 1 and np.isfinite(p).all():
            return np.array([self.is_free_at(float(p[0, 0]), float(p[0, 1]), float(p[0, 2]))])
        idx = self.to_index(p)
        ok = self.in_bounds(idx)
        out = np.zeros(len(idx), dtype=bool)
        j = idx[ok]
        out[ok] = self.free[j[:, 0], j[:, 1], j[:, 2]]
        return out

    def is_free_at(self, x: float, y: float, z: float) -> bool:
        """Whether the point (x, y, z) lies in free space, as :meth:`is_free` of one point.
        A robot's probes, two every sim step: the same arithmetic on plain floats is
        several times faster than on arrays of one point."""
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return False
        o, v, n = self.origin, self.voxel_size_m, self.free.shape
        i, j, k = (math.floor((c - float(o[a])) / v) for a, c in enumerate((x, y, z)))
        return 0 <= i < n[0] and 0 <= j < n[1] and 0 <= k < n[2] and bool(self.free[i, j, k])

    # ---------------------------------------------------------- ray casting
    @property
    def scene(self) -> o3d.t.geometry.RaycastingScene:
        """Cached open3d RaycastingScene holding the rock mesh."""
        if self._scene is None:
            scene = o3d.t.geometry.RaycastingScene()
            if len(self.mesh.triangles) > 0:
                scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(self.mesh))
            self._scene = scene
        return self._scene

    def cast_rays(self, origins: np.ndarray, directions: np.ndarray,
                  max_range_m: float) -> np.ndarray:
        """Distance along each ray to the first rock hit.

        origins, directions: (N, 3); directions must be unit vectors.
        Returns (N,) float32 distances, np.inf where nothing is hit within
        ``max_range_m``.
        """
        o = np.asarray(origins).reshape(-1, 3)
        d = np.asarray(directions).reshape(-1, 3)
        if len(o) != len(d):
            raise ValueError(f"{len(o)} origins but {len(d)} directions")
        if len(o) == 0:
            return np.zeros(0, dtype=np.float32)
        rays = np.empty((len(o), 6), dtype=np.float32)   # rounded to float32 as they are copied in
        rays[:, :3] = o
        rays[:, 3:] = d
        t = self.scene.cast_rays(o3d.core.Tensor.from_numpy(rays))["t_hit"].numpy()
        t[~(t <= np.float32(max_range_m))] = np.inf
        return t

    def distance_down(self, x: float, y: float, z: float, max_range_m: float) -> float:
        """Distance straight down from (x, y, z) to the first rock hit, as
        :meth:`cast_rays` of that one ray (np.inf beyond ``max_range_m``). A legged
        robot's ground probe, every sim step: the ray is written into a kept buffer
        that open3d reads in place, half the cost of a :meth:`cast_rays` call."""
        if self._down_ray is None:
            buf = np.zeros((1, 6), dtype=np.float32)
            buf[0, 5] = -1.0
            self._down_ray = (buf, o3d.core.Tensor.from_numpy(buf))
        buf, rays = self._down_ray
        buf[0, 0], buf[0, 1], buf[0, 2] = x, y, z
        t = float(self.scene.cast_rays(rays)["t_hit"].numpy()[0])
        return t if t <= float(np.float32(max_range_m)) else math.inf

    def line_of_sight(self, a: np.ndarray, b: np.ndarray) -> bool:
        """True when no rock lies on the straight segment from a to b."""
        a = np.asarray(a, dtype=float).reshape(3)
        b = np.asarray(b, dtype=float).reshape(3)
        length = float(np.linalg.norm(b - a))
        if length == 0.0:
            return True
        hit = self.cast_rays(a[None], ((b - a) / length)[None], length)
        return bool(np.isinf(hit[0]))

    # -------------------------------------------------------- connectivity
    def _nearest_free_voxel(self, point: np.ndarray) -> np.ndarray:
        """Index of the free voxel nearest to point within 1 m; ValueError if none."""
        v = self.voxel_size_m
        centre = self.to_index(point)[0]
        r = int(np.ceil(_START_SEARCH_RADIUS_M / v))
        rng = np.arange(-r, r + 1)
        off = np.stack(np.meshgrid(rng, rng, rng, indexing="ij"), -1).reshape(-1, 3)
        idx = centre + off
        dist = np.linalg.norm(self.index_to_center(idx) - np.asarray(point, float), axis=1)
        keep = (dist <= _START_SEARCH_RADIUS_M + 0.5 * np.sqrt(3) * v) & self.in_bounds(idx)
        idx, dist = idx[keep], dist[keep]
        ok = self.free[idx[:, 0], idx[:, 1], idx[:, 2]]
        if not ok.any():
            raise ValueError(
                f"no free voxel within {_START_SEARCH_RADIUS_M} m of "
                f"{np.round(np.asarray(point, float), 2).tolist()} in world {self.name!r}")
        idx, dist = idx[ok], dist[ok]
        order = np.lexsort((idx[:, 2], idx[:, 1], idx[:, 0], dist))
        return idx[order[0]]

    def reachable_free(self, start: np.ndarray) -> np.ndarray:
        """Free space connected (26-connectivity) to the voxel at ``start``.

        If that voxel is rock, the nearest free voxel within 1 m is used;
        ValueError if there is none. Returns a read-only bool grid, cached per
        start voxel.
        """
        start = np.asarray(start, dtype=float).reshape(3)
        idx = self.to_index(start)[0]
        if not (self.in_bounds(idx[None])[0] and self.free[tuple(idx)]):
            idx = self._nearest_free_voxel(start)
        key = tuple(int(i) for i in idx)
        if key not in self._reachable:
            labels = self._region_labels()
            comp = labels == labels[key]
            comp.flags.writeable = False
            self._reachable[key] = comp
        return self._reachable[key]

    def free_regions(self) -> tuple[np.ndarray, np.ndarray]:
        """(labels, sizes): the free space's 26-connected regions (label 0 is rock) and
        each label's voxel count (``sizes[0]`` = 0). The labels are cached."""
        labels = self._region_labels()
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        return labels, sizes

    def region_label(self, point: np.ndarray) -> int:
        """The label (see :meth:`free_regions`) of the free region at ``point``, or of
        the nearest free voxel within 1 m; ValueError if there is none."""
        p = np.asarray(point, dtype=float).reshape(3)
        idx = self.to_index(p)[0]
        if not (self.in_bounds(idx[None])[0] and self.free[tuple(idx)]):
            idx = self._nearest_free_voxel(p)
        return int(self._region_labels()[tuple(int(i) for i in idx)])

    def _region_labels(self) -> np.ndarray:
        """The free space's region labels (cached), in the smallest unsigned dtype that
        holds them: labelled into uint16 first, so that a large world never holds
        the int32 grid scipy would otherwise return (4 bytes a voxel)."""
        if self._labels is None:
            labels = np.empty(self.free.shape, dtype=np.uint16)
            try:
                n = ndimage.label(self.free, structure=_CONNECTIVITY_26, output=labels)
            except RuntimeError as err:       # more than 65535 regions: scipy's own int32
                if "bit-depth" not in str(err):
                    raise
                labels, n = ndimage.label(self.free, structure=_CONNECTIVITY_26)
            self._labels = labels.astype(np.min_scalar_type(n), copy=False)
        return self._labels

    # --------------------------------------------------------------- ground
    def ground_height(self, points: np.ndarray, max_drop_m: float) -> np.ndarray:
        """z of the ground under each point (N, 3), searching down at most max_drop_m.

        The ground is the top surface of the first rock voxel met going down
        from the point's own voxel. np.nan where there is none within
        ``max_drop_m`` (e.g. over a shaft), where the point itself is in rock,
        or where the point is outside the grid.
        """
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        v = self.voxel_size_m
        n_down = max(int(np.ceil(max(float(max_drop_m), 0.0) / v)) + 1, 1)
        idx = self.to_index(p)
        nx_, ny_, nz_ = self.shape
        col_ok = ((idx[:, 0] >= 0) & (idx[:, 0] < nx_) & (idx[:, 1] >= 0)
                  & (idx[:, 1] < ny_) & (idx[:, 2] >= 0) & (idx[:, 2] < nz_))
        out = np.full(len(p), np.nan)
        if not col_ok.any():
            return out
        i, j, k = idx[col_ok, 0], idx[col_ok, 1], idx[col_ok, 2]
        ks = k[:, None] - np.arange(n_down + 1)[None, :]          # (M, n+1) downward
        inside = ks >= 0
        free = np.zeros(ks.shape, dtype=bool)                      # below the grid = rock
        free[inside] = self.free[np.broadcast_to(i[:, None], ks.shape)[inside],
                                 np.broadcast_to(j[:, None], ks.shape)[inside],
                                 ks[inside]]
        rock = ~free
        first = np.argmax(rock, axis=1)
        found = rock[np.arange(len(ks)), first] & (first > 0)
        ground = self.origin[2] + (ks[np.arange(len(ks)), first] + 1) * v
        ok = found & (ground >= p[col_ok, 2] - float(max_drop_m) - 1e-9)
        res = np.full(len(ks), np.nan)
        res[ok] = ground[ok]
        out[col_ok] = res
        return out

    def start_problem(self, point: np.ndarray) -> str | None:
        """None if ``point`` is a valid start, else why not, with the nearest free floor.

        Valid: inside the grid and in free space, or on a floor, that is in the rock
        voxel the floor surface passes through with free space right above it."""
        p = np.asarray(point, dtype=float).reshape(3)
        if not self.in_bounds(self.to_index(p))[0]:
            lo, hi = self.bounds_min, self.bounds_max
            return ("outside the world (bounds "
                    f"x∈[{lo[0]:.1f}, {hi[0]:.1f}], y∈[{lo[1]:.1f}, {hi[1]:.1f}], "
                    f"z∈[{lo[2]:.1f}, {hi[2]:.1f}])" + self.nearest_floor_hint(p))
        if not self.is_free(p[None])[0] and not self.on_floor(p):
            return "inside rock" + self.nearest_floor_hint(p)
        return None

    def on_floor(self, point: np.ndarray) -> bool:
        """Whether ``point`` lies in a rock voxel with a free voxel right above it (on
        the floor surface, as a user measures a start on a model)."""
        idx = self.to_index(point)[0] + np.array([0, 0, 1])
        return bool(self.in_bounds(idx[None])[0] and self.free[tuple(idx)])

    def nearest_floor(self, point: np.ndarray, headroom_m: float = FLOOR_HEADROOM_M) -> np.ndarray | None:
        """The floor point nearest to ``point`` in the largest free region: the centre of
        the bottom face of a free voxel that has rock below and ``headroom_m`` of air
        above it (any floor when none has that much). None if the world has no floor."""
        labels, sizes = self.free_regions()
        if not sizes.any():
            return None
        main = labels == int(np.argmax(sizes))
        floor = main.copy()
        floor[:, :, 1:] &= ~self.free[:, :, :-1]
        idx = np.argwhere(floor)
        head = max(int(np.ceil(headroom_m / self.voxel_size_m)), 1)
        tall = np.ones(len(idx), dtype=bool)
        for dz in range(1, head):
            k = idx[:, 2] + dz
            ok = k < self.shape[2]
            tall &= ok
            tall[ok] &= self.free[idx[ok, 0], idx[ok, 1], k[ok]]
        if tall.any():
            idx = idx[tall]
        p = np.asarray(point, dtype=float).reshape(3)
        pts = self.index_to_center(idx)
        pts[:, 2] -= 0.5 * self.voxel_size_m
        return pts[int(np.argmin(np.linalg.norm(pts - p, axis=1)))]

    def nearest_floor_hint(self, point: np.ndarray) -> str:
        """`` (nearest free floor: [x, y, z], d m away)``, or "" when the world has no floor."""
        floor = self.nearest_floor(point)
        if floor is None:
            return ""
        d = float(np.linalg.norm(floor - np.asarray(point, dtype=float).reshape(3)))
        return f" (nearest free floor: [{floor[0]:.1f}, {floor[1]:.1f}, {floor[2]:.1f}], {d:.1f} m away)"

    # ------------------------------------------------------------------ io
    def save_mesh(self, path: str | Path) -> None:
        """Write the rock mesh to a .ply, .obj or .stl file (binary where the format allows)."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in MESH_SUFFIXES:
            raise ValueError(f"cannot save mesh as '{path}': use one of {', '.join(MESH_SUFFIXES)}")
        mesh = self.mesh
        if suffix == ".stl" and not mesh.has_triangle_normals():
            mesh = o3d.geometry.TriangleMesh(mesh)
            mesh.compute_triangle_normals()
        elif suffix == ".obj" and mesh.has_triangle_normals():
            mesh = o3d.geometry.TriangleMesh(mesh)       # OBJ keeps vertex normals only
            mesh.triangle_normals = o3d.utility.Vector3dVector()
        path.parent.mkdir(parents=True, exist_ok=True)
        ok = o3d.io.write_triangle_mesh(str(path), mesh, write_ascii=False,
                                        write_vertex_normals=suffix != ".stl",
                                        print_progress=False)
        if not ok:
            raise OSError(f"open3d could not write mesh '{path}'")
