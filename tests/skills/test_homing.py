"""delve.skills.homing: EnduranceLow, and Home along the navigation graph of the onboard
map (``path_source: navigator``, formerly ``ReturnHome``), built from YAML and ticked on
the fake robot (their behaviour only: what they write, command and log). Home along
GBPlanner2's graph is tested in test_gbplanner.py."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.executive.errors import DelveDeprecation
from delve.planners.gbplanner2 import synthetic as syn
from py_trees.common import Status

from .fakes import TREES, FakeRobot, bb, body, build, events, make_ctx, run

#: Home on the shortest path of the onboard map's navigation graph.
RETURN_HOME = "type: Home\npath_source: navigator"
HOME = np.array([5.0, 4.0, 1.5])
#: The far end of the U, 6 m from HOME as the crow flies and 46 m on foot.
FAR_SIDE = np.array([5.0, 12.0, 1.5])


@pytest.fixture(scope="module")
def u_tunnel():
    """Two parallel 22 m tunnels 8 m apart, joined at their far ends (3 m wide, floor at
    z = 1 m), all mapped."""
    return syn.carve((32, 18, 5), 0.2, [syn.Tunnel((4, 4, 1), (26, 4, 1), 3.0, 3.0),
                                         syn.Tunnel((26, 4, 1), (26, 12, 1), 3.0, 3.0),
                                         syn.Tunnel((26, 12, 1), (4, 12, 1), 3.0, 3.0)])


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=30)


def path_length(path) -> float:
    return float(np.linalg.norm(np.diff(np.asarray(path), axis=0), axis=1).sum())


# ---------------------------------------------------------------------- EnduranceLow


def test_the_way_home_is_the_path_on_the_map_not_the_straight_line(u_tunnel):
    robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
    ctx = make_ctx(robot)
    low = build("type: EnduranceLow", ctx)
    low.tick_once()
    assert low.status == Status.FAILURE  # 3000 s left
    assert 44.0 <= bb("time_to_home_s") <= 50.0  # round the U at 1 m/s, not 6 m * detour_factor
    assert not events(ctx, "endurance_low")


def test_time_to_home_is_at_the_robots_speed(u_tunnel):
    robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
    ctx = make_ctx(robot)
    build("type: EnduranceLow", ctx).tick_once()
    at_1_mps = bb("time_to_home_s")
    py_trees.blackboard.Blackboard.clear()
    slow = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
    slow.mobility.speed_mps = 0.5
    ctx = make_ctx(slow)
    build("type: EnduranceLow", ctx).tick_once()
    assert bb("time_to_home_s") == pytest.approx(2 * at_1_mps, abs=0.02)


@pytest.mark.parametrize("safety_factor, margin_s", [(1.2, 60.0), (2.0, 0.0)])
def test_endurance_low_when_the_reserve_barely_covers_the_way_home(u_tunnel, safety_factor, margin_s):
    text = f"type: EnduranceLow\nsafety_factor: {safety_factor}\nmargin_s: {margin_s}"
    robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
    build(text, make_ctx(robot)).tick_once()
    needed = safety_factor * bb("time_to_home_s") + margin_s
    for endurance_s, expected in ((needed + 0.5, Status.FAILURE), (needed - 0.5, Status.SUCCESS)):
        py_trees.blackboard.Blackboard.clear()
        robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME, endurance_s=endurance_s)
        ctx = make_ctx(robot)
        low = build(text, ctx)
        low.tick_once()
        assert low.status == expected
    (fired,) = events(ctx, "endurance_low")
    assert fired["trigger"] is True
    assert fired["endurance_s"] == pytest.approx(needed - 0.5, abs=0.1)
    assert fired["time_to_home_s"] == pytest.approx(bb("time_to_home_s"), abs=0.1)
    assert robot.paths == [] and robot.stops == 0  # a condition: it commands nothing


def test_without_a_path_home_the_straight_line_times_the_detour_factor(tunnel):
    grid, a, _ = tunnel
    home = body(a, 2.0) + np.array([0.0, 0.0, 30.0])  # far above the map: no path there
    robot = FakeRobot(grid, body(a, 15.0), home=home)
    straight = float(np.linalg.norm(robot.position - home))
    build("type: EnduranceLow", make_ctx(robot)).tick_once()
    assert bb("time_to_home_s") == pytest.approx(1.5 * straight, abs=0.01)
    py_trees.blackboard.Blackboard.clear()
    build("type: EnduranceLow\ndetour_factor: 2.0", make_ctx(robot)).tick_once()
    assert bb("time_to_home_s") == pytest.approx(2.0 * straight, abs=0.01)


def test_endurance_low_is_never_late_for_a_robot_walking_away():
    """Endurance drains at 1 s per s while the robot walks away from home: the check
    fires at the first tick at which the reserve no longer covers the way home, though
    it re-plans the way home only now and then."""
    grid, a, _ = syn.straight_tunnel(length_m=60)
    home = body(a, 2.0)
    robot = FakeRobot(grid, home, home=home, endurance_s=140.0)
    ctx = make_ctx(robot)
    low = build("type: EnduranceLow\ncheck_period_s: 5.0", ctx)
    robot.follow_path([body(a, 57.0)])
    fired_at, planned = None, set()
    for t in range(100):
        low.tick_once()
        planned.add(bb("time_to_home_s"))
        walked = float(np.linalg.norm(robot.position - home))
        late = robot.endurance_remaining_s <= 1.2 * walked + 60.0  # the truth, in a straight tunnel
        if low.status == Status.SUCCESS:
            fired_at = t
            break
        assert not late, f"not fired at {t} s: {robot.endurance_remaining_s} s left, {walked:.1f} m from home"
        robot.step(1.0)
        ctx.clock.now_s += 1.0
        robot.endurance_remaining_s -= 1.0
    # 140 - t <= 1.2 t + 60 first at t = 37 s (not much early either).
    assert fired_at == 37
    assert len(planned) < 10  # re-planned a few times, not on each of 37 ticks
    assert events(ctx, "endurance_low")[0]["trigger"] is True


# ------------------------------------------------------- Home, path_source: navigator


def test_return_home_walks_round_the_u_and_writes_returned_home(u_tunnel):
    robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME, ctx)
    homing.tick_once()
    assert homing.status == Status.RUNNING
    (path,) = robot.paths
    assert np.allclose(path[-1], HOME)
    assert path[:, 0].max() > 24.0  # round the far end, not through the rock between
    assert bb("returned_home") is not True
    homing.tick_once()
    assert homing.status == Status.RUNNING and len(robot.paths) == 1  # on its way: no new command
    assert run(homing, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position - HOME) <= 1.0
    assert bb("returned_home") is True
    assert robot.distance_m == pytest.approx(path_length(path), abs=1.5)
    (started,) = events(ctx, "homing")
    assert 44.0 <= started["path_length_m"] <= 50.0
    assert events(ctx, "home_reached")[0]["endurance_s"] == pytest.approx(robot.endurance_remaining_s)


def test_return_home_at_home_succeeds_at_once(tunnel):
    grid, a, _ = tunnel
    home = body(a, 2.0)
    robot = FakeRobot(grid, home + np.array([0.8, 0.0, 0.0]), home=home)
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME + "\ntolerance_m: 1.0", ctx)
    homing.tick_once()
    assert homing.status == Status.SUCCESS and robot.paths == []
    assert bb("returned_home") is True and events(ctx, "home_reached")
    py_trees.blackboard.Blackboard.clear()
    ctx = make_ctx(robot)
    strict = build(RETURN_HOME + "\ntolerance_m: 0.5", ctx)
    assert run(strict, ctx, robot, dt_s=0.25) == Status.SUCCESS
    assert len(robot.paths) == 1 and np.linalg.norm(robot.position - home) <= 0.5


def test_return_home_replans_after_a_blocked_path(tunnel):
    grid, a, _ = tunnel
    home = body(a, 2.0)
    robot = FakeRobot(grid, body(a, 20.0), home=home)
    robot.block_at, robot.block_radius_m = body(a, 15.0), 0.5
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME, ctx)
    for _ in range(10):  # walks into the block
        homing.tick_once()
        robot.step(1.0)
        if robot.path_status.value == "blocked":
            break
    assert robot.path_status.value == "blocked" and homing.status == Status.RUNNING
    robot.block_at = None  # the rock is gone
    assert run(homing, ctx, robot) == Status.SUCCESS
    assert len(robot.paths) == 2 and len(events(ctx, "homing")) == 2
    assert np.linalg.norm(robot.paths[1][0] - body(a, 15.5)) < 1.0  # the new path starts where it stood
    assert bb("returned_home") is True


@pytest.mark.parametrize("max_replans", [0, 2])
def test_return_home_gives_up_after_max_replans(tunnel, max_replans):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 20.0), home=body(a, 2.0))
    robot.block_at, robot.block_radius_m = body(a, 15.0), 2.5  # the tunnel's whole width
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME + f"\nmax_replans: {max_replans}", ctx)
    assert run(homing, ctx, robot) == Status.FAILURE
    assert len(robot.paths) == max_replans + 1
    (failed,) = events(ctx, "homing_failed")
    assert "rock in the way" in failed["reason"]  # the robot's reason for the last blocked path
    assert bb("returned_home") is not True
    # Entered again (say, the next time the tree asks), it has its re-plans again.
    robot.block_at = None
    assert run(homing, ctx, robot) == Status.SUCCESS and bb("returned_home") is True


def test_return_home_fails_when_home_cannot_be_reached(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 15.0), home=body(a, 2.0) + np.array([0.0, 0.0, 30.0]))
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME + "\nmax_replans: 2", ctx)
    statuses = []
    for _ in range(20):
        homing.tick_once()
        statuses.append(homing.status)
        if homing.status != Status.RUNNING:
            break
        robot.block_at, robot.block_radius_m = robot.position, 1.5  # rock all round: no way out
        robot.step(1.0)
        robot.block_at = None
    assert statuses[-1] == Status.FAILURE
    assert events(ctx, "homing_failed") and bb("returned_home") is not True


def test_the_former_name_return_home_still_works_and_says_what_to_write(u_tunnel):
    walked = []
    with pytest.warns(DelveDeprecation) as told:
        walk_home_twice(u_tunnel, walked)
    assert len(walked[0]) == len(walked[1]) == 1 and np.array_equal(walked[0][0], walked[1][0])
    notice = " ".join(str(w.message) for w in told)
    assert "'ReturnHome' is deprecated" in notice and "path_source: navigator" in notice


def walk_home_twice(u_tunnel, walked: list) -> None:
    """Walk home once as Home with path_source: navigator and once as ReturnHome."""
    for text in (RETURN_HOME, "type: ReturnHome"):
        py_trees.blackboard.Blackboard.clear()
        robot = FakeRobot(u_tunnel, FAR_SIDE, home=HOME)
        ctx = make_ctx(robot)
        # The notice is told once per place in a file: a place no other test builds at.
        homing = build(text, ctx, within=TREES / "test_homing_alias")
        assert run(homing, ctx, robot) == Status.SUCCESS and bb("returned_home") is True
        walked.append(robot.paths)


def test_return_home_interrupted_stops_only_its_own_motion(tunnel):
    grid, a, _ = tunnel
    robot = FakeRobot(grid, body(a, 20.0), home=body(a, 2.0))
    ctx = make_ctx(robot)
    homing = build(RETURN_HOME, ctx)
    homing.tick_once()
    robot.step(1.0)
    homing.stop(Status.INVALID)  # a higher-priority branch took over
    assert robot.stops == 1 and robot.path_status.value == "idle"
    homing.tick_once()
    robot.follow_path([body(a, 25.0)])  # the newcomer's command comes first ...
    homing.stop(Status.INVALID)         # ... then py_trees stops the old behaviour
    assert robot.stops == 1 and robot.path_status.value == "following"


# ------------------------------------------------------------- the two in a subtree


def test_explore_until_endurance_low_then_return_home():
    """trees/subtrees/explore_then_home.yaml: the robot explores a half-mapped tunnel
    until its endurance barely covers the way back, and gets home with the reserve."""
    grid, a, _ = syn.straight_tunnel(length_m=50, mapped_to_m=25)
    home = body(a, 2.0)
    # The fake map does not grow, so the frontier goal (which stands back from the
    # mapped end to see it) is reached and the frontier stays: endurance must run low
    # before the robot gets there.
    robot = FakeRobot(grid, home, home=home, endurance_s=80.0)
    ctx = make_ctx(robot)
    root = build("include: subtrees/explore_then_home.yaml", ctx)
    farthest = 0.0
    for _ in range(200):
        root.tick_once()
        if root.status != Status.RUNNING:
            break
        robot.step(1.0)
        ctx.clock.now_s += 1.0
        robot.endurance_remaining_s -= 1.0
        farthest = max(farthest, float(np.linalg.norm(robot.position - home)))
    assert root.status == Status.SUCCESS
    assert bb("returned_home") is True and np.linalg.norm(robot.position - home) <= 1.0
    kinds = [e for e, _ in ctx.events]
    assert kinds.index("frontier_goal") < kinds.index("endurance_low") < kinds.index("homing")
    assert kinds[-1] == "home_reached"
    # 80 - t <= 1.2 t + 60: turned back after ~9 s, ~9 m out; home with ~60 s to spare.
    assert 7.0 <= farthest <= 12.0
    assert robot.endurance_remaining_s >= 55.0


# ---------------------------------------------------------------------------- EndSortie


def test_end_sortie_ends_the_mission_unless_the_supervisor_will_send_the_robot_out_again(tunnel):
    grid, a, _ = tunnel
    ctx = make_ctx(FakeRobot(grid, body(a, 2.0)))
    end = build("type: EndSortie", ctx)
    end.tick_once()
    assert end.status == Status.SUCCESS  # never tasked: the mission ends at home
    py_trees.blackboard.Blackboard.set("/r1/end_at_home", True)
    end.tick_once()
    assert end.status == Status.SUCCESS and not events(ctx, "sortie_ended")
    for key, value in (("end_at_home", False), ("mode", "home"), ("time_budget_s", 300.0),
                       ("budget_start_s", 10.0)):
        py_trees.blackboard.Blackboard.set(f"/r1/{key}", value)
    end.tick_once()
    assert end.status == Status.FAILURE  # a sortie ended: lower blocks run, the last waits
    assert (bb("mode"), bb("time_budget_s"), bb("budget_start_s")) == ("idle", None, None)
    assert len(events(ctx, "sortie_ended")) == 1
    py_trees.blackboard.Blackboard.set("/r1/homing_due", True)  # the endurance called it home
    end.tick_once()
    assert end.status == Status.SUCCESS
