"""Write an open-yard mine model and a three-robot COPS scenario that loads it.

    .venv/bin/python bench/make_cops_yard.py OUT_DIR

The model (OUT_DIR/yard.ply) is built like a Gazebo model: floor slabs and wall
boxes, no ceiling, metres, z up. Its floor plan: a 56 m x 40 m yard, reached from
the portal by a 4 m drift 12 m long from the south, with three drifts leaving it
(north, 30 m; east and west, 22 m). The scenario (OUT_DIR/cops_yard.yaml): the base
station and three legged robots at the portal (the world's start, where the base
station stands), the shipped COPS trees, endurance 1200 s each (the legged
platform's 1800 s less a third: the team cannot dawdle).

Then: ``delve run OUT_DIR/cops_yard.yaml --out DIR``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import trimesh
from scipy import ndimage

from delve import TREES_DIR

#: Axis-aligned floor rectangles (x0, y0, x1, y1), metres: the portal drift, the
#: yard, the drifts that leave it.
RECTANGLES = [(-2, -12, 2, 0), (-28, 0, 28, 40), (-2, 40, 2, 70), (28, 18, 50, 22), (-50, 30, -28, 34)]
HEIGHT_M, WALL_M, SLAB_M = 4.0, 0.5, 0.3
#: The floor plan's raster (walls are built from it).
CELL_M = 0.25
START = (0.0, -10.0, 0.1)


def yard_mesh(rectangles=RECTANGLES, height_m: float = HEIGHT_M, wall_m: float = WALL_M,
              slab_m: float = SLAB_M, cell_m: float = CELL_M) -> trimesh.Trimesh:
    """Floor slabs under the rectangles and wall boxes around their union (runs of
    wall cells along y), z up, the floor's top at z = 0."""
    r = np.asarray(rectangles, float)
    lo = r[:, :2].min(axis=0) - 2 * wall_m
    n = np.ceil((r[:, 2:].max(axis=0) + 2 * wall_m - lo) / cell_m).astype(int)
    gx, gy = np.meshgrid(lo[0] + (np.arange(n[0]) + 0.5) * cell_m, lo[1] + (np.arange(n[1]) + 0.5) * cell_m,
                         indexing="ij")
    free = np.zeros(n, bool)
    for x0, y0, x1, y1 in r:
        free |= (gx >= x0) & (gx <= x1) & (gy >= y0) & (gy <= y1)
    k = int(round(wall_m / cell_m))
    walls = ndimage.binary_dilation(free, np.ones((2 * k + 1, 2 * k + 1), bool)) & ~free
    boxes = []
    for i in range(n[0]):
        row = np.concatenate([[0], walls[i].astype(int), [0]])
        for j0, j1 in zip(np.flatnonzero(np.diff(row) == 1), np.flatnonzero(np.diff(row) == -1)):
            centre = (lo[0] + (i + 0.5) * cell_m, lo[1] + (j0 + j1) / 2 * cell_m, height_m / 2)
            boxes.append(trimesh.creation.box((cell_m, (j1 - j0) * cell_m, height_m),
                                              trimesh.transformations.translation_matrix(centre)))
    for x0, y0, x1, y1 in r:
        size = (x1 - x0 + 2 * wall_m, y1 - y0 + 2 * wall_m, slab_m)
        boxes.append(trimesh.creation.box(size, trimesh.transformations.translation_matrix(
            ((x0 + x1) / 2, (y0 + y1) / 2, -slab_m / 2))))
    return trimesh.util.concatenate(boxes)


SCENARIO = """# Three legged robots as a COPS team on an open yard (bench/make_cops_yard.py).
name: cops_yard
seed: 1
duration_s: 3600
world:
  mesh: yard.ply
  voxel_size_m: 0.2
  start: [{start}]
team: {{strategy: cops}}
base_station:
  tree: {trees}/cops_base_voxel.yaml
  tick_hz: 1.0
radio:
  range_m: 60
  loss: 0.05
robots:
{robots}"""


def write(out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    ply = out / "yard.ply"
    yard_mesh().export(ply)
    robots = "".join(
        f"  - {{name: r{i + 1}, platform: legged, tree: {TREES_DIR}/cops_robot.yaml, tick_hz: 5.0, "
        f"endurance_s: 1200, start: [{START[0] + dx}, {START[1]}, {START[2]}]}}\n"
        for i, dx in enumerate((-1.2, 0.0, 1.2)))
    scenario = out / "cops_yard.yaml"
    scenario.write_text(SCENARIO.format(trees=TREES_DIR, robots=robots, start=", ".join(map(str, START))))
    return [ply, scenario]


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    for p in write(Path(sys.argv[1])):
        print(f"wrote {p}")
