"""What the CSIRO skill tests share: a 40 m tunnel (its voxel map for the fake robot and its
surface as LiDAR points) and a fake LiDAR sweep from where the robot stands."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn

from ...planners.csiro.frontier_clouds import corridor


@pytest.fixture(scope="session")
def tunnel():
    """(grid, a, b): the tunnel's voxel map, mapped all along, floor z = 1 m from a to b along x
    at y = 6 (4 m wide, 3 m high)."""
    return syn.straight_tunnel(length_m=40)


@pytest.fixture(scope="session")
def tunnel_points():
    """The tunnel's surface (floor, roof, walls) as points 0.1 m apart, open at both ends."""
    return corridor(5.0, 47.0) + np.array([0.0, 6.0, 1.0])


def sweep(robot, points: np.ndarray, range_m: float = 30.0) -> None:
    """Give ``robot`` one LiDAR sweep: the ``points`` within ``range_m`` of it, seen from it."""
    near = points[np.linalg.norm(points - robot.position, axis=1) <= range_m]
    robot.lidar_scans.append(SimpleNamespace(sensor=robot.position, points=near))


def uav_with_frontiers(grid, a, tunnel_points):
    """A flying robot 18 m into the tunnel, its sweep integrated and its frontiers updated:
    (robot, ctx, its CSIRO state)."""
    from delve.skills.csiro import UpdateFrontiers, csiro_state

    from ..fakes import FakeRobot, make_ctx

    robot = FakeRobot(grid, a + np.array([18.0, 0.0, 1.5]), platform="aerial")
    ctx = make_ctx(robot)
    sweep(robot, tunnel_points)
    UpdateFrontiers("update", ctx).tick_once()
    return robot, ctx, csiro_state(ctx)


@pytest.fixture(scope="session")
def two_drifts():
    """Two parallel drifts along x, 3 m wide, 3 m high, floor z = 1 m, at y = 4 and y = 12 (5 m of
    rock between them), joined at x = 45 only; mapped throughout."""
    return syn.carve((50.0, 16.0, 6.0), 0.2, [syn.Tunnel((3.0, 4.0, 1.0), (45.0, 4.0, 1.0), 3.0, 3.0),
                                              syn.Tunnel((3.0, 12.0, 1.0), (45.0, 12.0, 1.0), 3.0, 3.0),
                                              syn.Tunnel((45.0, 4.0, 1.0), (45.0, 12.0, 1.0), 3.0, 3.0)])
