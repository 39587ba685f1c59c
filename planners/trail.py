"""The way back along a robot's own traversed path (the CERBERUS tree's "Recovery
Homing" and its WiFi-safety back-off): newest point first, loops cut out where the map
shows the shortcut is passable.

Pure numpy and scipy on a planner :class:`~delve.planners.occupancy.Grid`.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .geometry import cut_path, nearest_segment
from .occupancy import FREE, OCCUPIED, Grid

#: ``can_jump(a, b)``: whether a robot can go straight from trail point ``a`` to ``b``.
JumpCheck = Callable[[np.ndarray, np.ndarray], bool]


def jump_check(grid: Grid, *, aerial: bool, body_height_m: float, max_step_m: float) -> JumpCheck:
    """Whether a robot can go straight from one point of its trail to another, on
    ``grid`` (its onboard map): an aerial robot through known free voxels; a legged
    robot over mapped ground, every point of the segment with rock at most
    ``body_height_m + max_step_m`` below the body and the ground's height varying by
    at most ``max_step_m`` (so a loop cut never crosses a trench or a ledge)."""
    vs = grid.voxel_size_m

    def ok(a: np.ndarray, b: np.ndarray) -> bool:
        n = int(np.ceil(np.linalg.norm(b - a) / (0.5 * vs))) + 1
        pts = a + (b - a) * np.linspace(0.0, 1.0, n)[:, None]
        if aerial:
            return bool(np.all(grid.value_at(pts) == FREE))
        if np.any(grid.value_at(pts) == OCCUPIED):
            return False
        depth = np.arange(0.0, body_height_m + max_step_m + vs, vs)
        col = pts[:, None, :] - np.stack([np.zeros_like(depth), np.zeros_like(depth), depth], axis=1)[None]
        rock = grid.value_at(col.reshape(-1, 3)).reshape(n, len(depth)) == OCCUPIED
        if not np.all(rock.any(axis=1)):
            return False
        ground = pts[:, 2] - depth[rock.argmax(axis=1)]
        return bool(ground.max() - ground.min() <= max_step_m + vs)

    return ok


@dataclass
class TrailWalk:
    """A way back along a snapshot of the traversed path: ``indices`` into ``trail``
    (oldest first), newest first, loops cut out; ``path`` is at most ``distance_m``."""

    trail: np.ndarray
    indices: np.ndarray
    distance_m: float | None = None

    @classmethod
    def plan(cls, trail: np.ndarray, distance_m: float | None = None, loop_radius_m: float = 0.75,
             can_jump: JumpCheck | None = None) -> TrailWalk:
        """Walk back from the newest point; where the trail passes within
        ``loop_radius_m`` of an older point of itself (and ``can_jump`` allows going
        straight there), jump to the oldest such point, so an earlier back-and-forth
        (a previous backtrack, a dead end, a loop) is not walked again."""
        trail = np.asarray(trail, float).reshape(-1, 3)
        if len(trail) == 0:
            return cls(trail, np.zeros(0, np.int64), distance_m)
        tree = cKDTree(trail) if loop_radius_m > 0 else None
        out = [len(trail) - 1]
        i = len(trail) - 1
        while i > 0:
            nxt = i - 1
            if tree is not None:
                for j in sorted(tree.query_ball_point(trail[i], loop_radius_m)):
                    if j >= i - 1:
                        break
                    if can_jump is None or can_jump(trail[i], trail[j]):
                        nxt = j
                        break
            i = nxt
            out.append(i)
        return cls(trail, np.asarray(out, np.int64), distance_m)

    @property
    def path(self) -> np.ndarray:
        return cut_path(self.trail[self.indices], self.distance_m)

    def exact_rest(self, position: np.ndarray, covered_m: float = 0.0) -> np.ndarray:
        """The rest of the way from ``position`` exactly as walked, no loop cut: back
        to the start of the leg of this walk nearest to ``position``, then along every
        older point of the trail (at most ``distance_m - covered_m``)."""
        pts = self.trail[self.indices]
        if len(pts) == 0:
            return pts
        k = nearest_segment(pts, position) if len(pts) > 1 else 0
        rest = self.trail[self.indices[k]::-1]
        left = None if self.distance_m is None else max(self.distance_m - covered_m, 0.0)
        return cut_path(np.vstack([position, rest]), left)[1:]


def backtrack_path(trail: np.ndarray, distance_m: float | None = None, loop_radius_m: float = 0.75,
                   can_jump: JumpCheck | None = None) -> np.ndarray:
    """The way back along ``trail`` ((N, 3) positions, oldest first), newest first,
    with loops cut out (see :meth:`TrailWalk.plan`), at most ``distance_m`` long (None:
    all the way to its start)."""
    return TrailWalk.plan(trail, distance_m, loop_radius_m, can_jump).path


__all__ = ["JumpCheck", "TrailWalk", "backtrack_path", "jump_check"]
