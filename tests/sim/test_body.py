"""delve.sim.body: the robot interface voxel and graph robots share."""
import numpy as np

from delve.sim.body import RobotBody
from delve.sim.platforms import PLATFORMS


class Body(RobotBody):
    def __init__(self):
        self._name, self._platform = "r1", PLATFORMS["legged"]
        self._pos, self._home = np.array([1.0, 2.0, 0.5]), np.zeros(3)
        self._endurance, self._distance, self._status, self._commands = 60.0, 12.5, "idle", 3


def test_the_body_reports_copies_and_counters():
    b = Body()
    assert (b.name, b.platform, b.mobility) == ("r1", "legged", PLATFORMS["legged"])
    p = b.position
    p[0] = 99.0
    assert b.position[0] == 1.0 and not b.home.any()
    assert (b.endurance_remaining_s, b.distance_m, b.path_status, b.command_id) == (60.0, 12.5, "idle", 3)
