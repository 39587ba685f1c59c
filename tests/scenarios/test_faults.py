"""Each fault kind injected into a short mission on a small tunnel network: the
fault takes hold when it starts, lets go when it ends, and the mission survives it
(or ends honestly when it cannot). Slow (see conftest.py)."""
import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from delve.executive.cli import main
from delve.executive.worlds import BASE
from delve.sim.voxel_map import OCCUPIED, UNKNOWN

from .conftest import run_scenario

TREES = Path(__file__).parent.parent.parent / "trees"


def scenario(tmp_path: Path, faults: str, *, tree: str = "frontier_explorer.yaml", duration_s: float = 600,
             robot: str = "", extra: str = "", name: str = "faults") -> Path:
    """The small tunnel network of small_tunnel.yaml, one legged robot, the faults given."""
    tree_path = tree if Path(tree).is_absolute() else TREES / tree
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"""name: {name}
seed: 4
duration_s: {duration_s}
world: {{generator: tunnel_network, total_length_m: 120, loops: 1}}
base_station: {{tree: {TREES / 'base_station.yaml'}}}
radio: {{range_m: 150}}
robots:
  - {{name: anymal, platform: legged, tree: {tree_path}, endurance_s: 900{robot}}}
{extra}
faults:
{faults}
""")
    return path


def events(mission, *names):
    return [e for e in mission.state.events if e["event"] in names]


def samples_in(mission, start, end):
    return [s for s in mission.state.samples if start <= s.t < end]


def the_robot(report):
    return report["robots"][0]


def test_radio_blackouts_of_a_robot_a_link_and_the_base_station(tmp_path):
    windows = {"robot": (20, 50), "link": (70, 100), "base": (120, 150)}
    mission, report = run_scenario(scenario(tmp_path, """
  - {at_s: 20, robot: anymal, kind: radio_blackout, duration_s: 30}
  - {at_s: 70, link: [anymal, base], kind: radio_blackout, duration_s: 30}
  - {at_s: 120, base_station: true, kind: radio_blackout, duration_s: 30}
"""), tmp_path / "out")
    assert [e["event"] for e in events(mission, "fault", "fault_end")] == ["fault", "fault_end"] * 3
    for start, end in windows.values():
        inside = samples_in(mission, start, end)
        assert len(inside) == 6 and not any(s.linked["anymal"] for s in inside)
        assert len({s.base for s in inside}) == 1, "nothing reaches the base map during a blackout"
    assert mission.radio.cut_links == set() and not mission.radio.endpoints[BASE].blackout
    # What waited in the outbox arrived once the radio was back: nothing is lost.
    assert report["succeeded"] and the_robot(report)["returned_home"]
    assert the_robot(report)["messages_undelivered"] == 0 and the_robot(report)["map_voxels_undelivered"] == 0


def test_a_degraded_lidar_maps_only_near_the_robot_and_a_dropout_maps_nothing(tmp_path):
    seen = {}

    def watch(m):
        robot = m.robots["anymal"]
        seen[round(m.clock.now_s)] = (robot.onboard_map.occupancy.copy(), robot.traversed_path)

    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario

    mission = Mission(load_scenario(scenario(tmp_path, """
  - {at_s: 0, robot: anymal, kind: lidar_degraded, range_m: 3, duration_s: 60}
  - {at_s: 90, robot: anymal, kind: lidar_dropout, duration_s: 30}
""", duration_s=150)))
    mission.run(progress=watch, progress_period_s=5.0)
    occupancy, trail = seen[55]
    robot = mission.robots["anymal"]
    voxels = np.argwhere(occupancy != UNKNOWN)
    centres = robot.onboard_map.origin + (voxels + 0.5) * robot.onboard_map.voxel_size_m
    far = cKDTree(trail).query(centres)[0]
    assert len(voxels) and far.max() <= 3.0 + 1.5, "a 3 m sensor maps nothing farther from the robot's way"
    voxel = robot.onboard_map.voxel_size_m
    later = robot.onboard_map.origin + (np.argwhere(seen[85][0] != UNKNOWN) + 0.5) * voxel
    assert cKDTree(seen[85][1]).query(later)[0].max() > 6.0, "the full range is back at 60 s"
    dropout = [s.robots["anymal"] for s in samples_in(mission, 90, 120)]
    assert len(dropout) == 6 and len(set(dropout)) == 1, "blind: the map does not grow"
    assert mission.state.samples[-1].robots["anymal"] > dropout[0]


