"""sim/robot.py: the range sensors' sweeps for take_lidar_scans (the CSIRO frontiers' point cloud)."""
from __future__ import annotations

import numpy as np

from ..skills.test_robot_protocol import sim_robot


def test_lidar_scans_are_kept_once_asked_and_lie_on_the_rock():
    robot = sim_robot()
    robot.scan()
    assert robot.take_lidar_scans() == []                 # nothing kept before the first call
    robot.scan()
    scans = robot.take_lidar_scans()
    assert len(scans) == 2                                 # the LiDAR and the terrain cameras
    lidar = scans[0]
    assert np.allclose(lidar.sensor, robot.position + [0.0, 0.0, robot.mobility.lidar.mount_height_m])
    assert len(lidar.points) > 100
    # Every point is on the rock: the world's ray from the sensor meets rock there.
    d = lidar.points - lidar.sensor
    r = np.linalg.norm(d, axis=1)
    hit = robot.world.cast_rays(np.broadcast_to(lidar.sensor, d.shape), d / r[:, None], 40.0)
    assert np.allclose(hit, r, atol=1e-3)
    assert robot.take_lidar_scans() == []                  # taken
