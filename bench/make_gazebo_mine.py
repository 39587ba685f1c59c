"""Write a mine model of the kind Gazebo users have, and scenarios that load it.

    .venv/bin/python bench/make_gazebo_mine.py OUT_DIR

The model (OUT_DIR/gazebo_mine.dae) is built the way Gazebo tunnel models often are:
floor slabs and wall boxes, no ceiling, metres, z up, in a Collada file whose header
says Y_UP (trimesh writes that header, as many exporters do; Gazebo ignores it). Its
drifts: a 60 m main drift along y, three cross-cuts along x, one of them joined back
to the main drift by a parallel drift (a loop), and dead ends.

Scenarios written beside it (their trees are the shipped ones):

- ``gazebo_mine_as_is.yaml``: the file as a new user first tries it: no
  ``up_axis``, a start 0.5 m above the floor. ``delve world`` warns that the world
  stands on its end and says which axis is flattest.
- ``gazebo_mine.yaml``: ``up_axis: z``, the same start (it lands on the floor), one
  legged robot with the frontier explorer.
- ``gazebo_mine_cops.yaml``: three legged robots as a COPS team.

Then: ``delve world OUT_DIR/gazebo_mine.yaml --preview OUT_DIR/preview`` and
``delve run OUT_DIR/gazebo_mine.yaml``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import trimesh

from delve import TREES_DIR

#: Drifts as (x0, y0) -> (x1, y1) centre lines (m), axis-aligned.
DRIFTS = [((0, 0), (0, 60)), ((0, 12), (30, 12)), ((0, 30), (24, 30)), ((0, 48), (36, 48)),
          ((24, 30), (24, 48)), ((30, 12), (30, 2))]
WIDTH_M, HEIGHT_M, WALL_M, SLAB_M = 4.0, 3.0, 0.5, 0.3
#: The floor plan's raster (walls are built from it).
CELL_M = 0.25


def floor_plan(drifts=DRIFTS, width_m: float = WIDTH_M, cell_m: float = CELL_M, margin_m: float = 2.0):
    """(free cells, origin): a raster of the drifts' floor, ``cell_m`` cells."""
    pts = np.array([p for d in drifts for p in d], float)
    lo = pts.min(axis=0) - width_m / 2 - margin_m
    hi = pts.max(axis=0) + width_m / 2 + margin_m
    n = np.ceil((hi - lo) / cell_m).astype(int)
    cx = lo[0] + (np.arange(n[0]) + 0.5) * cell_m
    cy = lo[1] + (np.arange(n[1]) + 0.5) * cell_m
    gx, gy = np.meshgrid(cx, cy, indexing="ij")
    free = np.zeros(n, bool)
    for (x0, y0), (x1, y1) in drifts:
        ax, bx = sorted((x0, x1))
        ay, by = sorted((y0, y1))
        free |= ((gx >= ax - width_m / 2) & (gx <= bx + width_m / 2)
                 & (gy >= ay - width_m / 2) & (gy <= by + width_m / 2))
    return free, lo


def slab_and_wall_mesh(drifts=DRIFTS, width_m=WIDTH_M, height_m=HEIGHT_M, wall_m=WALL_M, slab_m=SLAB_M,
                       cell_m=CELL_M) -> trimesh.Trimesh:
    """Floor slabs under the drifts and wall boxes along them (runs of wall cells
    along x), z up, the floor's top at z = 0."""
    free, lo = floor_plan(drifts, width_m, cell_m)
    k = int(round(wall_m / cell_m))
    from scipy import ndimage

    walls = ndimage.binary_dilation(free, np.ones((2 * k + 1, 2 * k + 1), bool)) & ~free
    boxes = []
    for i in range(walls.shape[0]):
        row = np.concatenate([[0], walls[i].astype(int), [0]])
        starts, ends = np.flatnonzero(np.diff(row) == 1), np.flatnonzero(np.diff(row) == -1)
        for j0, j1 in zip(starts, ends):
            size = (cell_m, (j1 - j0) * cell_m, height_m)
            centre = (lo[0] + (i + 0.5) * cell_m, lo[1] + (j0 + j1) / 2 * cell_m, height_m / 2)
            boxes.append(trimesh.creation.box(size, trimesh.transformations.translation_matrix(centre)))
    for (x0, y0), (x1, y1) in drifts:
        ax, bx = sorted((x0, x1))
        ay, by = sorted((y0, y1))
        size = (bx - ax + width_m + 2 * wall_m, by - ay + width_m + 2 * wall_m, slab_m)
        centre = ((ax + bx) / 2, (ay + by) / 2, -slab_m / 2)
        boxes.append(trimesh.creation.box(size, trimesh.transformations.translation_matrix(centre)))
    return trimesh.util.concatenate(boxes)


SCENARIO = """# {what}
name: {name}
seed: 1
duration_s: {duration}
world:
  mesh: gazebo_mine.dae
{world_extra}  voxel_size_m: 0.2
base_station:
  tree: {trees}/{base}.yaml
{team}robots:
{robots}"""


def write(out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    mesh = slab_and_wall_mesh()
    data = trimesh.exchange.dae.export_collada([mesh])
    dae = out / "gazebo_mine.dae"
    dae.write_bytes(data if isinstance(data, bytes) else data.encode())
    def legged(name: str, tree: str, x: float) -> str:
        return (f"  - name: {name}\n    platform: legged\n    tree: {TREES_DIR}/{tree}.yaml\n"
                f"    endurance_s: 1200\n    start: [{x}, 2.0, 0.5]\n")

    one = legged("anymal", "frontier_explorer", 0.0)
    team = "".join(legged(f"r{i}", "cops_robot", x) for i, x in enumerate((-1.2, 0.0, 1.2)))
    files = {
        "gazebo_mine_as_is.yaml": dict(
            what="The model as a new user first tries it: no up_axis, a start 0.5 m above the floor.",
            name="gazebo_mine_as_is", duration=1800, world_extra="", base="base_station", team="", robots=one),
        "gazebo_mine.yaml": dict(
            what="The model with its real up axis (the header says Y_UP; Gazebo ignores it).",
            name="gazebo_mine", duration=1800, world_extra="  up_axis: z\n", base="base_station", team="",
            robots=one),
        "gazebo_mine_cops.yaml": dict(
            what="Three legged robots as a COPS team on the model.", name="gazebo_mine_cops", duration=2400,
            world_extra="  up_axis: z\n", base="cops_base_voxel", team="team: {strategy: cops}\n", robots=team),
    }
    written = [dae]
    for fname, fields in files.items():
        path = out / fname
        path.write_text(SCENARIO.format(trees=TREES_DIR, **fields))
        written.append(path)
    return written


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    for p in write(Path(sys.argv[1])):
        print(f"wrote {p}")
