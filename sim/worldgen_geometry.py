"""Geometry shared by the world generators: carving passages into a voxel
grid, clearance checks between planned passages, and the rock surface mesh.

Every carving function writes into a :class:`VoxelCanvas` only inside the
bounding box of the shape it carves, with numpy broadcasting over that box.
A voxel is carved (made free) when its centre lies inside the shape.
"""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import open3d as o3d
from scipy import ndimage
from skimage import measure

from .limits import check_voxels, voxel_count
from .world import START_ABOVE_FLOOR_M, World

#: Rock kept between passages that the plan does not join.
CLEARANCE_M = 2.0
#: Radius range of vertical shafts.
SHAFT_RADIUS_M = (1.5, 2.0)
#: Gaussian smoothing (in voxels) of the free grid before marching cubes.
MESH_SMOOTHING_SIGMA_VOXELS = 0.7
#: Iso-level at which the rock surface is drawn. Free voxels count 1 and rock
#: voxels their smoothed value capped at MESH_ROCK_CAP (< level), so every free
#: voxel centre is inside the surface, every rock centre outside, and the
#: surface crosses each free-rock voxel pair 70-93 % of the way to the rock
#: centre: a LiDAR hit nudged 5 cm further along its ray lands in rock.
MESH_ISO_LEVEL = 0.3
#: Upper bound of the smoothed field in rock voxels (must stay below MESH_ISO_LEVEL).
MESH_ROCK_CAP = 0.25
#: Meshes with more triangles than this are decimated. Marching cubes gives about
#: 0.6 triangles per free voxel (the demo's 400 m: 0.3 M; a 300 x 500 m mine with
#: 4 km of drifts: 3.1 M), and quadric decimation costs about 16 s per million
#: triangles on the 2-core machine while ray casting grows only with their
#: logarithm, so worlds keep their full surface up to this size.
MESH_MAX_TRIANGLES = 8_000_000
#: Rock left around the passages at the edge of a generated grid.
GRID_MARGIN_M = 1.0
#: Fraction of a cave cross-section's vertical semi-axis that lies below the
#: ellipse centre before the flat floor cuts it.
CAVE_FLOOR_CUT = 0.6
#: Arch rise of a tunnel roof as a fraction of the tunnel width (capped at half the height).
TUNNEL_ARCH_RISE = 0.35


