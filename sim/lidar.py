"""A spinning LiDAR: a fixed fan of beams cast into the world mesh with open3d."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LidarSpec:
    """Field of view (centred on ``pitch_deg`` of elevation), range, angular
    resolution and rate of a LiDAR or a ring of depth cameras.

    Defaults: the legged robot's sensor of the GBPlanner2 paper's Table I (360×30°,
    30 m); the aerial robot's is 360×90°. A VLP-16 sweeps at 10 Hz; integrating one
    sweep a second into the map (the robot moves about 1 m between sweeps) keeps the
    simulation fast, and each sweep is rotated a little so sweeps sample new voxels.
    """

    horizontal_fov_deg: float = 360.0
    vertical_fov_deg: float = 30.0
    range_m: float = 30.0
    horizontal_resolution_deg: float = 1.5
    vertical_resolution_deg: float = 2.0
    rate_hz: float = 1.0
    mount_height_m: float = 0.1
    pitch_deg: float = 0.0

    def beam_directions(self, yaw_rad: float) -> np.ndarray:
        """(N, 3) unit directions of all beams for a sensor at heading ``yaw_rad``."""
        nh = max(1, int(round(self.horizontal_fov_deg / self.horizontal_resolution_deg)))
        nv = max(1, int(round(self.vertical_fov_deg / self.vertical_resolution_deg)) + 1)
        if self.horizontal_fov_deg >= 360.0:
            az = np.arange(nh) * (2 * np.pi / nh)
        else:
            half = np.radians(self.horizontal_fov_deg) / 2
            az = np.linspace(-half, half, nh)
        half_v = np.radians(self.vertical_fov_deg) / 2
        el = np.linspace(-half_v, half_v, nv) if nv > 1 else np.zeros(1)
        el = el + np.radians(self.pitch_deg)
        az, el = np.meshgrid(az + yaw_rad, el, indexing="ij")
        az, el = az.ravel(), el.ravel()
        return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)


@dataclass(frozen=True)
class LidarScan:
    """One sweep of a range sensor: where the sensor was (3,) and the (N, 3) points its beams
    returned within range, both in the robot's (believed) world frame."""

    sensor: np.ndarray
    points: np.ndarray


#: ANYmal's downward-looking depth cameras, which map the terrain around its feet
#: (a LiDAR's lowest beam misses the floor of a ramp that falls away).
TERRAIN_CAMERAS = LidarSpec(vertical_fov_deg=50.0, pitch_deg=-40.0, range_m=4.0, horizontal_resolution_deg=3.0,
                            vertical_resolution_deg=5.0, mount_height_m=0.0)
