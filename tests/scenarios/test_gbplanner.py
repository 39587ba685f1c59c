"""GBPlanner2's skills in whole missions: the legged explorer, the aerial stack, Backtrack
and GoTo's no_path, on small generated worlds."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from py_trees.common import Status
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario

from delve import TREES_DIR

BASE_TREE = str(TREES_DIR / "base_station.yaml")
SMALL_TUNNEL = {"generator": "tunnel_network", "total_length_m": 120, "loops": 1}
SMALL_CAVE = {"generator": "cave", "total_length_m": 120, "shaft": True, "shaft_height_m": 12}


def scenario_file(tmp: Path, name: str, world: dict, robot: dict, seed: int, duration_s: float) -> Path:
    doc = {"name": name, "seed": seed, "duration_s": duration_s, "world": world,
           "base_station": {"tree": BASE_TREE}, "robots": [{"name": robot.pop("name", "anymal"), **robot}]}
    path = tmp / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def tree_file(tmp: Path, name: str, tree: dict) -> str:
    path = tmp / f"{name}_tree.yaml"
    path.write_text(yaml.safe_dump(tree, sort_keys=False))
    return str(path)


def events(mission: Mission, kind: str) -> list[dict]:
    return [e for e in mission.state.events if e["event"] == kind]


@pytest.fixture(scope="module")
def legged(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gbplanner_legged")
    path = scenario_file(tmp, "gbplanner_small_tunnel", SMALL_TUNNEL,
                         {"platform": "legged", "tree": str(TREES_DIR / "gbplanner_explorer.yaml"),
                          "endurance_s": 900}, seed=4, duration_s=900)
    mission = Mission(load_scenario(path))
    mission.run()
    return mission


def test_the_legged_robot_explores_a_small_tunnel_network_with_gbplanner2_and_comes_home(legged):
    robot = legged.robots["anymal"]
    assert legged.succeeded
    assert legged.state.samples[-1].team >= 0.85
    assert np.linalg.norm(robot.position - robot.home) <= 1.0
    assert robot.endurance_remaining_s > 0
    assert events(legged, "exploration_complete") or events(legged, "planner_homing") or \
        events(legged, "endurance_low")
    assert {e["mode"] for e in events(legged, "gbplanner_path")} >= {"explore"}
    assert events(legged, "home_reached")


def test_gbplanner2_writes_its_state_to_the_blackboard(legged):
    import py_trees

    bb = py_trees.blackboard.Blackboard.storage
    assert bb.get("/anymal/planner_mode") in ("homing", "none", "explore", "reposition")
    assert bb.get("/anymal/last_plan_reason") in ("exploration_complete", "homing_due", "ok", "reposition")
    assert bb.get("/anymal/returned_home") is True


@pytest.fixture(scope="module")
def aerial(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gbplanner_aerial")
    path = scenario_file(tmp, "aerial_small_cave", SMALL_CAVE,
                         {"name": "obelix", "platform": "aerial", "tree": str(TREES_DIR / "aerial_explorer.yaml"),
                          "endurance_s": 510}, seed=5, duration_s=700)
    mission = Mission(load_scenario(path))
    mission.run()
    return mission


def test_the_aerial_stack_flies_the_cave_and_its_shaft_and_comes_home(aerial):
    robot = aerial.robots["obelix"]
    assert aerial.succeeded
    assert np.linalg.norm(robot.position - robot.home) <= 1.0
    assert aerial.state.samples[-1].team >= 0.8
    # Up the shaft: the upper half of it and the passage above are seen.
    g = aerial.world.centreline
    a, b = next((a, b) for a, b, d in g.edges(data=True) if d["kind"] == "shaft")
    bottom, top = sorted(float(g.nodes[n]["pos"][2]) for n in (a, b))
    idx = np.stack(np.unravel_index(aerial.backend.truth, aerial.world.free.shape), axis=1)
    upper = aerial.backend.truth[aerial.world.index_to_center(idx)[:, 2] >= (bottom + top) / 2]
    seen = robot.onboard_map.occupancy.reshape(-1)[upper] == 0
    assert len(upper) > 1000 and seen.mean() >= 0.6
    assert robot.traversed_path[:, 2].max() > bottom + 0.6 * (top - bottom)
    # Homing is the planner's: after the exploration, along its global graph.
    assert events(aerial, "homing")[0]["source"] == "gbplanner2"


def test_backtrack_returns_along_the_traversed_path(tmp_path):
    tree = {
        "type": "Sequence", "name": "Explore a minute, then backtrack", "memory": True,
        "children": [
            {"type": "FailureIsSuccess", "name": "Time up is fine",
             "child": {"type": "Timeout", "name": "One minute", "duration_s": 60.0,
                       "child": {"type": "ExploreGBPlanner2", "name": "Explore", "max_vertices": 300}}},
            {"type": "Backtrack", "name": "Backtrack", "distance_m": None},
        ],
    }
    path = scenario_file(tmp_path, "backtrack", SMALL_TUNNEL,
                         {"platform": "legged", "tree": tree_file(tmp_path, "backtrack", tree), "endurance_s": 600},
                         seed=4, duration_s=300)
    mission = Mission(load_scenario(path))
    track: list[tuple[float, np.ndarray]] = []
    mission.run(progress=lambda m: track.append((m.clock.now_s, m.robots["anymal"].position)), progress_period_s=0.5)
    assert mission.succeeded
    (start,) = events(mission, "backtrack")
    assert start["trigger"] is True
    out = np.array([p for t, p in track if t <= start["t"]])
    back = np.array([p for t, p in track if t > start["t"]])
    assert np.linalg.norm(out[-1] - out[0]) > 10.0  # it went somewhere first
    robot = mission.robots["anymal"]
    assert np.linalg.norm(robot.position - robot.home) <= 1.0
    # Every position on the way back lies on the way out.
    a, b = out[:-1], out[1:]
    ab = b - a
    for p in back:
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12), 0, 1)
        assert np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1)) <= 1.0


def test_goto_fails_with_no_path_for_a_goal_inside_rock(tmp_path):
    placeholder = tree_file(tmp_path, "placeholder", {"type": "Success"})
    world = load_scenario(scenario_file(tmp_path, "goto_rock", dict(SMALL_TUNNEL),
                                        {"platform": "legged", "tree": placeholder}, seed=4,
                                        duration_s=60)).build_world()
    goal = np.asarray(world.start, float) + np.array([0.0, 0.0, -6.0])  # deep below the floor
    assert not world.is_free(goal[None])[0]
    tree = {
        "type": "Selector", "name": "Go, or handle no path", "memory": True,
        "children": [
            {"type": "GoTo", "name": "Go to the waypoint", "goal": goal.tolist()},
            {"type": "Sequence", "name": "No path? stay home", "memory": True, "children": [
                {"type": "CheckBlackboardVariableValue", "name": "No path?", "variable_name": "goto_failure",
                 "value": "no_path", "operator": "=="},
                {"type": "Home", "name": "Home"},
            ]},
        ],
    }
    path = scenario_file(tmp_path, "goto_rock", dict(SMALL_TUNNEL),
                         {"platform": "legged", "tree": tree_file(tmp_path, "goto", tree)}, seed=4, duration_s=60)
    mission = Mission(load_scenario(path), world=world)
    mission.run()
    (failed,) = events(mission, "goto_failed")
    assert failed["goto_failure"] == "no_path"
    robot = next(a for n, a in mission.agents.items() if n != "base")
    assert robot.root.status == Status.SUCCESS  # the tree handled it
    # ... but a robot that stayed home is no successful mission, and the console says why.
    assert not mission.succeeded and "never left its start" in mission.outcome.reasons[0]
    assert mission.clock.now_s < 5.0