class VoxelCanvas:
    """A boolean voxel grid covering a box, into which shapes are carved."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray, voxel_size_m: float,
                 margin_m: float = GRID_MARGIN_M) -> None:
        v = float(voxel_size_m)
        self.voxel_size_m = v
        self.origin = np.floor((np.asarray(lo, float) - margin_m) / v) * v
        top = np.asarray(hi, float) + margin_m
        self.shape = tuple(int(n) for n in np.ceil((top - self.origin) / v - 1e-9))
        extent = top - self.origin
        check_voxels(voxel_count(extent, v), v, f"the world's box of {extent[0]:.0f} x {extent[1]:.0f} x "
                     f"{extent[2]:.0f} m", "total_length_m")
        self.free = np.zeros(self.shape, dtype=bool)

    def window(self, lo, hi):
        """Slices of the grid covering world box [lo, hi] and its voxel-centre coordinates.

        Returns (slices, xs, ys, zs) with xs shaped (nx, 1), ys (1, ny) and
        zs (1, 1, nz), or None when the box misses the grid.
        """
        v = self.voxel_size_m
        i0 = np.maximum(np.floor((np.asarray(lo, float) - self.origin) / v).astype(int), 0)
        i1 = np.minimum(np.ceil((np.asarray(hi, float) - self.origin) / v).astype(int) + 1,
                        self.shape)
        if np.any(i1 <= i0):
            return None
        c = [self.origin[a] + (np.arange(i0[a], i1[a]) + 0.5) * v for a in range(3)]
        sl = tuple(slice(int(i0[a]), int(i1[a])) for a in range(3))
        return sl, c[0][:, None], c[1][None, :], c[2][None, None, :]


def horizontal_frame(a: np.ndarray, b: np.ndarray):
    """Horizontal length, along-axis unit vector and left normal of segment a->b."""
    d = np.asarray(b[:2], float) - np.asarray(a[:2], float)
    length = float(np.hypot(d[0], d[1]))
    u = d / length if length > 1e-9 else np.array([1.0, 0.0])
    return length, u, np.array([-u[1], u[0]])


def tunnel_roof(lateral: np.ndarray, width_m: float, height_m: float) -> np.ndarray:
    """Height above the floor of an arched tunnel roof at a lateral offset from the axis."""
    rise = min(TUNNEL_ARCH_RISE * width_m, 0.5 * height_m)
    q = np.clip(1.0 - (2.0 * lateral / width_m) ** 2, 0.0, 1.0)
    return (height_m - rise) + rise * np.sqrt(q)


def landing_floor(along_m: np.ndarray, length_m: float, z_a: float, z_b: float,
                  landing_m: float) -> np.ndarray:
    """Floor height ``along_m`` metres from a along a passage from a to b that is flat
    for ``landing_m`` at each end and climbs evenly in between.

    The landings keep a climbing passage's floor level where the flat floors of
    the other passages at its junctions reach into it: free space is the union
    of the carved shapes, so without them a junction's flat floor would end in
    a step as high as the climb over half a tunnel width.
    """
    climb = length_m - 2.0 * landing_m
    if z_a == z_b:
        return np.full(np.shape(along_m), float(z_a))
    if climb <= 1e-9:
        raise ValueError(f"a passage {length_m:.1f} m long cannot climb between "
                         f"{landing_m:.1f} m landings")
    return z_a + (z_b - z_a) * np.clip((along_m - landing_m) / climb, 0.0, 1.0)


def carve_tunnel(canvas: VoxelCanvas, a, b, width_m: float, height_m: float,
                 landing_m: float = 0.0) -> None:
    """Carve a straight mine tunnel between floor points a and b.

    The floor is level across the tunnel and along it flat for ``landing_m``
    at each end, climbing evenly in between (:func:`landing_floor`); the walls
    are vertical and the roof an elliptic arch. The tunnel ends flush at a and
    b; junction chambers round the ends off.
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    length, u, n = horizontal_frame(a, b)
    if length < 1e-9:
        return
    half = 0.5 * width_m
    lo = np.minimum(a, b) - [half, half, 0.0]
    hi = np.maximum(a, b) + [half, half, height_m]
    win = canvas.window(lo, hi)
    if win is None:
        return
    sl, xs, ys, zs = win
    x, y = xs - a[0], ys - a[1]
    along = x * u[0] + y * u[1]
    lat = x * n[0] + y * n[1]
    ok = (along >= 0.0) & (along <= length) & (np.abs(lat) <= half)
    floor = landing_floor(along, length, a[2], b[2], landing_m)
    roof = floor + tunnel_roof(lat, width_m, height_m)
    canvas.free[sl] |= ok[..., None] & (zs >= floor[..., None]) & (zs <= roof[..., None])


def carve_chamber(canvas: VoxelCanvas, centre, radius_m: float, height_m: float,
                  upward: list[tuple[np.ndarray, float]] = (), landing_m: float = 0.0) -> None:
    """Carve a round junction chamber with a domed roof around floor point ``centre``.

    ``upward`` lists (horizontal unit direction, slope) of the passages that
    climb away from the junction after a flat ``landing_m``: beyond it the
    chamber floor rises with them so that the junction has no step or pit.
    """
    c = np.asarray(centre, float)
    max_rise = max([s * max(radius_m - landing_m, 0.0) for _, s in upward], default=0.0)
    lo = c - [radius_m, radius_m, 0.0]
    hi = c + [radius_m, radius_m, max_rise + height_m]
    win = canvas.window(lo, hi)
    if win is None:
        return
    sl, xs, ys, zs = win
    x, y = xs - c[0], ys - c[1]
    d = np.sqrt(x * x + y * y)
    rise = np.zeros(np.broadcast_shapes(x.shape, y.shape))
    for u, s in upward:
        rise = np.maximum(rise, s * (x * u[0] + y * u[1] - landing_m))
    floor = c[2] + rise
    roof = floor + tunnel_roof(d, 2.0 * radius_m, height_m)
    ok = d <= radius_m
    canvas.free[sl] |= ok[..., None] & (zs >= floor[..., None]) & (zs <= roof[..., None])


def carve_shaft(canvas: VoxelCanvas, centre_xy, radius_m: float, z0: float, z1: float) -> None:
    """Carve a vertical cylindrical shaft of the given radius from z0 up to z1."""
    cx, cy = float(centre_xy[0]), float(centre_xy[1])
    win = canvas.window([cx - radius_m, cy - radius_m, z0], [cx + radius_m, cy + radius_m, z1])
    if win is None:
        return
    sl, xs, ys, zs = win
    ok = (xs - cx) ** 2 + (ys - cy) ** 2 <= radius_m ** 2
    canvas.free[sl] |= ok[..., None] & (zs >= z0) & (zs <= z1)


