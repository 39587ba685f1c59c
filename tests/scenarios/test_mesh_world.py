"""A scanned mine loaded from a mesh file (centimetres, y up) can be explored."""
from delve import SCENARIOS_DIR

from .conftest import run_scenario


def test_scanned_mine_is_explored_and_the_robot_returns(tmp_path):
    mission, report = run_scenario(SCENARIOS_DIR / "scanned_mine.yaml", tmp_path)
    assert report["succeeded"]
    assert report["coverage_fraction"] >= 0.85
    assert report["robots"][0]["returned_home"]
    extent = mission.world.bounds_max - mission.world.bounds_min
    assert extent[2] < extent[0] and extent[2] < extent[1]  # y-up scan turned z-up, in metres