def test_a_planner_that_raises_or_is_slow(tmp_path):
    mission, report = run_scenario(scenario(tmp_path, """
  - {at_s: 10, robot: anymal, kind: planner_slow, delay_s: 15}
  - {at_s: 40, robot: anymal, kind: planner_error}
  - {at_s: 60, robot: anymal, kind: planner_error, duration_s: 8}
""", tree="anymal_explorer.yaml", duration_s=300), tmp_path / "out")
    delayed = events(mission, "planner_delayed")
    assert len(delayed) == 1
    t = delayed[0]["t"]
    stood = {tuple(s.positions["anymal"]) for s in samples_in(mission, t + 0.5, t + 14.5)}
    assert len(stood) == 1, "the robot stands while the planner thinks"
    failed = [e for e in events(mission, "explore_failed") if "InjectedPlannerError" in e.get("detail", "")]
    once = [e for e in failed if e["t"] < 60]
    assert len(once) == 1 and 40 <= once[0]["t"] < 60, "without duration_s only the next plan raises"
    window = [e for e in failed if 60 <= e["t"] < 68]
    ended = events(mission, "fault_end")[0]
    assert len(window) >= 1 and ended["plans_hit"] == len(window)
    assert not [e for e in failed if e["t"] >= 68], "the planner works again after the fault"
    assert events(mission, "gbplanner_path")[-1]["t"] > 68
    assert json.loads((tmp_path / "out" / "report.json").read_text())["scenario"] == "faults"


def test_a_flat_battery_stops_the_robot_and_silences_it(tmp_path):
    mission, report = run_scenario(scenario(tmp_path, """
  - {at_s: 40, robot: anymal, kind: battery_drop, drop_fraction: 1.0}
""", duration_s=200), tmp_path / "out")
    lost = events(mission, "robot_lost")
    assert [(e["t"], e["robot"], e["reason"]) for e in lost] == [(40.0, "anymal", "endurance exhausted")]
    robot = mission.robots["anymal"]
    assert not robot.alive and robot.radio.silent and robot.path_status == "blocked"
    after = {tuple(s.positions["anymal"]) for s in samples_in(mission, 40.5, 1e9)}
    assert len(after) == 1, "it does not move again"
    r = the_robot(report)
    assert r["lost"] and r["endurance_left_s"] == 0.0
    assert r["map_voxels_undelivered"] > 0 or r["messages_undelivered"] > 0, "what it held is counted"
    assert not report["succeeded"] and report["outcome"]["lost"] == {"anymal": "endurance exhausted"}
    assert any("every robot was lost" in why for why in report["outcome"]["reasons"])


def test_a_battery_drop_sends_the_robot_home_early(tmp_path):
    mission, report = run_scenario(scenario(tmp_path, """
  - {at_s: 30, robot: anymal, kind: battery_drop, drop_fraction: 0.85}
""", duration_s=400), tmp_path / "out")
    assert events(mission, "fault")[0]["endurance_left_s"] == pytest.approx(0.15 * 870, abs=1)
    r = the_robot(report)
    assert r["returned_home"] and not r.get("lost") and 0 < r["endurance_left_s"] < 100
    assert events(mission, "endurance_low")


def test_a_drifting_pose_smears_the_map_until_the_robot_relocalises(tmp_path):
    phantom = {}

    def watch(m):
        robot = m.robots["anymal"]
        rock = robot.onboard_map.occupancy == OCCUPIED
        phantom[round(m.clock.now_s)] = (int(np.count_nonzero(rock & m.world.free)), robot.drift_m)

    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario

    mission = Mission(load_scenario(scenario(tmp_path, """
  - {at_s: 20, robot: anymal, kind: localisation_drift, rate_mps: 0.1, heading_deg: 90, duration_s: 40}
""", duration_s=80)))
    mission.run(progress=watch, progress_period_s=10.0)
    assert phantom[20][1] == 0.0 and 0.5 < phantom[50][1] < 4.0
    assert phantom[60][0] > phantom[20][0] + 1000, "walls mapped at the drifted pose: rock where it is free"
    ended = events(mission, "fault_end")[0]
    assert ended["drift_m"] > phantom[50][1] and phantom[70][1] == 0.0
    robot = mission.robots["anymal"]
    assert np.allclose(robot.position, robot.true_position)