def cave_section_top(height_m: float) -> float:
    """Height of a cave passage's ceiling above its flat floor (at most, with shape noise)."""
    b = height_m / (1.0 + CAVE_FLOOR_CUT)
    return CAVE_FLOOR_CUT * b + b * 1.3


def carve_cave_segment(canvas: VoxelCanvas, a, b, width_a: float, width_b: float,
                       height_a: float, height_b: float,
                       shape_a: np.ndarray, shape_b: np.ndarray,
                       cap_rise: tuple[float, float] = (0.0, 0.0)) -> None:
    """Carve one piece of a natural cave passage between floor points a and b.

    The cross-section is an ellipse (semi-axes width/2 and height/1.6) whose
    radius is modulated by harmonics of the angle around the axis
    (``shape`` rows are (cos, sin) amplitudes of harmonics 1, 2, 3), with the
    bottom cut flat at the floor. Width, height and shape vary linearly from
    a to b; beyond the ends the section is swept round into a rounded cap, so
    consecutive segments join smoothly. The cap's floor rises away from the end
    at ``cap_rise`` (slopes beyond a and beyond b): free space is the union of
    the segments, so where another segment goes on from an end and climbs, a cap
    with a level floor would undercut it and leave a step where the cap ends
    (give 0 at a dead end, whose cap would become a steep bowl).
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    length, u, n = horizontal_frame(a, b)
    reach = 0.5 * max(width_a, width_b) * 1.3
    top = max(cave_section_top(height_a), cave_section_top(height_b))
    lo = np.minimum(a, b) - [reach, reach, 0.0]
    hi = np.maximum(a, b) + [reach, reach, top]
    win = canvas.window(lo, hi)
    if win is None:
        return
    sl, xs, ys, zs = win
    x, y = xs - a[0], ys - a[1]
    along = x * u[0] + y * u[1]
    t = np.clip(along / length, 0.0, 1.0) if length > 1e-9 else np.zeros_like(along)
    beyond = along - t * length
    lat = x * n[0] + y * n[1]
    radial = np.where(lat < 0, -1.0, 1.0) * np.sqrt(lat * lat + beyond * beyond)
    half_w = 0.5 * (width_a + t * (width_b - width_a))
    semi_v = (height_a + t * (height_b - height_a)) / (1.0 + CAVE_FLOOR_CUT)
    floor = a[2] + t * (b[2] - a[2])
    centre_z = floor + CAVE_FLOOR_CUT * semi_v
    U = (radial / half_w)[..., None]
    V = (zs - centre_z[..., None]) / semi_v[..., None]
    rho = np.sqrt(U * U + V * V)
    inv = 1.0 / np.maximum(rho, 1e-9)
    c, s = U * inv, V * inv
    coef = [(shape_a[k] + t[..., None] * (shape_b[k] - shape_a[k])) for k in range(3)]
    cos2, sin2 = 2 * c * c - 1, 2 * s * c
    cos3, sin3 = c * (4 * c * c - 3), s * (3 - 4 * s * s)
    r = (1.0 + coef[0][..., 0, None] * c + coef[0][..., 1, None] * s
         + coef[1][..., 0, None] * cos2 + coef[1][..., 1, None] * sin2
         + coef[2][..., 0, None] * cos3 + coef[2][..., 1, None] * sin3)
    cut = floor + np.where(beyond < 0.0, cap_rise[0], cap_rise[1]) * np.abs(beyond)
    canvas.free[sl] |= (rho <= r) & (zs >= cut[..., None])


# --------------------------------------------------------------- clearances
def slab(x: float, y: float, radius_m: float, z_lo: float, z_hi: float) -> np.ndarray:
    """One clearance sample: a vertical cylinder (x, y, radius, z_lo, z_hi) as a (1, 5) array."""
    return np.array([[x, y, radius_m, z_lo, z_hi]], dtype=float)


def segment_slabs(a, b, radius_m: float, height_m: float, step_m: float = 1.0,
                  landing_m: float = 0.0) -> np.ndarray:
    """Clearance samples along a passage from floor point a to b (floor to roof), its
    floor flat for ``landing_m`` at each end (:func:`landing_floor`)."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    length = float(np.linalg.norm(b[:2] - a[:2]))
    n = max(int(np.ceil(length / step_m)), 1) + 1
    t = np.linspace(0.0, 1.0, n)
    p = a + t[:, None] * (b - a)
    floor = landing_floor(t * length, length, a[2], b[2], landing_m) if landing_m > 0 else p[:, 2]
    return np.column_stack([p[:, 0], p[:, 1], np.full(n, radius_m), floor, floor + height_m])


