"""Robot platforms: kinematic limits and default sensors of the legged and aerial robots."""

from __future__ import annotations

from dataclasses import dataclass, field

from .lidar import TERRAIN_CAMERAS, LidarSpec


@dataclass(frozen=True)
class Platform:
    """Kinematic limits of a platform (satisfies the robot interface's ``Mobility``)."""

    name: str
    aerial: bool
    speed_mps: float
    body_height_m: float
    radius_m: float
    endurance_s: float
    max_inclination_deg: float = 90.0
    max_step_m: float = 0.0
    lidar: LidarSpec = field(default_factory=LidarSpec)
    terrain: LidarSpec | None = None


#: A quadruped like ANYmal C: about 1 m/s, steps up to 0.3 m, slopes up to 35°.
LEGGED = Platform(
    name="legged",
    aerial=False,
    speed_mps=1.0,
    body_height_m=0.5,
    radius_m=0.4,
    endurance_s=1800.0,
    max_inclination_deg=35.0,
    max_step_m=0.3,
    lidar=LidarSpec(vertical_fov_deg=30.0),
    terrain=TERRAIN_CAMERAS,
)

#: A small flying robot like RMF-Obelix: about 2 m/s, 360×90° LiDAR, short endurance.
AERIAL = Platform(
    name="aerial",
    aerial=True,
    speed_mps=2.0,
    body_height_m=1.0,
    radius_m=0.4,
    endurance_s=510.0,
    lidar=LidarSpec(vertical_fov_deg=90.0, vertical_resolution_deg=4.0, mount_height_m=0.0),
)

PLATFORMS = {p.name: p for p in (LEGGED, AERIAL)}
