"""Reading the geometry of a world file: triangle meshes, point clouds, Gazebo models.

:func:`read_geometry` gives a :class:`Geometry` (vertices in the file's units and
axes, triangles or none, and what the file itself says of its up axis and unit),
whatever the format:

========================  ==========================  ============================
suffix                    read by                     up axis / unit from the file
========================  ==========================  ============================
.ply .obj .stl (mesh)     open3d                      none (z up unless told)
.dae (Collada)            trimesh + pycollada         ``<up_axis>`` (Y_UP when
                                                      absent), ``<unit meter=>``
.gltf .glb                trimesh                     y up, metres (the glTF spec)
.ply (no faces) .pcd      open3d (point cloud)        none
.xyz .xyzn .xyzrgb .pts
.npy                      numpy: (N, >=3) array       none
.sdf, a model folder      this module (SDF's          z up, as in Gazebo (which
                          ``<collision>`` meshes)     ignores ``<up_axis>``);
                                                      ``<scale>``, ``<pose>``
========================  ==========================  ============================

Nothing here voxelises or rotates: see :mod:`delve.sim.worldfile`.
"""
from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import open3d as o3d

from .meshio import native_output_silenced, read_mesh

#: Mesh formats read by open3d (as the closed-mesh loader always has) and by trimesh.
OPEN3D_MESH_SUFFIXES = (".ply", ".obj", ".stl")
TRIMESH_SUFFIXES = {".dae": "Collada", ".gltf": "glTF", ".glb": "glTF"}
#: Point-cloud formats (a PLY without faces is one too).
POINT_SUFFIXES = (".pcd", ".xyz", ".xyzn", ".xyzrgb", ".pts", ".npy")
#: A Gazebo model: an SDF file, or a folder holding model.sdf.
SDF_SUFFIXES = (".sdf",)
WORLD_FILE_SUFFIXES = OPEN3D_MESH_SUFFIXES + tuple(TRIMESH_SUFFIXES) + POINT_SUFFIXES + SDF_SUFFIXES
#: What glTF's specification fixes: +y up, metres.
GLTF_UP_AXIS = "y"
#: Collada's <up_axis> values, and the default when the header has none (the spec's).
COLLADA_UP_AXES = {"X_UP": "x", "Y_UP": "y", "Z_UP": "z"}
COLLADA_DEFAULT_UP = "y"


@dataclass
class Geometry:
    """A world file's geometry as the file has it.

    Fields:
        vertices: (N, 3) float64 points in the file's units and axes.
        triangles: (M, 3) int32 vertex indices, or None for a point cloud.
        format: a name for messages ("Collada", "PLY point cloud", ...).
        up_axis: the up axis the file declares ("x", "y", "z"), or None when the
            format does not say.
        unit_m: metres per file unit where the file says (Collada), else None.
        mesh: the open3d mesh as read (PLY / OBJ / STL), so that a closed mesh takes
            exactly the path it always took; None otherwise.
    """

    vertices: np.ndarray
    triangles: np.ndarray | None
    format: str
    up_axis: str | None = None
    unit_m: float | None = None
    mesh: o3d.geometry.TriangleMesh | None = None

    @property
    def is_points(self) -> bool:
        return self.triangles is None


