"""The CERBERUS supervisor's practice on the ANYmal tree: short budgeted sorties, each
ending at home where the robot waits to be sent out again, and the supervisor's
commands obeyed at all times, also once a budget has run out."""
import numpy as np

from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario

from .conftest import DATA
from .test_cerberus import ends_well, events


def run_tracked(name: str) -> tuple[Mission, dict[float, np.ndarray]]:
    """Run a scenario of tests/scenarios/data; the robot's position every second."""
    mission = Mission(load_scenario(DATA / name))
    track: dict[float, np.ndarray] = {}
    mission.run(progress=lambda m: track.__setitem__(round(m.clock.now_s), m.robots["anymal"].position.copy()),
                progress_period_s=1.0)
    return mission, track


def moved(track: dict[float, np.ndarray], t0: float, t1: float) -> float:
    """The farthest the robot got between t0 and t1 from where it was at t0 (m)."""
    start = track[t0]
    return max(float(np.linalg.norm(p - start)) for t, p in track.items() if t0 <= t <= t1)


def test_a_robot_home_from_a_sortie_waits_and_is_sent_out_again():
    mission, track = run_tracked("cerberus_sorties.yaml")
    explore = [e["t"] for e in events(mission, "operator_command", command="explore")]
    ended = events(mission, "sortie_ended")
    assert len(ended) == 2, "each budgeted sortie ends at home, not the mission"
    first_home = ended[0]["t"]
    assert first_home < explore[1]
    # Home and waiting until the second command ...
    assert moved(track, round(first_home) + 1, explore[1] - 1) < 0.3
    # ... which sends it out again: it explores and goes beyond where it stood.
    assert [e for e in events(mission, "gbplanner_path") if explore[1] <= e["t"] < ended[1]["t"]]
    assert moved(track, explore[1], ended[1]["t"]) > 10.0
    assert len(events(mission, "homing_timer")) == 2
    # The supervisor's home ends the mission where the robot already is.
    (home,) = events(mission, "operator_command", command="home")
    assert mission.finished_s <= home["t"] + 5.0 and not mission.timed_out
    ends_well(mission)


def test_cancel_and_goto_are_obeyed_after_the_budget_ran_out():
    mission, track = run_tracked("cerberus_after_budget.yaml")
    (timer,) = events(mission, "homing_timer")
    (cancel,) = events(mission, "operator_command", command="cancel")
    (goto,) = events(mission, "operator_command", command="goto")
    (home,) = events(mission, "operator_command", command="home")
    assert timer["t"] < cancel["t"], "the budget ran out and the robot went home before the cancel"
    # Cancel: it stops where it is and stays, instead of going on home.
    assert moved(track, round(cancel["t"]) + 1, goto["t"] - 1) < 0.3
    assert np.linalg.norm(track[round(goto["t"]) - 1] - mission.robots["anymal"].home) > 2.0
    assert not [e for e in events(mission, "homing") if cancel["t"] <= e["t"] < home["t"]]
    # Goto: it goes to the waypoint, and waits there for the next command.
    reached = events(mission, "goto_reached")
    assert reached and goto["t"] < reached[0]["t"] < home["t"]
    goal = np.array(goto["goal"])
    assert np.linalg.norm(track[round(home["t"]) - 1] - goal) < 1.5
    ends_well(mission)
