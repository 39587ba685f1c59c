"""delve.executive.teams.cohort: the COHORT strategy's parameters, services, checks and
report section (the malformed scenarios are in tests/data/malformed_scenarios/cohort_*)."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from delve.executive.errors import DelveError  # noqa: E402
from delve.executive.runner import Mission  # noqa: E402
from delve.executive.scenario import load_scenario  # noqa: E402
from delve.executive.teams import TEAM_STRATEGIES, implied_strategy  # noqa: E402
from delve.executive.teams.cohort import Cohort, cohort_figures  # noqa: E402
from delve.executive.worlds.height_bands import ALL_HEIGHTS, HeightBand  # noqa: E402
from delve.planners.cohort import CohortParams  # noqa: E402
from delve.skills.cohort import CallHub, MergeSubmaps  # noqa: E402

TREES = Path(__file__).resolve().parents[3] / "trees"


def test_cohort_is_registered_and_implied_by_its_behaviours():
    assert TEAM_STRATEGIES["cohort"] is Cohort
    assert implied_strategy({CallHub}) == "cohort" and implied_strategy({MergeSubmaps}) == "cohort"


def test_the_defaults_are_the_papers_and_every_agent_gets_them():
    team = Cohort()
    assert team.cohort == CohortParams()
    assert team.robot_services("r1")["cohort_params"] is team.cohort
    assert team.base_services()["cohort_params"] is team.cohort


def test_given_parameters_reach_the_params():
    team = Cohort(period_s=20.0, box_m=[100, 100, 10], best_share_pct=100.0)
    assert team.cohort == CohortParams(period_s=20.0, box_m=(100.0, 100.0, 10.0), best_share_pct=100.0)


@pytest.mark.parametrize("key, value, problem", [
    ("period_s", 0, "must be > 0.0"), ("submap_window_s", -1.0, "must be > 0.0"),
    ("best_share_pct", 0, "must be > 0.0"), ("best_share_pct", 100.5, "must be <= 100.0"),
    ("box_m", [1, 0, 1], "three sizes > 0"), ("box_m", [1, 1], "list of 3 numbers"),
    ("extra_explore_s", -5, "must be >= 0.0"), ("f_min", 0, "must be >= 1"),
])
def test_out_of_range_parameters_are_refused(key, value, problem):
    assert problem in Cohort.PARAMS[key].problem(value)


def scenario(tmp_path, team: str, base_tree: str | None = "cohort_hub.yaml"):
    base = f"base_station: {{tree: {TREES / base_tree}}}\n" if base_tree else ""
    path = tmp_path / "s.yaml"
    path.write_text(f"name: s\nduration_s: 60\nworld: {{generator: tunnel_network, total_length_m: 60, loops: 0}}\n"
                    f"team: {team}\n{base}robots:\n"
                    f"  - {{name: r1, platform: aerial, tree: {TREES / 'cohort_robot.yaml'}}}\n")
    return load_scenario(path)


def test_a_box_given_larger_than_the_world_is_refused_at_its_line(tmp_path):
    s = scenario(tmp_path, "{strategy: cohort, box_m: [500, 500, 50]}")
    with pytest.raises(DelveError, match="larger than the world") as err:
        s.check_starts(s.build_world())
    assert err.value.line == 4


def test_a_box_that_restricts_somewhere_and_the_default_box_pass(tmp_path):
    world = scenario(tmp_path, "{strategy: cohort}").build_world()
    extent = world.bounds_max - world.bounds_min
    # Larger than the world along every axis, but under twice its height: centred on a
    # frontier near the floor or the roof, it keeps the robot off the other end.
    tall = [500, 500, round(1.5 * float(extent[2]), 1)]
    for team in ("{strategy: cohort, box_m: [500, 500, 4]}", f"{{strategy: cohort, box_m: {tall}}}",
                 "{strategy: cohort}"):
        s = scenario(tmp_path, team)
        s.check_starts(s.build_world())


def test_a_base_station_tree_without_the_hub_is_refused_when_the_scenario_is_loaded(tmp_path):
    with pytest.raises(DelveError, match="no COHORT hub") as err:
        scenario(tmp_path, "{strategy: cohort}", base_tree="base_station.yaml")
    assert err.value.line == 5   # base_station: {tree: ...}


def test_the_hub_gets_the_first_robots_home(tmp_path):
    m = Mission(scenario(tmp_path, "{strategy: cohort}"))
    assert np.allclose(m.agents["base"].ctx.services["cohort_home"], m.robots["r1"].home)


def fake_hub():
    result = SimpleNamespace(reason="ok", frontier=np.array([10.0, 2.0, 1.0]), cluster_size=300, distance_m=12.34,
                             box_min=np.array([0.0, -5.0, 0.0]), box_max=np.array([20.0, 9.0, 4.0]))
    return SimpleNamespace(
        submaps={("r1", 0): None, ("r1", 1): None, ("r2", 0): None},
        assignments=[SimpleNamespace(robot="r1", t_s=50.0, request_id=1, result=result)],
        clusters=[SimpleNamespace(voxels=np.arange(300))], frontier_centroids=np.array([[10.0, 2.0, 1.0]]))


def test_the_report_counts_per_robot_and_lists_the_assignments():
    events = [{"event": "cohort_submap_sent", "agent": "r1"}, {"event": "cohort_submap_sent", "agent": "r1"},
              {"event": "cohort_call", "agent": "r1", "reached": True},
              {"event": "cohort_call", "agent": "r2", "reached": False},
              {"event": "cohort_assignment_received", "agent": "r1", "frontier": None},
              {"event": "cohort_assignment_received", "agent": "r1", "frontier": [1.0, 2.0, 0.5]},
              {"event": "cohort_extra_exploration", "agent": "r2"}, {"event": "cohort_backtrack", "agent": "r2"},
              {"event": "cohort_link_regained", "agent": "r2"}]
    fig = cohort_figures(events, ["r1", "r2"], fake_hub())
    r1, r2 = fig["robots"]["r1"], fig["robots"]["r2"]
    assert (r1["submaps_sent"], r1["submaps_received"], r1["calls"], r1["assignments"]) == (2, 2, 1, 2)
    assert r1["frontiers_received"] == 1 and r2["frontiers_received"] == 0
    assert (r2["calls_out_of_reach"], r2["extra_explorations"], r2["lost_link_backtracks"]) == (1, 1, 1)
    assert (r1["links_regained_on_the_way"], r2["links_regained_on_the_way"]) == (0, 1)
    assert fig["submaps_at_hub"] == 3 and fig["frontier_clusters_at_end"] == 1 and fig["frontier_points_at_end"] == 300
    assert fig["assignments"] == [{"robot": "r1", "t": 50.0, "request_id": 1, "reason": "ok",
                                   "frontier": [10.0, 2.0, 1.0], "cluster_size": 300, "distance_m": 12.3}]
    assert cohort_figures([], ["r1"], None)["submaps_at_hub"] == 0


def drawn_labels(world, band: HeightBand = ALL_HEIGHTS) -> set[str]:
    mission = SimpleNamespace(agents={"base": SimpleNamespace(ctx=SimpleNamespace(services={"cohort_hub": fake_hub()}))},
                              state=SimpleNamespace(events=[
                                  {"event": "cohort_call", "reached": True, "position": [1.0, 0.0, 1.0]},
                                  {"event": "cohort_call", "reached": False, "position": [70.0, 0.0, 1.0]}]),
                              world=world)
    fig, ax = plt.subplots()
    Cohort().draw(ax, mission, band)
    labels = {line.get_label() for line in ax.get_lines()} | {t.get_text() for t in ax.texts}
    plt.close(fig)
    return labels


def test_the_map_shows_boxes_targets_frontiers_and_calls():
    world = SimpleNamespace(bounds_min=(-50.0, -50.0, -5.0), bounds_max=(50.0, 50.0, 10.0))
    assert {"COHORT box", "COHORT target (robot, time given)", "r1 50 s", "hub frontiers (end)",
            "call to the hub (link)", "call, hub out of reach"} <= drawn_labels(world)


def test_a_box_spanning_the_world_across_is_not_drawn():
    world = SimpleNamespace(bounds_min=(0.0, -5.0, 0.0), bounds_max=(20.0, 9.0, 10.0))
    labels = drawn_labels(world)
    assert "COHORT box" not in labels and "COHORT target (robot, time given)" in labels


def test_a_view_of_one_level_draws_only_what_lies_at_its_heights():
    world = SimpleNamespace(bounds_min=(-50.0, -50.0, -5.0), bounds_max=(50.0, 50.0, 10.0))
    assert {"COHORT target (robot, time given)", "call to the hub (link)"} <= drawn_labels(world, HeightBand(hi_m=5.0))
    above = drawn_labels(world, HeightBand(lo_m=5.0))                   # the target and the call are at 1 m
    assert "COHORT target (robot, time given)" not in above and "call to the hub (link)" not in above


def test_without_a_team_key_the_trees_imply_cohort_and_the_warning_says_so(tmp_path):
    from delve.executive.errors import DelveDeprecation

    path = tmp_path / "s.yaml"
    path.write_text(f"name: s\nworld: {{generator: tunnel_network, total_length_m: 60, loops: 0}}\n"
                    f"base_station: {{tree: {TREES / 'cohort_hub.yaml'}}}\nrobots:\n"
                    f"  - {{name: r1, platform: aerial, tree: {TREES / 'cohort_robot.yaml'}}}\n")
    with pytest.warns(DelveDeprecation, match="runs as a 'cohort' team with the default parameters"):
        s = load_scenario(path)
    assert s.team.strategy is Cohort