def read_geometry(path: str | Path) -> Geometry:
    """The geometry of a mesh, point-cloud or Gazebo model file (see the module table).

    ValueError, naming only the file, when it is absent, of an unknown kind, broken
    or empty."""
    path = Path(path)
    if path.is_dir():
        sdf = path / "model.sdf"
        if not sdf.is_file():
            raise ValueError(f"world file '{path.name}' is a folder without model.sdf (a Gazebo model folder "
                             f"holds one)")
        return read_sdf_model(sdf)
    suffix = path.suffix.lower()
    if not path.is_file():
        raise ValueError(f"cannot read world file '{path.name}': no such file")
    if suffix not in WORLD_FILE_SUFFIXES:
        raise ValueError(f"cannot read world file '{path.name}': unknown kind {suffix or '(no suffix)'!r} "
                         f"(meshes: .dae .gltf .glb .obj .stl .ply; point clouds: .pcd .ply .xyz .npy; "
                         f"Gazebo: .sdf or a model folder)")
    if suffix in SDF_SUFFIXES:
        return read_sdf_model(path)
    if suffix in TRIMESH_SUFFIXES:
        return _read_with_trimesh(path, TRIMESH_SUFFIXES[suffix])
    if suffix in OPEN3D_MESH_SUFFIXES:
        if suffix == ".ply" and not _ply_has_faces(path):
            return _read_points(path)
        mesh = read_mesh(path)
        return Geometry(np.asarray(mesh.vertices, dtype=np.float64),
                        np.asarray(mesh.triangles, dtype=np.int32), suffix.lstrip(".").upper(), mesh=mesh)
    return _read_points(path)


def _ply_has_faces(path: Path) -> bool:
    """Whether a PLY file's header declares faces (else it is a point cloud)."""
    with path.open("rb") as f:
        for _ in range(200):
            line = f.readline()
            if not line or line.strip() == b"end_header":
                break
            words = line.split()
            if len(words) == 3 and words[0] == b"element" and words[1] == b"face":
                return words[2] != b"0"
    return False


def _why(err: Exception, fmt: str) -> str:
    """Why a reader failed, in words that quote nothing of the file (a reader's own
    message may): where XML stops being well-formed, else that the file is broken or
    not of its kind, with the reader's exception's name."""
    if isinstance(err, ET.ParseError) and getattr(err, "position", None):
        line, column = err.position
        return f"not well-formed XML at line {line}, column {column + 1}"
    if isinstance(err, OSError) and err.strerror:
        return err.strerror.lower()
    return f"a broken file, or not a {fmt} file ({type(err).__name__} in its reader)"


def _read_with_trimesh(path: Path, fmt: str) -> Geometry:
    import trimesh

    quiet = logging.getLogger("trimesh")
    level = quiet.level
    quiet.setLevel(logging.ERROR)
    try:
        scene = trimesh.load(str(path), force="scene", process=False)
        meshes = [g for g in scene.dump() if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    except Exception as err:   # noqa: BLE001 - any reader failure is the file's fault
        raise ValueError(f"cannot read {fmt} file '{path.name}': {_why(err, fmt)}") from None
    finally:
        quiet.setLevel(level)
    if not meshes:
        raise ValueError(f"cannot read {fmt} file '{path.name}': no triangles in it")
    mesh = trimesh.util.concatenate(meshes)
    up, unit = (collada_asset(path) if fmt == "Collada" else (GLTF_UP_AXIS, None))
    return Geometry(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int32), fmt,
                    up_axis=up, unit_m=unit)


def collada_asset(path: Path) -> tuple[str, float | None]:
    """A Collada file's declared up axis ("x", "y", "z"; Y_UP when the header has
    none, as the specification says) and its metres per unit (None when absent).
    Reads the ``<asset>`` element only."""
    up, unit = COLLADA_DEFAULT_UP, None
    try:
        for _, el in ET.iterparse(str(path), events=("end",)):
            tag = el.tag.rsplit("}", 1)[-1]
            if tag == "up_axis" and el.text:
                up = COLLADA_UP_AXES.get(el.text.strip().upper(), up)
            elif tag == "unit":
                try:
                    unit = float(el.get("meter", ""))
                except ValueError:
                    unit = None
                if unit is not None and not (math.isfinite(unit) and unit > 0):
                    unit = None
            elif tag == "asset":
                break
    except ET.ParseError:
        pass
    return up, unit


