"""What every simulated robot shows of itself, whatever world it drives in."""
from __future__ import annotations

import numpy as np

from .platforms import Platform
from .radio import Endpoint


class RobotBody:
    """The read-only part of the robot interface that voxel and graph robots share.

    Subclasses set ``_name``, ``_platform``, ``_pos``, ``_home``, ``_endurance``,
    ``_distance``, ``_radio``, ``_status`` and ``_commands``.
    """

    _name: str
    _platform: Platform
    _pos: np.ndarray
    _home: np.ndarray
    _endurance: float
    _distance: float
    _radio: Endpoint
    _status: str
    _commands: int

    @property
    def name(self) -> str:
        return self._name

    @property
    def platform(self) -> str:
        return self._platform.name

    @property
    def mobility(self) -> Platform:
        return self._platform

    @property
    def position(self) -> np.ndarray:
        """Where the robot believes it is (the true position, unless its localisation drifts)."""
        return self._pos.copy()

    @property
    def true_position(self) -> np.ndarray:
        """Where the robot really is (the simulator's, for radio links and reports)."""
        return self._pos.copy()

    @property
    def view_up_deg(self) -> float:
        """How far above the horizontal the platform's LiDAR sees (half its vertical view
        above its pitch)."""
        lidar = self._platform.lidar
        return lidar.pitch_deg + lidar.vertical_fov_deg / 2

    @property
    def home(self) -> np.ndarray:
        return self._home.copy()

    @property
    def endurance_remaining_s(self) -> float:
        return self._endurance

    def drain_battery(self, fraction: float) -> None:
        """A fault: the battery loses ``fraction`` (0..1] of the endurance it has left at
        once; at zero the robot stops for good at its next step."""
        self._endurance = max(0.0, self._endurance * (1.0 - float(fraction)))

    @property
    def distance_m(self) -> float:
        return self._distance

    @property
    def path_status(self) -> str:
        return self._status

    @property
    def parked(self) -> bool:
        """Whether the robot was parked (its mission is over: it stands powered down)."""
        return getattr(self, "_parked", False)

    @property
    def command_id(self) -> int:
        """Counts motion commands (``follow_path`` and ``stop``)."""
        return self._commands
