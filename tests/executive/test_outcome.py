"""delve.executive.outcome: the verdict on a mission, the same for every team
strategy; report.json is strict JSON; COPS robots count what they did not deliver."""
import json
import math
from types import SimpleNamespace

import numpy as np
import py_trees
from py_trees.common import Status

from delve.executive.outcome import (MIN_DISTANCE_M, Outcome, failing_node, failure_event, mission_outcome)
from delve.executive.outputs import finite
from delve.executive.teams import Cops, Independent
from delve.skills.cops import CopsState


def tree(*statuses: Status, selector: bool = False) -> py_trees.behaviour.Behaviour:
    """A composite whose children ended with ``statuses``; the root ended FAILURE."""
    kind = py_trees.composites.Selector if selector else py_trees.composites.Sequence
    children = [py_trees.behaviours.Dummy(f"c{i}") for i in range(len(statuses))]
    root = kind("Root", memory=True, children=children)
    for child, status in zip(root.children, statuses):
        child.status = status
    root.status = Status.FAILURE
    return root


def test_the_failing_node_is_found_down_the_failure_children():
    assert failing_node(tree(Status.SUCCESS, Status.FAILURE, Status.INVALID)).name == "c1"
    assert failing_node(tree(Status.FAILURE, Status.FAILURE, selector=True)).name == "c1"
    assert failing_node(tree(Status.SUCCESS)).name == "Root"


def test_the_failure_event_is_the_agents_last():
    events = [{"event": "explore_failed", "agent": "a", "reason": "error", "detail": "boom"},
              {"event": "homing_failed", "agent": "b", "reason": "blocked"},
              {"event": "frontier_goal", "agent": "a"}]
    assert failure_event(events, "a") == "explore_failed: error, boom"
    assert failure_event(events, "b") == "homing_failed: blocked"
    assert failure_event(events, "c") is None


def agent(name, status, node_name="Explore"):
    root = py_trees.behaviours.Dummy(node_name)
    root.status = status
    return SimpleNamespace(name=name, root=root)


def mission(statuses, distances, coverage=(0.05, 0.6), lost=None, events=(), team=None, timed_out=False):
    agents = {n: agent(n, s) for n, s in statuses.items()}
    lost = dict(lost or {})
    return SimpleNamespace(
        agents=agents, robot_agents=[a for n, a in agents.items() if n not in lost], lost=lost,
        robots={n: SimpleNamespace(distance_m=d) for n, d in distances.items()},
        state=SimpleNamespace(events=list(events), samples=[SimpleNamespace(team=c) for c in coverage]),
        team=team or Independent(), timed_out=timed_out, duration_s=600.0)


def test_a_mission_whose_robots_succeeded_and_explored_succeeded():
    out = mission_outcome(mission({"a": Status.SUCCESS}, {"a": 120.0}))
    assert out == Outcome(True, False, (), {}, ())


def test_every_failure_is_explained():
    events = [{"event": "explore_failed", "agent": "a", "reason": "invalid_start",
               "detail": "start position is invalid"}]
    out = mission_outcome(mission({"a": Status.FAILURE, "b": Status.INVALID}, {"a": 30.0, "b": 40.0},
                                  events=events, timed_out=True))
    assert not out.succeeded and out.timed_out
    assert out.reasons == (
        "a: FAILURE at 'Explore': explore_failed: invalid_start, start position is invalid",
        "b: had not finished when the run stopped at its duration (600 s)")


def test_a_robot_that_never_left_its_start_is_no_success_even_when_its_tree_succeeded():
    events = [{"event": "exploration_complete", "agent": "a", "blacklisted_voxels": 400}]
    out = mission_outcome(mission({"a": Status.SUCCESS}, {"a": 0.4 * MIN_DISTANCE_M}, events=events))
    assert not out.succeeded
    assert out.reasons[0] == ("a: never left its start (0.4 m travelled); exploration complete with 400 "
                              "frontier voxels blacklisted")


