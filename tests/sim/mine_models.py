"""Small world files of the kinds users bring, made with trimesh in the tests: a
closed corridor, a slab-and-wall corridor (Gazebo style), an open one (bare floor and
wall sheets), a corridor's point cloud. Corridors run along x from 0 to LENGTH, are
WIDTH wide (y from -WIDTH/2) and HEIGHT high, floor at z = 0."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

LENGTH, WIDTH, HEIGHT = 10.0, 4.0, 3.0
WALL, SLAB = 0.3, 0.3


def box(size, centre) -> trimesh.Trimesh:
    return trimesh.creation.box(size, trimesh.transformations.translation_matrix(centre))


def closed_corridor(length=LENGTH, width=WIDTH, height=HEIGHT) -> trimesh.Trimesh:
    """The inner surface of a closed corridor: a box with its faces turned inwards."""
    mesh = box((length, width, height), (length / 2, 0.0, height / 2))
    mesh.invert()
    return mesh


def slab_and_wall(length=LENGTH, width=WIDTH, height=HEIGHT, wall=WALL, slab=SLAB,
                  dead_end: bool = False) -> trimesh.Trimesh:
    """A floor slab and two wall boxes standing on it, no ceiling; ends open, or at
    x = 0 a wall across (``dead_end``)."""
    parts = [box((length, width + 2 * wall, slab), (length / 2, 0.0, -slab / 2))]
    for side in (-1, 1):
        parts.append(box((length, wall, height), (length / 2, side * (width + wall) / 2, height / 2)))
    if dead_end:
        parts.append(box((wall, width, height), (-wall / 2, 0.0, height / 2)))
    return trimesh.util.concatenate(parts)


def open_corridor(length=LENGTH, width=WIDTH, height=HEIGHT) -> trimesh.Trimesh:
    """A floor sheet and two wall sheets (no thickness, so open: boundary edges)."""
    def quad(corners):
        return trimesh.Trimesh(np.array(corners, float), [[0, 1, 2], [0, 2, 3]], process=False)

    w = width / 2
    return trimesh.util.concatenate([
        quad([(0, -w, 0), (length, -w, 0), (length, w, 0), (0, w, 0)]),
        quad([(0, -w, 0), (0, -w, height), (length, -w, height), (length, -w, 0)]),
        quad([(0, w, 0), (length, w, 0), (length, w, height), (0, w, height)])])


def corridor_cloud(length=LENGTH, width=WIDTH, height=HEIGHT, step=0.05, noise=0.01, seed=0) -> np.ndarray:
    """Points on a closed corridor's floor, roof and walls (ends open), with noise."""
    xs, ys, zs = np.arange(0, length, step), np.arange(-width / 2, width / 2, step), np.arange(0, height, step)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    floor = np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)]
    gx, gz = np.meshgrid(xs, zs, indexing="ij")
    wall = np.c_[gx.ravel(), np.full(gx.size, -width / 2), gz.ravel()]
    pts = np.concatenate([floor, floor + [0, 0, height], wall, wall * [1, -1, 1]])
    return pts + np.random.default_rng(seed).normal(0.0, noise, pts.shape)


def turned(mesh: trimesh.Trimesh, up_axis: str) -> trimesh.Trimesh:
    """The z-up ``mesh`` as a file with ``up_axis`` up would hold it (the inverse of
    loading with that up axis)."""
    from delve.sim.meshio import up_axis_rotation

    out = mesh.copy()
    out.vertices = np.asarray(mesh.vertices) @ up_axis_rotation(up_axis)
    return out


def write_collada(mesh: trimesh.Trimesh, path: Path, up: str | None = "Y_UP", unit_m: float | None = None) -> Path:
    """A Collada file; ``up`` goes in its <up_axis> (None: no such line), ``unit_m`` in <unit>."""
    text = trimesh.exchange.dae.export_collada([mesh])
    text = text.decode() if isinstance(text, bytes) else text
    text = text.replace("<up_axis>Y_UP</up_axis>", f"<up_axis>{up}</up_axis>" if up else "")
    if unit_m is not None:
        text = text.replace("</asset>", f'<unit meter="{unit_m}" name="unit"/></asset>')
    path.write_text(text)
    return path
