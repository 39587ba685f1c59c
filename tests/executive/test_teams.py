"""delve.executive.teams: strategies by name, the legacy rule, and the default
end and success rules on agents that are not ticked."""
from types import SimpleNamespace

from py_trees.common import Status

from delve.executive.teams import (TEAM_STRATEGIES, TeamStrategy, implied_strategy, register_team,
                                   wall_clock_fields)
from delve.executive.teams.cops import Cops
from delve.executive.teams.independent import Independent
from delve.skills.cops import SolveCOPS
from delve.skills.motion import GoTo


def agents(*statuses: Status) -> SimpleNamespace:
    return SimpleNamespace(robot_agents=[SimpleNamespace(name=f"r{i}", root=SimpleNamespace(status=s),
                                                         finished=s in (Status.SUCCESS, Status.FAILURE))
                                         for i, s in enumerate(statuses)])


def test_shipped_strategies_are_registered():
    assert TEAM_STRATEGIES["independent"] is Independent and TEAM_STRATEGIES["cops"] is Cops


def test_independent_is_over_when_every_robot_finished_and_succeeds_when_each_succeeded():
    team = Independent()
    assert not team.done(agents(Status.SUCCESS, Status.RUNNING))
    assert team.done(agents(Status.SUCCESS, Status.FAILURE)) and not team.succeeded(agents(Status.SUCCESS, Status.FAILURE))
    assert team.succeeded(agents(Status.SUCCESS, Status.SUCCESS))
    assert team.figures(agents()) == {} and team.explored_at_base() == set()


def test_cops_is_implied_by_its_behaviours_only():
    assert implied_strategy({GoTo, SolveCOPS}) == "cops"
    assert implied_strategy({GoTo}) is None


def test_cops_parameters_default_to_the_papers_lattice_and_its_solve_times_are_wall_clock():
    assert Cops().params == {"cell_m": 8.0} and Cops(cell_m=4.0).params == {"cell_m": 4.0}
    assert "cops_solve_time_s" in wall_clock_fields()


def test_a_registered_strategy_is_found_by_name():
    class FirstHome(TeamStrategy):
        """Over as soon as one robot has finished."""

        def done(self, mission):
            return any(a.finished for a in mission.robot_agents)

    register_team("first_home", FirstHome)
    try:
        assert TEAM_STRATEGIES["first_home"]().done(agents(Status.RUNNING, Status.SUCCESS))
    finally:
        del TEAM_STRATEGIES["first_home"]
