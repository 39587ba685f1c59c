"""COHORT missions to the end (small worlds, short runs): the lost-link rule, the hub
sending two robots into different branches of a fork, and determinism."""
import json

import numpy as np
import pytest

from delve.executive.outputs import strip_wall_clock

from .conftest import DATA, run_scenario

pytestmark = pytest.mark.slow


def robot_events(mission, robot: str) -> list[dict]:
    return [e for e in mission.state.events if e.get("agent") == robot and e["event"].startswith("cohort_")]


def test_out_of_reach_at_its_call_the_robot_explores_t_ce_more_then_backtracks_toward_its_last_link_point():
    mission, _ = run_scenario(DATA / "cohort_lost_link.yaml")
    params = mission.team.cohort
    events = robot_events(mission, "a")
    calls = [e for e in events if e["event"] == "cohort_call"]
    # A call in reach stores a link point; a later call finds the hub out of reach, and
    # the robot goes back to where it last spoke to the hub.
    first_reached = next(e for e in calls if e["reached"])
    failed = next(e for e in calls if not e["reached"] and e["t"] > first_reached["t"])
    last_link = [e for e in calls if e["reached"] and e["t"] < failed["t"]][-1]
    after = [e for e in events if e["t"] >= failed["t"]]
    assert after[1]["event"] == "cohort_extra_exploration"  # the box was not explored
    back = next(e for e in after if e["event"] == "cohort_backtrack")
    assert back["t"] == pytest.approx(failed["t"] + params.extra_explore_s, abs=0.3)
    assert back["to"] == last_link["position"]
    assert np.linalg.norm(np.subtract(last_link["position"][:2], mission.robots["a"].home[:2])) > 5.0
    # On the way it pings the hub; here the link comes back before the point, where it
    # calls again (arriving at the point is tested in tests/skills/cohort/test_robot.py).
    regained = next(e for e in after if e["event"] in ("cohort_link_regained", "cohort_link_point"))
    assert regained["event"] == "cohort_link_regained" and regained["to"] == last_link["position"]
    left = np.linalg.norm(np.subtract(back["position"], last_link["position"]))
    assert np.linalg.norm(np.subtract(regained["at"], last_link["position"])) < left - 10.0
    again = next(e for e in after if e["event"] == "cohort_call" and e["t"] >= regained["t"])
    assert again["reached"] is True and again["t"] == regained["t"]


def test_the_hub_sends_two_robots_into_different_branches_of_a_fork():
    """The fork is at the portal: one tunnel runs north (y > 0), one south."""
    mission, _ = run_scenario(DATA / "cohort_fork.yaml")
    first = {r: next(e for e in robot_events(mission, r) if e["event"] == "cohort_assignment_received")
             for r in ("a", "b")}
    assert all(f["frontier"] is not None for f in first.values())
    assert np.sign(first["a"]["frontier"][1]) != np.sign(first["b"]["frontier"][1])
    # Each robot goes deep into the branch it was sent to and, once there, never into the
    # other one (before its first call it explored on its own, in either branch; by the
    # end of the run, out of reach, it may be on its way back to a link).
    for r in ("a", "b"):
        y = np.array([s.positions[r][1] for s in mission.state.samples if s.t >= first[r]["t"]])
        y *= np.sign(first[r]["frontier"][1])
        inside = np.flatnonzero(y > 3.0)
        assert len(inside) and y.max() > 10.0 and y[inside[0]:].min() > -3.0, r


def test_the_robots_explore_on_while_they_call_and_only_a_frontier_stops_the_explorer():
    mission, _ = run_scenario(DATA / "cohort_fork.yaml")
    for r in ("a", "b"):
        events = [e for e in mission.state.events if e.get("agent") == r]
        halted = {e["t"] for e in events if e["event"] == "status" and e["node"] == "Explore (GBPlanner2)"
                  and e["old"] == "RUNNING" and e["new"] == "INVALID"}
        calls = {e["request_id"]: e for e in events if e["event"] == "cohort_call" and e["reached"]
                 and e["node"] == "Call the hub while exploring"}
        answers = [e for e in events
                   if e["event"] == "cohort_assignment_received" and e["request_id"] in calls]
        assert answers, r
        for answer in answers:
            call = calls[answer["request_id"]]
            assert answer["t"] > call["t"], (r, call)
            assert not any(call["t"] <= t < answer["t"] for t in halted), (r, call)
            assert (answer["t"] in halted) == (answer["frontier"] is not None), (r, answer)


def test_same_seed_same_report_and_log(tmp_path):
    _, a = run_scenario(DATA / "cohort_fork.yaml", tmp_path / "a")
    _, b = run_scenario(DATA / "cohort_fork.yaml", tmp_path / "b")
    assert json.dumps(strip_wall_clock(a)) == json.dumps(strip_wall_clock(b))
    assert a["cohort"]["submaps_at_hub"] > 0 and len(a["cohort"]["assignments"]) >= 2
    assert (tmp_path / "a" / "log.jsonl").read_bytes() == (tmp_path / "b" / "log.jsonl").read_bytes()


def test_once_the_hub_knows_no_frontier_left_the_robots_go_home():
    """The fork's network is small: the common map closes, every robot's next call is
    answered ``explored``, and each goes home at once (no more T_C cycles)."""
    mission, report = run_scenario(DATA / "cohort_fork.yaml", duration_s=600)
    for r in ("a", "b"):
        answers = [e for e in robot_events(mission, r) if e["event"] == "cohort_assignment_received"]
        assert answers[-1]["reason"] == "explored" and all(a["reason"] != "explored" for a in answers[:-1])
        homing = next(e for e in mission.state.events if e.get("agent") == r and e["event"] == "homing")
        assert homing["t"] - answers[-1]["t"] < 1.0
    assert mission.outcome.succeeded and mission.finished_s < 300
    assert mission.state.samples[-1].team > 0.95