def slabs_conflict(s1: np.ndarray, s2: np.ndarray, clearance_m: float) -> bool:
    """True when two sets of clearance samples come closer than ``clearance_m`` of rock."""
    if len(s1) == 0 or len(s2) == 0:
        return False
    dx = s1[:, None, 0] - s2[None, :, 0]
    dy = s1[:, None, 1] - s2[None, :, 1]
    near = np.sqrt(dx * dx + dy * dy) < s1[:, None, 2] + s2[None, :, 2] + clearance_m
    over = ((s1[:, None, 3] < s2[None, :, 4] + clearance_m)
            & (s2[None, :, 3] < s1[:, None, 4] + clearance_m))
    return bool(np.any(near & over))


# --------------------------------------------------------------------- mesh
def free_space_mesh(free: np.ndarray, origin: np.ndarray, voxel_size_m: float,
                    *, sigma_voxels: float = MESH_SMOOTHING_SIGMA_VOXELS,
                    level: float = MESH_ISO_LEVEL,
                    max_triangles: int = MESH_MAX_TRIANGLES) -> o3d.geometry.TriangleMesh:
    """Rock surface around the free voxels, as a closed legacy open3d mesh in world coordinates.

    Marching cubes (skimage) at ``level`` of a field that is 1 in free voxels
    and, in rock voxels, the Gaussian-smoothed free grid capped at
    MESH_ROCK_CAP; padded with rock so the surface closes. The surface thus
    lies between free and rock voxel centres, on the rock side of each voxel
    face; its normals point into free space.
    Decimated (quadric) when it has more than ``max_triangles`` triangles.
    """
    free = np.asarray(free, dtype=bool)
    mesh = o3d.geometry.TriangleMesh()
    if not free.any():
        return mesh
    pad = int(np.ceil(4 * sigma_voxels)) + 2
    nz = np.nonzero(free.any(axis=(1, 2)))[0], np.nonzero(free.any(axis=(0, 2)))[0], \
        np.nonzero(free.any(axis=(0, 1)))[0]
    lo = np.array([a[0] for a in nz])
    hi = np.array([a[-1] + 1 for a in nz])
    if not 0.0 <= MESH_ROCK_CAP < level < 1.0:
        raise ValueError(f"mesh iso level {level} must lie in ({MESH_ROCK_CAP}, 1)")
    # Padded as bool, and the smoothed field capped and set to 1 in place: two float32
    # grids at most (the field and its smoothing), not four.
    padded = np.pad(free[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]], pad)
    field_ = padded.astype(np.float32)
    if sigma_voxels > 0:
        field_ = ndimage.gaussian_filter(field_, sigma_voxels, mode="constant", cval=0.0)
        np.minimum(field_, np.float32(MESH_ROCK_CAP), out=field_)
        field_[padded] = np.float32(1.0)
    del padded
    verts, faces, _, _ = measure.marching_cubes(field_, level, gradient_direction="descent",
                                                allow_degenerate=True)
    verts = (np.asarray(origin, float)
             + (verts.astype(np.float64) + (lo - pad) + 0.5) * voxel_size_m)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                     o3d.utility.Vector3iVector(faces.astype(np.int32)))
    mesh.remove_degenerate_triangles()
    mesh.remove_unreferenced_vertices()
    if len(mesh.triangles) > max_triangles:
        mesh = mesh.simplify_quadric_decimation(int(max_triangles))
    mesh.compute_vertex_normals()
    return mesh


# -------------------------------------------------------------- helpers
def snap_height(z: float, v: float) -> float:
    """Round a height to the voxel grid (so flat floors lie on voxel faces)."""
    return round(z / v) * v


def snap_toward_zero(dz: float, v: float) -> float:
    """A height change rounded to the voxel grid without growing in magnitude."""
    return math.copysign(math.floor(abs(dz) / v + 1e-9) * v, dz)


def assemble_world(name: str, canvas: VoxelCanvas, graph: nx.Graph,
                   start_floor: np.ndarray) -> World:
    """Mesh the carved canvas and assemble the World with a start on the floor."""
    mesh = free_space_mesh(canvas.free, canvas.origin, canvas.voxel_size_m)
    world = World(name=name, voxel_size_m=canvas.voxel_size_m, origin=canvas.origin,
                  free=canvas.free, mesh=mesh, centreline=graph, start=start_floor)
    probe = np.asarray(start_floor, float) + [0.0, 0.0, 0.5]
    ground = world.ground_height(probe[None], 1.5)[0]
    z = ground if np.isfinite(ground) else start_floor[2]
    world.start = np.array([start_floor[0], start_floor[1], z + START_ABOVE_FLOOR_M])
    return world
