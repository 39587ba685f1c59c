"""Artifacts in worlds: the SubT Final's ten classes, placed by seed or listed.

Ground truth that only the simulator's artifact sensors and the referee read.
:func:`place_artifacts` spreads artifacts over the free space reachable from the
start the way the Final's were (CERBERUS paper, Sections 3.5 and 4.2): in dead
ends, on every level and along the passages from near the entrance to the far
end, on floors and on walls, and gas as a room at a dead end. It works on
procedural worlds (dead ends are the centreline's degree-1 nodes) and on mesh
worlds, whose centreline is empty (dead ends are local maxima of the geodesic
distance from the start). :func:`listed_artifacts` checks explicit positions.

A floor artifact's ``position`` is its centre, half its size above the floor; a
wall artifact's is half its size off the wall along the wall's normal; gas is a
room, its position the room's centre ``ROOM_HEIGHT_M`` above the floor.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from .world import World

#: The SubT Final's artifact classes, exactly these strings.
ARTIFACT_CLASSES = ("survivor", "cell_phone", "backpack", "drill", "fire_extinguisher",
                    "vent", "gas", "helmet", "rope", "cube")
SURFACES = ("floor", "wall", "room")
#: Characteristic sizes (m) of DARPA's artifacts (approximate; not in the paper). Gas:
#: the height of the room it fills, so that its centre is ROOM_HEIGHT_M above the floor.
ARTIFACT_SIZE_M = {"survivor": 1.2, "cell_phone": 0.15, "backpack": 0.5, "drill": 0.3,
                   "fire_extinguisher": 0.6, "vent": 0.6, "gas": 2.0, "helmet": 0.3,
                   "rope": 0.6, "cube": 0.25}
ROOM_HEIGHT_M = ARTIFACT_SIZE_M["gas"] / 2.0
#: Air above a floor site (the centre of every floor artifact, and a robot's view of it).
FLOOR_HEADROOM_M = 1.0
#: Classes always on a wall, classes sometimes on a wall (with ``wall_share``), the room class.
WALL_CLASSES = ("vent",)
WALL_OR_FLOOR_CLASSES = ("fire_extinguisher", "helmet")
ROOM_CLASSES = ("gas",)
_UP = np.array([0.0, 0.0, 1.0])
#: The four sideways neighbours of a voxel (a wall is rock beside free space).
_SIDEWAYS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]])


@dataclass(frozen=True, eq=False)
class Artifact:
    """One artifact (ground truth).

    Fields:
        name: class + index, unique in the world ("backpack_3"); a Bluetooth
            artifact's SSID (see :mod:`delve.sim.artifact_sensors`).
        artifact_class: one of ARTIFACT_CLASSES.
        position: (3,) world metres, the artifact's centre.
        surface: "floor", "wall" or "room" (gas fills a room; position = room centre).
        normal: (3,) unit normal of the surface it sits on ((0, 0, 1) on a floor).
        size_m: characteristic size (for the camera's bounding box).
    """

    name: str
    artifact_class: str
    position: np.ndarray
    surface: str
    normal: np.ndarray
    size_m: float


@dataclass(frozen=True)
class PlacementSpec:
    """How :func:`place_artifacts` spreads artifacts (model choices, not the paper's).

    Fields:
        min_spacing_m: artifacts' centres at least this far apart (twice the 5 m
            scoring radius, so that a report never scores for a neighbour).
        min_start_distance_m: none within this geodesic distance of the start (the
            staging area).
        dead_end_share: share of the artifacts placed at dead ends (gas first).
        dead_end_radius_m: a dead-end artifact lies within this of the dead end.
        wall_share: share of the wall-or-floor classes (fire extinguisher, helmet)
            placed on walls.
        wall_height_m: (low, high) height above the floor of a wall artifact's foot.
        level_height_m: floors are grouped into levels by bands of this height in
            z; every band with floor gets an artifact when there are enough.
        geodesic_cell_m: cell of the coarse grid over which geodesic distances run.
    """

    min_spacing_m: float = 10.0
    min_start_distance_m: float = 10.0
    dead_end_share: float = 0.3
    dead_end_radius_m: float = 4.0
    wall_share: float = 0.5
    wall_height_m: tuple[float, float] = (0.3, 1.5)
    level_height_m: float = 6.0
    geodesic_cell_m: float = 1.0

    def __post_init__(self) -> None:
        for name in ("min_spacing_m", "min_start_distance_m", "dead_end_radius_m",
                     "level_height_m", "geodesic_cell_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0) or (name.endswith("cell_m") and value == 0):
                raise ValueError(f"{name} must be a finite number >= 0 (> 0 for a cell), got {value}")
        for name in ("dead_end_share", "wall_share"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"{name} must lie in [0, 1], got {getattr(self, name)}")
        lo, hi = self.wall_height_m
        if not 0.0 <= lo <= hi:
            raise ValueError(f"wall_height_m must be (low, high) with 0 <= low <= high, got {(lo, hi)}")


# ======================================================== geodesic distance
class GeodesicGrid:
    """Geodesic distances through free space on a coarse grid (26-connected cells).

    A coarse cell of ``cell_m`` is free when any voxel of ``free`` in it is; rock
    thinner than a cell may therefore join two passages. Built once per world and
    free mask; :meth:`distances` runs Dijkstra (scipy.sparse.csgraph) from sources.
    """

    def __init__(self, world: World, free: np.ndarray, cell_m: float) -> None:
        self.world = world
        self.factor = max(int(round(cell_m / world.voxel_size_m)), 1)
        f = self.factor
        pad = [(0, (-n) % f) for n in free.shape]
        grid = np.pad(free, pad)
        cs = tuple(n // f for n in grid.shape)
        coarse = grid.reshape(cs[0], f, cs[1], f, cs[2], f).any(axis=(1, 3, 5))
        self.shape = cs
        self.cells = np.argwhere(coarse)
        self.codes = np.ravel_multi_index(self.cells.T, cs)           # sorted (argwhere order)
        self.centres = world.origin + (self.cells + 0.5) * f * world.voxel_size_m
        rows, cols, weights = [], [], []
        offsets = np.array([o for o in np.ndindex(3, 3, 3)]) - 1
        for off in offsets[len(offsets) // 2 + 1:]:                    # 13 half-offsets
            nb = self.cells + off
            ok = np.all((nb >= 0) & (nb < cs), axis=1)
            j = self._lookup(nb[ok])
            hit = j >= 0
            rows.append(np.flatnonzero(ok)[hit])
            cols.append(j[hit])
            weights.append(np.full(int(hit.sum()), np.linalg.norm(off) * f * world.voxel_size_m))
        r, c, w = (np.concatenate(a) for a in (rows, cols, weights))
        n = len(self.cells)
        self.graph = sparse.coo_matrix((w, (r, c)), shape=(n, n)).tocsr()

    def _lookup(self, cells: np.ndarray) -> np.ndarray:
        """Row of each coarse cell (N, 3) in ``self.cells``, -1 where it is not free."""
        if len(cells) == 0:
            return np.zeros(0, dtype=np.int64)
        code = np.ravel_multi_index(cells.T, self.shape)
        j = np.searchsorted(self.codes, code)
        j = np.minimum(j, len(self.codes) - 1)
        return np.where(self.codes[j] == code, j, -1)

    def cell_of(self, points: np.ndarray) -> np.ndarray:
        """Row (N,) of the coarse cell holding each world point, -1 outside free cells."""
        idx = self.world.to_index(points) // self.factor
        ok = np.all((idx >= 0) & (idx < self.shape), axis=1)
        out = np.full(len(idx), -1, dtype=np.int64)
        out[ok] = self._lookup(idx[ok])
        return out

    def distances(self, sources: np.ndarray, limit_m: float = np.inf) -> np.ndarray:
        """Geodesic distance (m) of every cell from the nearest source point (M, 3)
        (each starts at its cell's centre); inf beyond ``limit_m`` or unconnected."""
        rows = self.cell_of(np.asarray(sources, float).reshape(-1, 3))
        rows = np.unique(rows[rows >= 0])
        if len(rows) == 0:
            return np.full(len(self.cells), np.inf)
        return csgraph.dijkstra(self.graph, directed=False, indices=rows, min_only=True,
                                limit=limit_m)

    def at(self, field: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Value of a per-cell field at world points (inf outside free cells)."""
        rows = self.cell_of(np.asarray(points, float).reshape(-1, 3))
        out = np.full(len(rows), np.inf)
        out[rows >= 0] = field[rows[rows >= 0]]
        return out


# ======================================================== candidate surfaces
@dataclass
class _Pool:
    """Candidate feet on one kind of surface: points (N, 3) on it and its normals."""

    feet: np.ndarray
    normals: np.ndarray

    def positions(self, size_m: float) -> np.ndarray:
        return self.feet + self.normals * (0.5 * size_m)


def _floor_pool(world: World, reach: np.ndarray, headroom_m: float) -> _Pool:
    """Floor voxels (free, rock or the grid's bottom below) with ``headroom_m`` of air above."""
    floor = reach.copy()
    floor[:, :, 1:] &= ~world.free[:, :, :-1]
    head = max(int(math.ceil(headroom_m / world.voxel_size_m)), 1)
    for dz in range(1, head):
        floor[:, :, :-dz] &= world.free[:, :, dz:]
        floor[:, :, -dz:] = False
    idx = np.argwhere(floor)
    feet = world.index_to_center(idx)
    feet[:, 2] -= 0.5 * world.voxel_size_m
    return _Pool(feet, np.broadcast_to(_UP, feet.shape).copy())


def _wall_pool(world: World, reach: np.ndarray, height_m: tuple[float, float],
               clearance_m: float) -> _Pool:
    """Free voxels beside rock (sideways) whose centre is ``height_m`` above the ground;
    the foot is on the wall, the normal (horizontal) points into free space, and
    ``clearance_m`` of air lies in front of the foot along it."""
    v = world.voxel_size_m
    free = world.free
    side_rock = np.zeros(reach.shape + (4,), dtype=bool)
    padded = np.pad(free, 1, constant_values=False)
    nx_, ny_, nz_ = free.shape
    for n, (di, dj, _) in enumerate(_SIDEWAYS):
        side_rock[..., n] = ~padded[1 + di:1 + di + nx_, 1 + dj:1 + dj + ny_, 1:1 + nz_]
    wall = reach & side_rock.any(axis=3)
    idx = np.argwhere(wall)
    if len(idx) == 0:
        return _Pool(np.zeros((0, 3)), np.zeros((0, 3)))
    rock = side_rock[idx[:, 0], idx[:, 1], idx[:, 2]].astype(float)       # (N, 4)
    normal = -(rock @ _SIDEWAYS.astype(float))
    norm = np.linalg.norm(normal, axis=1)
    centres = world.index_to_center(idx)
    ground = world.ground_height(centres, height_m[1] + v)
    above = centres[:, 2] - ground
    ok = (norm > 0) & (above >= height_m[0]) & (above <= height_m[1])
    normal = normal[ok] / norm[ok, None]
    feet = centres[ok] - normal * (0.5 * v)
    clear = world.is_free(feet + normal * (0.5 * v + clearance_m))
    return _Pool(feet[clear], normal[clear])


def _dead_ends(world: World, grid: GeodesicGrid, from_start: np.ndarray, radius_m: float,
               min_start_m: float) -> np.ndarray:
    """Dead ends (M, 3): the centreline's degree-1 nodes, or (no centreline) the cells
    whose geodesic distance from the start no cell of the same passage within
    2 ``radius_m`` exceeds (farther than a bend's outer corner reaches)."""
    g = world.centreline
    if g.number_of_nodes():
        pts = [np.asarray(g.nodes[n]["pos"], float) for n in sorted(g.nodes) if g.degree(n) == 1]
        pts = np.array(pts).reshape(-1, 3)
        return pts[grid.at(from_start, pts) >= min_start_m]
    finite = np.flatnonzero(np.isfinite(from_start) & (from_start >= min_start_m))
    if len(finite) == 0:
        return np.zeros((0, 3))
    d = from_start[finite]
    tree = cKDTree(grid.centres[finite])
    pairs = tree.query_pairs(2.0 * radius_m, output_type="ndarray")
    beaten = np.zeros(len(finite), dtype=bool)
    if len(pairs):
        a, b = pairs[:, 0], pairs[:, 1]
        same = np.abs(d[a] - d[b]) <= 4.0 * radius_m       # the same passage, not a parallel one
        beaten[a[same & (d[b] > d[a])]] = True
        beaten[b[same & (d[a] > d[b])]] = True
        tie = same & (d[a] == d[b])
        beaten[np.maximum(a[tie], b[tie])] = True           # a plateau keeps one cell
    return grid.centres[finite[~beaten]]


# ============================================================== placement
def _class_list(count: int, classes: tuple[str, ...], rng: np.random.Generator) -> list[str]:
    """``count`` classes drawn evenly: each class count // len times, the rest by draw."""
    out = list(classes) * (count // len(classes))
    out += list(rng.choice(classes, size=count % len(classes), replace=False))
    return [str(c) for c in rng.permutation(out)]


def _surface(cls: str, wall_share: float, rng: np.random.Generator) -> str:
    if cls in ROOM_CLASSES:
        return "room"
    if cls in WALL_CLASSES or (cls in WALL_OR_FLOOR_CLASSES and rng.random() < wall_share):
        return "wall"
    return "floor"


def check_classes(classes) -> tuple[str, ...]:
    """The classes as a tuple; ValueError naming an unknown one."""
    out = tuple(str(c) for c in classes)
    for c in out:
        if c not in ARTIFACT_CLASSES:
            raise ValueError(f"unknown artifact class {c!r}{_did_you_mean(c)}")
    if not out:
        raise ValueError("classes must name at least one artifact class")
    return out


def _did_you_mean(name: str) -> str:
    close = difflib.get_close_matches(name, ARTIFACT_CLASSES, n=1)
    return f" (did you mean {close[0]!r}?)" if close else f" (classes: {', '.join(ARTIFACT_CLASSES)})"


class _Placer:
    """Picks artifact sites one at a time, keeping every pick min_spacing_m from the others."""

    def __init__(self, world: World, pools: dict[str, _Pool], grid: GeodesicGrid,
                 from_start: np.ndarray, spec: PlacementSpec, rng: np.random.Generator) -> None:
        self.world, self.pools, self.spec, self.rng = world, pools, spec, rng
        self.geo = {s: grid.at(from_start, p.feet) for s, p in pools.items()}
        self.eligible = {s: np.isfinite(g) & (g >= spec.min_start_distance_m)
                         for s, g in self.geo.items()}
        self.margin = 0.5 * max(ARTIFACT_SIZE_M.values())
        self.placed: list[Artifact] = []

    def free_positions(self, surface: str, cls: str) -> np.ndarray:
        """(N,) bool: the pool's candidates whose artifact centre lies in free space."""
        return self.world.is_free(self.pools[surface].positions(ARTIFACT_SIZE_M[cls]))

    def pick(self, cls: str, surface: str, where: np.ndarray | None) -> Artifact | None:
        """Place one ``cls`` on ``surface`` at a random eligible candidate (within
        ``where`` if given and possible); None when no candidate is left."""
        pool = self.pools[surface]
        ok = self.eligible[surface] & self.free_positions(surface, cls)
        if where is not None and (ok & where).any():
            ok = ok & where
        if not ok.any():
            return None
        i = int(self.rng.choice(np.flatnonzero(ok)))
        size = ARTIFACT_SIZE_M[cls]
        position = pool.positions(size)[i]
        index = sum(a.artifact_class == cls for a in self.placed) + 1
        art = Artifact(name=f"{cls}_{index}", artifact_class=cls, position=position,
                       surface=surface, normal=pool.normals[i].copy(), size_m=size)
        self.placed.append(art)
        for s, p in self.pools.items():
            far = np.linalg.norm(p.feet - position, axis=1) >= self.spec.min_spacing_m + self.margin
            self.eligible[s] &= far
        return art

    def capacity(self) -> int:
        """How many more floor artifacts would fit (greedy, on a copy of the state)."""
        eligible = self.eligible["floor"].copy()
        feet = self.pools["floor"].feet
        n = 0
        while eligible.any():
            i = int(np.flatnonzero(eligible)[0])
            eligible &= np.linalg.norm(feet - feet[i], axis=1) >= self.spec.min_spacing_m + self.margin
            n += 1
        return n


def place_artifacts(world: World, *, count: int, classes=ARTIFACT_CLASSES, seed: int,
                    start=None, spec: PlacementSpec | None = None) -> list[Artifact]:
    """``count`` artifacts spread over the free space reachable from ``start`` (default:
    the world's start), deterministic for ``seed``.

    Classes are drawn evenly from ``classes`` (each ``count // len`` times, the rest
    by draw). Sites, in this order: dead ends (``dead_end_share``, gas first; gas is a
    room there), one on each level (z band) not yet holding one, then one per
    stratum of geodesic distance from the start (equal shares of the floor), each a
    random candidate at least ``min_spacing_m`` from the others. Vents go on walls,
    fire extinguishers and helmets on walls with ``wall_share``, the rest on floors.
    ValueError for an unknown class, count < 0, or when the world cannot hold
    ``count`` artifacts ``min_spacing_m`` apart (the message says how many fit).
    """
    spec = spec if spec is not None else PlacementSpec()
    classes = check_classes(classes)
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 0:
        raise ValueError(f"count must be an integer >= 0, got {count!r}")
    start = world.start if start is None else np.asarray(start, float).reshape(3)
    rng = np.random.default_rng(seed)
    reach = world.reachable_free(start)
    grid = GeodesicGrid(world, reach, spec.geodesic_cell_m)
    from_start = grid.distances(start[None])
    pools = {"floor": _floor_pool(world, reach, FLOOR_HEADROOM_M)}
    pools["room"] = pools["floor"]
    pools["wall"] = _wall_pool(world, reach, spec.wall_height_m, 0.5 * max(ARTIFACT_SIZE_M.values()))
    placer = _Placer(world, pools, grid, from_start, spec, rng)

    cls_list = _class_list(count, classes, rng)
    surfaces = [_surface(c, spec.wall_share, rng) for c in cls_list]
    surfaces = [s if len(pools[s].feet) else "floor" for s in surfaces]
    order = sorted(range(count), key=lambda k: surfaces[k] != "room")     # gas slots first
    todo = list(order)

    def place(k: int, where: np.ndarray | None) -> None:
        art = placer.pick(cls_list[k], surfaces[k], where)
        if art is None and surfaces[k] == "wall":              # walls used up: the floor then
            surfaces[k] = "floor"
            art = placer.pick(cls_list[k], "floor", None)
        if art is None:
            fit = len(placer.placed) + placer.capacity()
            raise ValueError(f"world {world.name!r} can hold only {fit} of the {count} artifacts "
                             f"{spec.min_spacing_m:g} m apart (and {spec.min_start_distance_m:g} m "
                             f"from the start): lower count or min_spacing_m")
        todo.remove(k)

    # 1. dead ends
    ends = _dead_ends(world, grid, from_start, spec.dead_end_radius_m, spec.min_start_distance_m)
    feet = pools["floor"].feet
    if len(ends) and len(feet):
        ends = feet[cKDTree(feet).query(ends)[1]]            # onto the floor
    ends = ends[rng.permutation(len(ends))]
    n_dead = min(len(ends), max(int(math.ceil(spec.dead_end_share * count)),
                                sum(s == "room" for s in surfaces)))
    for end in ends[:n_dead]:
        if not todo:
            break
        k = todo[0]
        near = np.linalg.norm(pools[surfaces[k]].feet - end, axis=1) <= spec.dead_end_radius_m
        place(k, near)
    # 2. every level
    z0 = feet[:, 2].min() if len(feet) else 0.0

    def band(pts: np.ndarray) -> np.ndarray:
        return np.floor((pts[:, 2] - z0) / spec.level_height_m).astype(int)

    reachable_bands = np.unique(band(feet[placer.eligible["floor"]]))
    for b in rng.permutation(reachable_bands):
        if not todo:
            break
        if any(band(a.position[None] - a.normal[None] * 0.5 * a.size_m)[0] == b for a in placer.placed):
            continue
        k = todo[0]
        place(k, band(pools[surfaces[k]].feet) == b)
    # 3. strata of geodesic distance from the start
    if todo:
        g = placer.geo["floor"][placer.eligible["floor"]]
        edges = np.quantile(g, np.linspace(0.0, 1.0, len(todo) + 1)) if len(g) else np.zeros(len(todo) + 1)
        for lo, hi in zip(edges[:-1], edges[1:]):
            k = todo[0]
            geo = placer.geo[surfaces[k]]
            place(k, (geo >= lo) & (geo <= hi))
    return placer.placed


# ======================================================== listed artifacts
def _nearest_free(world: World, point: np.ndarray) -> np.ndarray | None:
    """Centre of the free voxel nearest to ``point`` (searching ever larger boxes)."""
    v = world.voxel_size_m
    centre = world.to_index(point)[0]
    for r_m in (2.0, 8.0, 32.0, float(np.max(world.bounds_max - world.bounds_min))):
        r = int(math.ceil(r_m / v))
        lo = np.maximum(centre - r, 0)
        hi = np.minimum(centre + r + 1, world.shape)
        if np.any(hi <= lo):
            continue
        idx = np.argwhere(world.free[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]) + lo
        if len(idx):
            pts = world.index_to_center(idx)
            return pts[int(np.argmin(np.linalg.norm(pts - point, axis=1)))]
    return None


def surface_normal(world: World, point: np.ndarray, surface: str) -> np.ndarray:
    """Unit normal of ``surface`` at ``point``: up on a floor and in a room; on a wall the
    horizontal direction away from the rock voxels within two voxels (up if none)."""
    if surface != "wall":
        return _UP.copy()
    c = world.to_index(point)[0]
    off = np.array(list(np.ndindex(5, 5, 5))) - 2
    idx = c + off
    inside = world.in_bounds(idx)
    rock = np.ones(len(idx), dtype=bool)
    rock[inside] = ~world.free[idx[inside, 0], idx[inside, 1], idx[inside, 2]]
    n = -off[rock].sum(axis=0).astype(float)
    n[2] = 0.0
    norm = np.linalg.norm(n)
    return n / norm if norm > 0 else _UP.copy()


def listed_artifacts(world: World, items: list[dict]) -> list[Artifact]:
    """Artifacts at explicit positions: ``items`` are ``{class, position, [surface]}``.

    The surface defaults to "room" for gas and "floor" otherwise ("wall" for a vent);
    gas must be a room and only gas may be. ValueError with a one-line message naming
    ``artifacts[i]`` for an unknown class or surface, a position that is not three
    numbers, outside the world or in rock (with the nearest free point).
    """
    out: list[Artifact] = []
    for i, item in enumerate(items):
        where = f"artifacts[{i}]"
        if not isinstance(item, dict):
            raise ValueError(f"{where}: expected a mapping with class and position, got {item!r}")
        cls = item.get("class")
        if cls not in ARTIFACT_CLASSES:
            raise ValueError(f"{where}: unknown artifact class {cls!r}{_did_you_mean(str(cls))}")
        try:
            p = np.asarray(item.get("position"), dtype=float).reshape(3)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: position must be three numbers [x, y, z], "
                             f"got {item.get('position')!r}") from None
        if not np.all(np.isfinite(p)):
            raise ValueError(f"{where}: position must be finite, got {p.tolist()}")
        default = "room" if cls in ROOM_CLASSES else "wall" if cls in WALL_CLASSES else "floor"
        surface = item.get("surface", default)
        if surface not in SURFACES:
            raise ValueError(f"{where}: unknown surface {surface!r} (surfaces: {', '.join(SURFACES)})")
        if (surface == "room") != (cls in ROOM_CLASSES):
            raise ValueError(f"{where}: {'gas must be a room' if cls in ROOM_CLASSES else 'only gas is a room'}")
        lo, hi = world.bounds_min, world.bounds_max
        if np.any(p < lo) or np.any(p >= hi):
            raise ValueError(f"{where}: position {np.round(p, 2).tolist()} is outside the world "
                             f"(x {lo[0]:.1f}..{hi[0]:.1f}, y {lo[1]:.1f}..{hi[1]:.1f}, "
                             f"z {lo[2]:.1f}..{hi[2]:.1f})")
        if not world.is_free(p[None])[0]:
            near = _nearest_free(world, p)
            hint = "" if near is None else (f"; nearest free point [{near[0]:.1f}, {near[1]:.1f}, "
                                            f"{near[2]:.1f}], {np.linalg.norm(near - p):.1f} m away")
            raise ValueError(f"{where}: position {np.round(p, 2).tolist()} is in rock{hint}")
        index = sum(a.artifact_class == cls for a in out) + 1
        out.append(Artifact(name=f"{cls}_{index}", artifact_class=cls, position=p, surface=surface,
                            normal=surface_normal(world, p, surface), size_m=ARTIFACT_SIZE_M[cls]))
    return out
