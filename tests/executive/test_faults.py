"""delve.executive.faults: the registry of fault kinds, reading ``faults:``, and the
schedule that starts, steps and ends faults (malformed entries: the
tests/data/malformed_scenarios corpus, files fault_*.yaml)."""
from pathlib import Path
from types import SimpleNamespace

import pytest

from delve.executive.errors import DelveError
from delve.executive.faults import FAULT_KINDS, Fault, Target, register_fault
from delve.executive.faults.base import LINK, NEVER, ROBOT
from delve.executive.faults.schedule import FaultSchedule
from delve.executive.scenario import load_scenario

TREES = Path(__file__).parent.parent.parent / "trees"
ISSUE_KINDS = {"stuck", "lost", "map_artifact", "radio_blackout", "lidar_degraded", "lidar_dropout",
               "planner_error", "planner_slow", "battery_drop", "localisation_drift", "breadcrumb_dies",
               "base_restart"}


def scenario(tmp_path: Path, faults: str, tree: str = "anymal_explorer.yaml", extra: str = "") -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(f"""name: s
world: {{generator: tunnel_network, total_length_m: 120, loops: 0}}
base_station: {{tree: {TREES / 'base_station.yaml'}}}
robots:
  - {{name: anymal, platform: legged, tree: {TREES / tree}, breadcrumbs: 2{extra}}}
  - {{name: spot, platform: legged, tree: {TREES / tree}}}
faults:
{faults}
""")
    return path


def test_every_kind_of_the_issue_is_registered_with_a_docstring():
    assert ISSUE_KINDS <= set(FAULT_KINDS)
    for name, cls in FAULT_KINDS.items():
        assert cls.KIND == name and cls.__doc__ and cls.TARGETS
        assert cls.DURATION in ("required", "optional", "never")


def test_faults_are_read_with_their_targets_parameters_and_ends(tmp_path):
    s = load_scenario(scenario(tmp_path, """
  - {at_s: 30, robot: anymal, kind: lidar_degraded, range_m: 5, duration_s: 20}
  - {at_s: 10, link: [base, spot], kind: radio_blackout, duration_s: 60}
  - {at_s: 10, base_station: true, kind: radio_blackout}
  - {at_s: 40, kind: base_restart, duration_s: 15}
  - {at_s: 50, robot: anymal, kind: planner_slow, delay_s: 12}
  - {at_s: 60, robot: anymal, kind: breadcrumb_dies, number: 2}
"""))
    kinds = [(f.KIND, str(f.target), f.at_s, f.end_s) for f in s.faults]
    assert kinds == [("radio_blackout", "base <-> spot", 10.0, 70.0),
                     ("radio_blackout", "base station", 10.0, None), ("lidar_degraded", "anymal", 30.0, 50.0),
                     ("base_restart", "base station", 40.0, 55.0), ("planner_slow", "anymal", 50.0, None),
                     ("breadcrumb_dies", "anymal", 60.0, None)]
    assert s.faults[2].p == {"range_m": 5.0, "ray_fraction": 1.0}
    assert s.faults[4].p == {"delay_s": 12.0}
    assert s.faults[0].fields() == {"kind": "radio_blackout", "link": ["base", "spot"], "duration_s": 60.0}


def test_a_kind_that_hits_only_the_base_station_needs_no_target(tmp_path):
    s = load_scenario(scenario(tmp_path, "  - {at_s: 5, kind: base_restart}"))
    assert s.faults[0].target == Target("base_station") and s.faults[0].end_s is None


@pytest.mark.parametrize("entry, message", [
    ("{at_s: 5, robot: anymal, kind: lost, duration_s: 3}", "does not end"),
    ("{at_s: 5, robot: anymal, kind: battery_drop, drop_fraction: 0}", "drop_fraction must be > 0.0"),
    ("{at_s: 5, robot: anymal, kind: localisation_drift, rate: 0.1}", "did you mean 'rate_mps'"),
    ("{at_s: 5, robot: anymal, kind: base_restart}", "hits the base station, not a robot"),
    ("{at_s: 5, link: [anymal], kind: radio_blackout}", "link"),
    ("{at_s: 5, robot: anymal, kind: breadcrumb_dies, number: 3}", "carries 2 breadcrumbs"),
    ("{at_s: 5, robot: spot, kind: breadcrumb_dies}", "carries 0 breadcrumbs"),
])
def test_wrong_entries_are_one_line_at_their_key(tmp_path, entry, message):
    path = scenario(tmp_path, f"  - {entry}")
    with pytest.raises(DelveError, match=message) as err:
        load_scenario(path)
    assert err.value.line == 8 and "\n" not in str(err.value)


