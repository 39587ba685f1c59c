"""delve.skills.operator: ProcessOperatorCommands turns the supervisor's commands, as they
arrive over the fake robot's radio, into blackboard state for the tree."""
from __future__ import annotations

import py_trees
import pytest
from delve.executive.errors import DelveError
from delve.planners.gbplanner2 import synthetic as syn
from delve.skills.base import mailbox
from delve.skills.operator import COMMAND, COMMANDS, MODES, TASKS
from py_trees.common import Status

from .fakes import FakeRobot, bb, body, build, events, make_ctx

KEYS = ("mode", "time_budget_s", "budget_start_s", "goal", "goal_source", "exploration_bbox",
        "inspection_request", "breadcrumb_request", "end_at_home", "autonomous_scans", "last_command")


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=30)


@pytest.fixture()
def agent(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 5.0))
    ctx = make_ctx(robot)
    node = build("type: ProcessOperatorCommands", ctx)
    node.setup()
    return robot, ctx, node


def command(robot, name: str, **args) -> None:
    robot.radio.deliver("base", COMMAND, {"command": name, "args": args})


def state() -> dict:
    return {k: bb(k) for k in KEYS}


def test_setup_writes_the_initial_state(agent):
    assert state() == {"mode": "idle", "time_budget_s": None, "budget_start_s": None, "goal": None,
                       "goal_source": None, "exploration_bbox": None, "inspection_request": None,
                       "breadcrumb_request": False, "end_at_home": True, "autonomous_scans": False,
                       "last_command": None}


def test_the_initial_mode_is_a_parameter(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a, 5.0)))
    build("type: ProcessOperatorCommands\ninitial_mode: explore", ctx).setup()
    assert bb("mode") == "explore"
    with pytest.raises(DelveError, match="initial_mode"):
        build("type: ProcessOperatorCommands\ninitial_mode: wander", ctx)
    assert "explore" in MODES and "wander" not in MODES


def test_nothing_changes_while_no_command_arrives(agent):
    robot, ctx, node = agent
    before = state()
    robot.radio.link_up = False
    for t in range(5):
        ctx.clock.now_s = float(t)
        node.tick_once()
        assert node.status == Status.RUNNING  # a background task
    assert state() == before and ctx.events == []


#: Each command with arguments, and what it writes (on top of ``last_command``) at 42 s.
CASES = {
    "explore": ({"budget_s": 300.0}, {"mode": "explore", "time_budget_s": 300.0, "budget_start_s": 42.0,
                                      "end_at_home": False}),
    "set_bbox": ({"min": [0, -5, 0], "max": [40, 5, 4]}, {"exploration_bbox": [[0, -5, 0], [40, 5, 4]]}),
    "home": ({}, {"mode": "home"}),
    "cancel": ({}, {"mode": "idle", "end_at_home": False}),
    "relocate": ({}, {"mode": "relocate", "end_at_home": False}),
    "scan": ({"point": [12.0, 6.0, 1.5]},
             {"inspection_request": {"point": [12.0, 6.0, 1.5], "requested_s": 42.0}}),
    "goto": ({"goal": [20.0, 6.0, 1.5]},
             {"mode": "goto", "goal": [20.0, 6.0, 1.5], "goal_source": "supervisor", "end_at_home": False}),
    "drop_breadcrumb": ({}, {"breadcrumb_request": True}),
    "autonomous_scans": ({"enabled": True}, {"autonomous_scans": True}),
}


def test_every_supervisor_command_is_covered_here():
    assert set(CASES) == set(COMMANDS)


@pytest.mark.parametrize("name", sorted(CASES))
def test_each_command_writes_its_state_and_logs_a_trigger(agent, name):
    robot, ctx, node = agent
    args, writes = CASES[name]
    before = state()
    ctx.clock.now_s = 42.0
    command(robot, name, **args)
    node.tick_once()
    assert node.status == Status.RUNNING
    assert state() == {**before, **writes, "last_command": name}
    (logged,) = events(ctx, "operator_command")
    assert logged == {"agent": "r1", "node": "ProcessOperatorCommands", "trigger": True, "command": name,
                      **args}


