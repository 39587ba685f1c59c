"""COPS scenario tests: the Figure 4 trees ticked to the end on small graph worlds."""
import json
from collections import defaultdict

from delve.executive.outputs import report as make_report
from delve.executive.outputs import strip_wall_clock

from .conftest import DATA
from .conftest import run_scenario as _run


def run_scenario(path, out=None):
    mission, report = _run(path, out)
    return mission, report or make_report(mission, 1.0)


def _events(mission, name):
    return [e for e in mission.state.events if e["event"] == name]


def test_relay_chain_delivers_the_map_to_the_base(tmp_path):
    mission, report = run_scenario(DATA / "cops_chain.yaml", tmp_path)
    assert report["succeeded"], report["cops"]
    assert report["locations_known_at_base"] == report["locations"] == 9
    plans = report["cops"]["plans"]
    assert report["cops"]["plans_valid"] == len(plans)
    # some information reached the base through robots other than its owner: a relay
    assert sum(p["relayed"] for p in plans if not p["final"]) > 0
    assert all(r["returned_home"] for r in report["robots"])
    assert plans[-1]["final"]
    assert (tmp_path / "tree_base.txt").read_text().count("COPS") >= 1
    dump = (tmp_path / "tree_a.txt").read_text()
    for node in ("Leader?", "Wait to receive plan", "Explore?", "Finished plan?", "Communication action",
                 "Transition action", "Action timer", "Exploration action", "Exploration timer",
                 "Transit to return node", "Information storage"):
        assert node in dump


def test_algorithm_1_splits_five_robots_at_forks_as_in_figure_5():
    mission, report = run_scenario(DATA / "cops_fork.yaml")
    assert report["succeeded"]
    choices = [e for e in _events(mission, "exploration_choice") if len(e["choices"]) > 1]
    by_fork = defaultdict(dict)
    for e in choices:
        by_fork[e["at"]].setdefault(e["agent"], e["choice"])
    first = by_fork["f1"]  # the fork in two: indices 0, 2, 4 one way, 1, 3 the other
    assert len(first) == 5
    assert first["k0"] == first["k2"] == first["k4"] != first["k1"] == first["k3"]
    second = by_fork["l1"]
    assert len(second) == 3 and len(set(second.values())) == 3  # the three take three branches
    assert set(second) == {"k0", "k2", "k4"}
    assert report["locations_known_at_base"] == report["locations"]


def test_a_lost_robot_triggers_a_replan_and_nothing_the_survivors_found_is_lost():
    mission, report = run_scenario(DATA / "cops_lost.yaml")
    assert report["lost_robots"] == ["b"]
    assert "b" in report["declared_lost"]
    lost_at = next(e["t"] for e in mission.state.events if e["event"] == "fault")
    later = [e for e in _events(mission, "cops_plan") if e["t"] > lost_at]
    assert any("b" not in e["team"] for e in later)  # re-planned without it
    assert later[-1]["team"] == ["a", "c"]  # a robot wrongly declared lost is counted again
    assert report["succeeded"]  # the survivors finish
    survivors = set(mission.robots["a"].explored) | set(mission.robots["c"].explored)
    known = mission.team.base_state().knowledge.topology.explored
    assert survivors <= known
    assert report["cops"]["plans_valid"] == report["cops"]["cycles"]


def test_same_seed_same_report():
    reports = [strip_wall_clock(run_scenario(DATA / "cops_fork.yaml")[1]) for _ in range(2)]
    assert json.dumps(reports[0], sort_keys=True) == json.dumps(reports[1], sort_keys=True)
