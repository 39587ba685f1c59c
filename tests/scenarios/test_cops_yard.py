"""COPS on an open yard (issue 16): the yard is one location, the team finishes and
comes home, and a robot whose endurance barely covers the way home goes home."""
import importlib.util
from pathlib import Path

import pytest

from delve import TREES_DIR

from .conftest import run_scenario

pytestmark = pytest.mark.slow

BENCH = Path(__file__).resolve().parents[2] / "bench" / "make_cops_yard.py"
#: A 20 m x 20 m yard north of an 8 m portal drift, a 10 m drift east of it.
RECTANGLES = [(-2, -8, 2, 0), (-10, 0, 10, 20), (10, 8, 20, 12)]


def yard_mesh(rectangles):
    """bench/make_cops_yard.py's slab-and-wall model of ``rectangles``."""
    spec = importlib.util.spec_from_file_location("make_cops_yard", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.yard_mesh(rectangles, height_m=3.0)


def write_scenario(folder: Path, endurance_s: tuple[float, float, float]) -> Path:
    folder.mkdir(parents=True)
    yard_mesh(RECTANGLES).export(folder / "yard.ply")
    robots = "".join(
        f"  - {{name: r{i + 1}, platform: legged, tree: {TREES_DIR}/cops_robot.yaml, tick_hz: 5.0, "
        f"endurance_s: {e}, start: [{x}, -6.0, 0.1]}}\n" for i, (x, e) in enumerate(zip((-1.2, 0.0, 1.2), endurance_s)))
    path = folder / "yard.yaml"
    path.write_text(f"""name: cops_yard_small
seed: 2
duration_s: 1800
world: {{mesh: yard.ply, voxel_size_m: 0.2, start: [0.0, -6.0, 0.1]}}
team: {{strategy: cops}}
base_station: {{tree: {TREES_DIR}/cops_base_voxel.yaml, tick_hz: 1.0}}
radio: {{range_m: 60, loss: 0.05}}
robots:
{robots}""")
    return path


def test_a_team_on_a_yard_explores_it_as_one_location_and_comes_home(tmp_path):
    """r3's endurance (150 s) barely covers its way home once it is out in the yard:
    it leaves the plan and goes home; r1 and r2 finish the yard without it."""
    _, report = run_scenario(write_scenario(tmp_path / "yard", (1500, 1500, 150)), tmp_path / "out")
    assert report["succeeded"], report["outcome"]
    cops = report["cops"]
    assert cops["plans_valid"] == cops["cycles"] and cops["plans"][-1]["final"]
    assert cops["plans"][-1]["frontiers"] == 0 and cops["transitions_failed"] == []
    assert report["locations_explored_at_base"] <= 6          # the yard is one location, not 9 cells and more
    assert report["coverage_fraction"] > 0.95
    assert all(r["returned_home"] for r in report["robots"]) and report["declared_lost"] == []
    assert report["gone_home"] == {"by_endurance": ["r3"], "after_failed_move": []}
    r3 = next(r for r in report["robots"] if r["name"] == "r3")
    assert 0 < r3["endurance_left_s"] < 150
