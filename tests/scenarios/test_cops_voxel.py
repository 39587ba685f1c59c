"""COPS on a 3D world: the Figure 4 trees with the network extracted from the robots' voxel maps."""
import json

from delve.executive.outputs import strip_wall_clock

from .conftest import DATA, run_scenario


def test_the_cops_trees_explore_a_3d_mine_and_bring_the_map_home(tmp_path):
    mission, report = run_scenario(DATA / "cops_mine_small.yaml", tmp_path / "a")
    assert report["succeeded"], report["cops"]
    cops = report["cops"]
    assert cops["cycles"] >= 2 and cops["plans_valid"] == cops["cycles"]
    assert cops["plans"][-1]["final"] and cops["plans"][-1]["frontiers"] == 0
    assert sum(len(p["explorers"]) for p in cops["plans"]) >= 2
    # the network grew from the first scans to the whole mine, all of it explored
    assert cops["plans"][0]["locations"] < cops["plans"][-1]["locations"] == report["locations_explored_at_base"]
    assert report["coverage_fraction"] > 0.95
    assert report["base_coverage_fraction"] > 0.95, "the robots' maps travelled with the plan's messages"
    assert all(r["returned_home"] for r in report["robots"])
    assert report["declared_lost"] == []
    dump = (tmp_path / "a" / "tree_r1.txt").read_text()
    for node in ("Wait to receive plan", "Communication action", "Transition action", "Exploration action"):
        assert node in dump
    _, again = run_scenario(DATA / "cops_mine_small.yaml", tmp_path / "b")
    assert json.dumps(strip_wall_clock(report)) == json.dumps(strip_wall_clock(again))


def test_locations_the_explorers_arrived_at_are_explored_and_the_mission_ends(tmp_path):
    """Robots arrive at locations whose cells their own maps never count as visited
    (cops_mine never ended so, issue 16): each is explored all the same, no frontier
    is left, and the team is recalled home well before the duration."""
    _, report = run_scenario(DATA / "cops_mine_arrivals.yaml", tmp_path)
    assert report["succeeded"] and not report["outcome"]["timed_out"], report["outcome"]
    plans = report["cops"]["plans"]
    assert plans[-1]["final"] and plans[-1]["frontiers"] == 0
    assert report["coverage_fraction"] > 0.95
    assert report["sim_time_s"] < 300
    assert all(r["returned_home"] for r in report["robots"])