def _read_points(path: Path) -> Geometry:
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            arr = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as err:
            raise ValueError(f"cannot read point cloud '{path.name}': {_why(err, 'NumPy')}") from None
        if arr.ndim != 2 or arr.shape[1] < 3 or not np.issubdtype(arr.dtype, np.number):
            raise ValueError(f"cannot read point cloud '{path.name}': a .npy world is an (N, 3) array of "
                             f"x, y, z (more columns are ignored), not shape {arr.shape}")
        pts = np.asarray(arr[:, :3], dtype=np.float64)
    else:
        with native_output_silenced():
            pts = np.asarray(o3d.io.read_point_cloud(str(path)).points, dtype=np.float64)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) == 0:
        raise ValueError(f"cannot read point cloud '{path.name}': no points in it (a broken or empty file?)")
    name = {".npy": "NumPy"}.get(suffix, suffix.lstrip(".").upper())
    return Geometry(pts, None, f"{name} point cloud")


# ------------------------------------------------------------------ Gazebo
def read_sdf_model(path: Path) -> Geometry:
    """The collision meshes of a Gazebo model (SDF), each with its ``<scale>`` and the
    ``<pose>`` of its link and collision, as one mesh in the model's frame: z up, and
    a Collada mesh's ``<up_axis>`` ignored, as Gazebo places it. ``model://NAME/...``
    URIs resolve against the model folder and its siblings; a world SDF's ``<include>``s are not followed."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as err:
        raise ValueError(f"cannot read SDF file '{path.name}': {_why(err, 'SDF')}") from None
    parts_v, parts_t, n = [], [], 0
    for link in root.iter("link"):
        link_pose = _sdf_pose(link.find("pose"))
        for col in link.iter("collision"):
            mesh_el = col.find("geometry/mesh")
            uri = mesh_el.findtext("uri") if mesh_el is not None else None
            if not uri:
                continue
            mesh_path = _resolve_model_uri(uri.strip(), path.parent)
            if mesh_path is None:
                raise ValueError(f"SDF file '{path.name}': cannot find the mesh {uri.strip()!r}")
            geo = read_geometry(mesh_path)
            if geo.is_points:
                raise ValueError(f"SDF file '{path.name}': {mesh_path.name} holds no triangles")
            scale = np.array([float(s) for s in (mesh_el.findtext("scale") or "1 1 1").split()] or [1, 1, 1])
            verts = geo.vertices * (geo.unit_m or 1.0) * scale     # Gazebo ignores <up_axis>
            pose = link_pose @ _sdf_pose(col.find("pose"))
            parts_v.append(verts @ pose[:3, :3].T + pose[:3, 3])
            parts_t.append(geo.triangles + n)
            n += len(verts)
    if not parts_v:
        raise ValueError(f"SDF file '{path.name}': no <collision> with a <mesh> in it (delve reads a model's "
                         f"collision meshes; a world's <include>s are not followed)")
    return Geometry(np.concatenate(parts_v), np.concatenate(parts_t).astype(np.int32), "Gazebo SDF",
                    up_axis="z", unit_m=1.0)


def _sdf_pose(el: ET.Element | None) -> np.ndarray:
    """4x4 transform of an SDF ``<pose>x y z roll pitch yaw</pose>`` (identity if absent)."""
    out = np.eye(4)
    if el is None or not (el.text or "").strip():
        return out
    x, y, z, roll, pitch, yaw = ([float(v) for v in el.text.split()] + [0.0] * 6)[:6]
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    out[:3, :3] = np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                            [-sp, cp * sr, cp * cr]])
    out[:3, 3] = (x, y, z)
    return out


def _resolve_model_uri(uri: str, model_dir: Path) -> Path | None:
    """A mesh URI of an SDF in ``model_dir``: ``model://NAME/rest`` (NAME is the model
    folder itself or a sibling of it), ``file://path`` or a relative path."""
    if uri.startswith("model://"):
        name, _, rest = uri[len("model://"):].partition("/")
        for folder in (model_dir if model_dir.name == name else None, model_dir.parent / name, model_dir):
            if folder is not None and (folder / rest).is_file():
                return folder / rest
        return None
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    p = Path(uri)
    p = p if p.is_absolute() else model_dir / p
    return p if p.is_file() else None