def test_explore_without_a_budget_clears_the_last_budget(agent):
    robot, ctx, node = agent
    ctx.clock.now_s = 10.0
    command(robot, "explore", budget_s=120.0)
    node.tick_once()
    assert (bb("time_budget_s"), bb("budget_start_s")) == (120.0, 10.0)
    ctx.clock.now_s = 20.0
    command(robot, "explore")
    node.tick_once()
    assert bb("mode") == "explore" and (bb("time_budget_s"), bb("budget_start_s")) == (None, None)


def test_a_budget_starts_when_the_command_arrives(agent):
    """Sent at 5 s while the link was down, delivered at 60 s: the robot could not have
    started on it before."""
    robot, ctx, node = agent
    ctx.clock.now_s = 60.0
    robot.radio.deliver("base", COMMAND, {"command": "explore", "args": {"budget_s": 100.0}}, sent_s=5.0)
    node.tick_once()
    assert bb("budget_start_s") == 60.0
    timer = build("type: BudgetElapsed", ctx)
    for now, expected in ((159.0, Status.FAILURE), (160.0, Status.SUCCESS)):
        ctx.clock.now_s = now
        timer.tick_once()
        assert timer.status == expected


def test_cancel_stops_the_robot(agent):
    robot, ctx, node = agent
    command(robot, "goto", goal=[20.0, 6.0, 1.5])
    node.tick_once()
    robot.follow_path([[20.0, 6.0, 1.5]])
    command(robot, "cancel")
    node.tick_once()
    assert bb("mode") == "idle" and robot.stops == 1 and robot.path_status.value == "idle"
    assert bb("goal") == [20.0, 6.0, 1.5]  # kept: the mode says it is not wanted


def test_commands_arriving_together_apply_in_order(agent):
    robot, ctx, node = agent
    command(robot, "goto", goal=[20.0, 6.0, 1.5])
    command(robot, "drop_breadcrumb")
    command(robot, "home")
    node.tick_once()
    assert bb("mode") == "home" and bb("last_command") == "home"  # the latest command wins
    assert bb("goal") == [20.0, 6.0, 1.5] and bb("breadcrumb_request") is True
    assert [e["command"] for e in events(ctx, "operator_command")] == ["goto", "drop_breadcrumb", "home"]


def test_other_messages_are_not_commands_and_stay_for_their_takers(agent):
    robot, ctx, node = agent
    before = state()
    robot.radio.deliver("base", "map_delta", {"flat": [1, 2], "values": [0, 0]})
    robot.radio.deliver("r2", "report", {"command": "home"})
    robot.radio.deliver("r2", "report", {"n": 2})
    node.tick_once()
    assert state() == before and not events(ctx, "operator_command")
    box = mailbox(ctx, robot.radio)
    assert [m.data for m in box.take("report")] == [{"command": "home"}, {"n": 2}]
    assert box.take("report") == [] and [m.kind for m in box.take("map_delta")] == ["map_delta"]


@pytest.mark.parametrize("name", TASKS)
def test_a_task_replaces_the_running_budget(agent, name):
    """A budget belongs to its explore task: any later task clears it (explore with a
    budget sets a new one), so the homing timer cannot outrank the supervisor's next
    command."""
    robot, ctx, node = agent
    ctx.clock.now_s = 10.0
    command(robot, "explore", budget_s=120.0)
    node.tick_once()
    ctx.clock.now_s = 200.0
    command(robot, name, **({"goal": [1.0, 2.0, 0.5]} if name == "goto" else {}))
    node.tick_once()
    assert (bb("time_budget_s"), bb("budget_start_s")) == (None, None)
    assert bb("end_at_home") is (name == "home")


def test_homing_ends_the_mission_only_when_the_supervisor_calls_the_robot_home(agent):
    robot, ctx, node = agent
    assert bb("end_at_home") is True  # no supervisor yet: the mission ends at home
    for name, expected in (("explore", False), ("scan", False), ("home", True), ("goto", False),
                           ("drop_breadcrumb", False), ("home", True)):
        command(robot, name, **({"goal": [1.0, 2.0, 0.5]} if name == "goto" else {}))
        node.tick_once()
        assert bb("end_at_home") is expected, name
