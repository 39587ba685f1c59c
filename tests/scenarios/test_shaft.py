"""The aerial robot explores the vertical shaft and the gallery above it, which the
legged robot cannot climb to."""
import numpy as np
import pytest

from .conftest import DATA, run_scenario


@pytest.fixture(scope="module")
def team():
    mission, _ = run_scenario(DATA / "shaft_team.yaml")
    return mission


def upper_region(mission) -> np.ndarray:
    """Flat indices of the free voxels in the upper half of the shaft and the gallery above."""
    g = mission.world.centreline
    (a, b) = next((a, b) for a, b, d in g.edges(data=True) if d["kind"] == "shaft")
    bottom, top = sorted(float(g.nodes[n]["pos"][2]) for n in (a, b))
    z = mission.world.index_to_center(np.stack(np.unravel_index(mission.backend.truth, mission.world.free.shape), axis=1))[:, 2]
    return mission.backend.truth[z >= (bottom + top) / 2]


def seen(mission, robot: str, voxels: np.ndarray) -> float:
    return float((mission.robots[robot].onboard_map.occupancy.reshape(-1)[voxels] == 0).mean())


def test_only_the_aerial_robot_explores_above_the_shaft(team):
    upper = upper_region(team)
    assert len(upper) > 1000
    assert seen(team, "obelix", upper) >= 0.6
    assert seen(team, "anymal", upper) <= 0.1
    legged_top = max(p[2] for p in team.robots["anymal"].traversed_path)
    aerial_top = max(p[2] for p in team.robots["obelix"].traversed_path)
    assert aerial_top > legged_top + 5


def test_both_robots_come_home(team):
    for robot in team.robots.values():
        assert np.linalg.norm(robot.position - robot.home) <= 1.5
    assert team.succeeded