def test_planner_faults_need_a_robot_that_plans_with_gbplanner2(tmp_path):
    load_scenario(scenario(tmp_path, "  - {at_s: 5, robot: anymal, kind: planner_error}"))
    with pytest.raises(DelveError, match="does not plan with GBPlanner2"):
        load_scenario(scenario(tmp_path, "  - {at_s: 5, robot: anymal, kind: planner_error}",
                               tree="frontier_explorer.yaml"))


class Recorder(Fault):
    """A fault for the tests: it records what the schedule calls."""

    KIND = "recorder"
    TARGETS = (ROBOT, LINK)
    DURATION = "optional"

    def start(self, mission):
        mission.calls.append(("start", self.at_s, mission.now))
        return {"started": True}

    def step(self, mission, now_s):
        mission.calls.append(("step", self.at_s, now_s))

    def end(self, mission):
        mission.calls.append(("end", self.at_s, mission.now))
        return {}


def test_the_schedule_starts_steps_and_ends_faults_in_time_order():
    events = []
    mission = SimpleNamespace(calls=[], now=0.0, lost={"gone": "lost (fault)"},
                              log=lambda event, **f: events.append((event, f)))
    schedule = FaultSchedule([Recorder(2.0, Target(ROBOT, ("r",)), 1.0), Recorder(1.0, Target(ROBOT, ("r",))),
                              Recorder(1.0, Target(ROBOT, ("gone",)))])
    for t in (0.0, 1.0, 2.0, 3.0):
        mission.now = t
        schedule.update(mission, t)
    assert mission.calls == [("start", 1.0, 1.0), ("step", 1.0, 1.0), ("start", 2.0, 2.0), ("step", 1.0, 2.0),
                             ("step", 2.0, 2.0), ("step", 1.0, 3.0), ("end", 2.0, 3.0)]
    assert [e for e, _ in events] == ["fault", "fault", "fault", "fault_end"]
    assert events[1][1]["skipped"] == "robot gone is lost" and events[0][1]["started"] is True


def test_a_registered_kind_can_be_used_by_a_scenario(tmp_path):
    register_fault(Recorder)
    try:
        entry = "  - {at_s: 5, link: [anymal, spot], kind: recorder, duration_s: 2}"
        s = load_scenario(scenario(tmp_path, entry))
        assert isinstance(s.faults[0], Recorder) and s.faults[0].end_s == 7.0
    finally:
        del FAULT_KINDS["recorder"]


def test_kinds_that_cannot_end_take_no_duration():
    assert FAULT_KINDS["lost"].DURATION == NEVER and FAULT_KINDS["stuck"].DURATION == "required"


def test_the_docs_list_every_kind():
    table = (Path(__file__).parent.parent.parent / "docs" / "scenarios.md").read_text()
    for name in FAULT_KINDS:
        assert f"| `{name}` |" in table, name


def test_overlapping_faults_of_a_kind_add_up(tmp_path):
    """A radio is back, a sensor restored, only when no active fault holds it any more."""
    from delve.executive.runner import Mission

    s = load_scenario(scenario(tmp_path, """
  - {at_s: 0, robot: anymal, kind: radio_blackout, duration_s: 2}
  - {at_s: 0.5, robot: anymal, kind: radio_blackout, duration_s: 0.5}
  - {at_s: 0, robot: anymal, kind: lidar_degraded, range_m: 5, duration_s: 2}
  - {at_s: 0.5, robot: anymal, kind: lidar_dropout, duration_s: 0.5}
  - {at_s: 0, link: [anymal, spot], kind: radio_blackout, duration_s: 2}
  - {at_s: 0.5, kind: base_restart, duration_s: 0.5}
""", tree="frontier_explorer.yaml"))
    m = Mission(s, duration_s=3.0)
    seen = {}

    def watch(mission):
        robot = mission.robots["anymal"]
        seen[round(mission.clock.now_s, 1)] = (mission.radio.endpoints["anymal"].blackout,
                                               mission.radio.endpoints["base"].blackout,
                                               sorted(mission.radio.cut_links),
                                               [round(spec.range_m) for spec, _ in robot._sensors])
    m.run(progress=watch, progress_period_s=0.5)
    assert seen[0.5] == (True, True, [("anymal", "spot")], [])
    assert seen[1.0] == (True, False, [("anymal", "spot")], [5, 4]), "the shorter fault's end frees nothing"
    assert seen[2.0] == (False, False, [], [30, 4])