def test_a_breadcrumb_that_dies_relays_nothing(tmp_path):
    mission, report = run_scenario(scenario(tmp_path, """
  - {at_s: 5, robot: anymal, kind: breadcrumb_dies}
""", tree="anymal_explorer.yaml", duration_s=60, robot=", breadcrumbs: 1",
        extra="supervisor:\n  - {at_s: 15, robot: anymal, command: drop_breadcrumb}"))
    dropped, died = events(mission, "breadcrumb_dropped"), events(mission, "breadcrumb_died")
    assert events(mission, "fault")[0]["dropped"] is False, "not dropped yet at 5 s: it dies when dropped"
    assert len(dropped) == 1 and [e["breadcrumb"] for e in died] == [dropped[0]["name"]]
    assert died[0]["t"] - dropped[0]["t"] <= 0.2
    assert mission.radio.breadcrumbs and not mission.radio.active_breadcrumbs()


def test_a_base_station_restart_keeps_its_map_and_loses_its_blackboard(tmp_path):
    import py_trees

    from delve.executive.runner import Mission
    from delve.executive.scenario import load_scenario

    mission = Mission(load_scenario(scenario(tmp_path, "  - {at_s: 40, kind: base_restart, duration_s: 20}")))
    first = mission.agents[BASE]
    py_trees.blackboard.Blackboard.storage[f"/{BASE}/note"] = "before"
    mission.run()
    assert mission.agents[BASE] is not first and first.root.status == py_trees.common.Status.INVALID
    assert f"/{BASE}/note" not in py_trees.blackboard.Blackboard.storage
    down = samples_in(mission, 40, 60)
    assert len(down) == 4 and not any(s.linked["anymal"] for s in down)
    base = {round(s.t): s.base for s in mission.state.samples}
    assert base[40] >= base[35] > 0 and len({s.base for s in down}) == 1, "the base map outlives the restart"
    assert mission.agents[BASE].ticks > 0 and "messages_lost" in events(mission, "fault")[0]
    from delve.executive.outputs import report

    rep = report(mission, 1.0)
    assert rep["succeeded"] and the_robot(rep)["map_voxels_undelivered"] == 0


def test_a_cops_base_station_restart_replans_and_the_team_finishes(data_dir, tmp_path):
    text = (data_dir / "cops_fork.yaml").read_text().replace("cops_fork_network.yaml",
                                                              str(data_dir / "cops_fork_network.yaml"))
    base = (data_dir / "cops_base_fast.yaml").read_text().replace("../../../trees/", f"{TREES}/")
    (tmp_path / "cops_base_fast.yaml").write_text(base)  # a scenario's trees stay in its folder
    text = text.replace("../../../trees/", f"{TREES}/")
    path = tmp_path / "cops_fork_restart.yaml"
    path.write_text(text + "faults:\n  - {at_s: 150, kind: base_restart, duration_s: 30}\n")
    mission, report = run_scenario(path, tmp_path / "out")
    plans = events(mission, "cops_plan")
    assert any(e["t"] == 180.0 for e in plans), "the new leader plans as soon as it is back"
    assert report["succeeded"] and report["coverage_fraction"] == 1.0
    assert all(r["locations_undelivered"] == 0 for r in report["robots"])


def test_a_robot_that_never_leaves_its_start_is_no_success(tmp_path, capsys):
    lazy = tmp_path / "lazy_tree.yaml"
    lazy.write_text(f"""type: Sequence
name: Explore then home
memory: true
children:
  - type: ExploreNearestFrontier
    name: Explore nearest frontier
    min_cluster_voxels: 100000000
  - type: Home
    name: Return home
    path_source: navigator
""")
    path = scenario(tmp_path, "  []", tree=str(lazy), duration_s=120, name="lazy")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 1
    out = capsys.readouterr().out
    assert "lazy: FAILED" in out
    assert "why: anymal: never left its start (0.0 m travelled); exploration complete" in out
    assert "why: the team explored 0.0% of the world beyond what it saw at its start" in out
    rep = json.loads((tmp_path / "out" / "report.json").read_text(),
                     parse_constant=lambda c: pytest.fail(f"not strict JSON: {c}"))
    assert rep["succeeded"] is False and rep["robots"][0]["final_status"] == "SUCCESS"
    assert len(rep["outcome"]["reasons"]) == 2