def test_a_team_that_explored_nothing_when_much_was_left_is_no_success():
    out = mission_outcome(mission({"a": Status.SUCCESS}, {"a": 50.0}, coverage=(0.05, 0.06)))
    assert not out.succeeded and "explored 1.0% of the world beyond" in out.reasons[0]
    # Almost all of it seen from the start: nothing was left to explore.
    assert mission_outcome(mission({"a": Status.SUCCESS}, {"a": 50.0}, coverage=(0.95, 0.95))).succeeded


def test_lost_robots_are_listed_and_do_not_fail_the_team_unless_none_is_left():
    out = mission_outcome(mission({"a": Status.SUCCESS, "b": Status.INVALID}, {"a": 50.0, "b": 0.0},
                                  lost={"b": "endurance exhausted"}))
    assert out.succeeded and out.lost == {"b": "endurance exhausted"}
    out = mission_outcome(mission({"a": Status.INVALID}, {"a": 10.0}, lost={"a": "lost (fault)"}))
    assert not out.succeeded and out.reasons == ("every robot was lost: a (lost (fault))",)


def test_a_success_after_a_failed_exploration_has_a_note():
    events = [{"event": "explore_failed", "agent": "a", "reason": "error",
               "detail": "InjectedPlannerError: x"}]
    out = mission_outcome(mission({"a": Status.SUCCESS}, {"a": 50.0}, events=events))
    assert out.succeeded
    assert out.notes == ("a: SUCCESS, but its exploration ended with explore_failed: error, "
                         "InjectedPlannerError: x",)
    for end in ("exploration_complete", "exploration_over"):   # a later end: the failure was recovered from
        later = events + [{"event": end, "agent": "a"}]
        assert mission_outcome(mission({"a": Status.SUCCESS}, {"a": 50.0}, events=later)).notes == ()


def test_cops_judges_the_base_station_too():
    m = mission({"a": Status.SUCCESS, "base": Status.FAILURE}, {"a": 50.0}, team=Cops())
    m.robot_agents = [m.agents["a"]]
    out = mission_outcome(m)
    assert not out.succeeded and out.reasons == ("base: FAILURE at 'Explore'",)


def test_cops_robots_count_the_locations_and_map_chunks_the_base_station_lacks():
    cops = Cops()
    base, robot = CopsState(), CopsState()
    base.knowledge.topology.explored.update({"s0", "s1"})
    robot.knowledge.topology.explored.update({"s0", "s1", "s2", "s3"})
    robot.knowledge.map_chunks.update({"r1/0": (), "r1/1": (), "r2/0": ()})
    base.knowledge.map_chunks.update({"r1/0": ()})
    cops.base_state = lambda: base
    leader = SimpleNamespace(stored_state=lambda: robot)
    import delve.executive.teams.cops as cops_module

    original = cops_module._cops_skill
    cops_module._cops_skill = lambda root: leader
    try:
        m = SimpleNamespace(agents={"r1": SimpleNamespace(root=None)},
                            backend=SimpleNamespace(map_undelivered=lambda name: 12))
        assert cops.robot_figures(m, "r1") == {"map_voxels_undelivered": 12, "locations_undelivered": 2,
                                               "map_chunks_undelivered": 1}
        m.backend = SimpleNamespace(map_undelivered=lambda name: None)
        assert cops.robot_figures(m, "r1") == {"locations_undelivered": 2}
    finally:
        cops_module._cops_skill = original


def test_reports_are_strict_json():
    rep = finite({"a": math.inf, "b": [1.0, -math.inf, math.nan], "c": np.float64(2.5), "d": np.array([1, 2]),
                  "e": (np.int64(3),), "f": "x"})
    assert rep == {"a": None, "b": [1.0, None, None], "c": 2.5, "d": [1, 2], "e": [3], "f": "x"}
    json.dumps(rep, allow_nan=False)
