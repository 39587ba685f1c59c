"""delve.skills.relocation: Relocate (to the best frontier of GBPlanner2's global graph)
and DeployBreadcrumb, built by their YAML type names and ticked on the fake robot."""
from __future__ import annotations

import numpy as np
import py_trees
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from py_trees.common import Status

from .fakes import FakeRobot, bb, body, build, events, make_ctx, run

EXPLORE = """
type: ExploreGBPlanner2
max_vertices: 150
planner: {num_edges_max: 2500}
"""


@pytest.fixture(scope="module")
def half_mapped():
    """A 50 m tunnel along x mapped for its first 25 m."""
    return syn.straight_tunnel(length_m=50, mapped_to_m=25)


def explored(half_mapped):
    """A robot that explored a little from home (its planner's global graph has frontiers
    ahead) and walked back home."""
    grid, a, _ = half_mapped
    home = body(a, 2.0)
    robot = FakeRobot(grid, home, home=home)
    ctx = make_ctx(robot)
    explore = build(EXPLORE, ctx)
    for _ in range(3):
        explore.tick_once()
        robot.step(100.0)
    explore.stop(Status.INVALID)
    robot.follow_path([home])
    robot.step(100.0)
    assert np.allclose(robot.position, home)
    ctx.events.clear()
    robot.paths.clear()
    robot.stops = 0
    return robot, ctx


def rounded(p) -> list[float]:
    return [round(float(v), 2) for v in p]


# -------------------------------------------------------------------------- Relocate


def test_relocate_goes_to_a_frontier_ahead(half_mapped):
    robot, ctx = explored(half_mapped)
    home = robot.position
    relocate = build("type: Relocate", ctx)
    relocate.tick_once()
    assert relocate.status == Status.RUNNING
    target = bb("relocation_target")
    assert len(target) == 3 and target[0] > home[0] + 10.0  # up the tunnel, towards the unknown
    (path,) = robot.paths
    assert np.linalg.norm(path[-1] - target) < 0.5
    (started,) = events(ctx, "relocate")
    assert started["trigger"] is True and started["to"] == target
    assert started["path_length_m"] >= np.linalg.norm(np.subtract(target, home)) - 0.1
    relocate.tick_once()
    assert relocate.status == Status.RUNNING and len(robot.paths) == 1  # on its way
    assert run(relocate, ctx, robot) == Status.SUCCESS
    assert np.linalg.norm(robot.position - target) < 0.5
    (arrived,) = events(ctx, "relocated")
    assert arrived["at"] == rounded(robot.position)


def test_relocate_never_goes_to_the_same_frontier_twice(half_mapped):
    robot, ctx = explored(half_mapped)
    targets = []
    for _ in range(2):
        relocate = build("type: Relocate", ctx)
        assert run(relocate, ctx, robot) == Status.SUCCESS
        targets.append(bb("relocation_target"))
    assert targets[0] != targets[1]


def test_relocate_fails_without_a_frontier():
    grid, a, _ = syn.straight_tunnel(length_m=24)  # all mapped: nothing to relocate to
    robot = FakeRobot(grid, body(a, 2.0))
    ctx = make_ctx(robot)
    relocate = build("type: Relocate", ctx)
    relocate.tick_once()
    assert relocate.status == Status.FAILURE
    assert robot.paths == [] and bb("relocation_target") is None
    (failed,) = events(ctx, "relocate_failed")
    assert "frontier" in failed["reason"]


def test_relocate_keeps_enough_endurance_to_come_back(half_mapped):
    robot, ctx = explored(half_mapped)
    robot.endurance_remaining_s = 15.0  # not enough to go 10 m out and back
    relocate = build("type: Relocate", ctx)
    relocate.tick_once()
    assert relocate.status == Status.FAILURE and robot.paths == []
    assert "endurance" in events(ctx, "relocate_failed")[0]["reason"]


@pytest.mark.parametrize("max_replans", [0, 1])
def test_relocate_gives_up_after_max_replans_blocked_paths(half_mapped, max_replans):
    robot, ctx = explored(half_mapped)
    relocate = build(f"type: Relocate\nmax_replans: {max_replans}", ctx)
    statuses = []
    for _ in range(10):
        relocate.tick_once()
        statuses.append(relocate.status)
        if relocate.status != Status.RUNNING:
            break
        robot.block_at, robot.block_radius_m = robot.position, 1.5  # every path is blocked at once
        robot.step(1.0)
        robot.block_at = None
    assert statuses == [Status.RUNNING] * (max_replans + 1) + [Status.FAILURE]
    assert len(robot.paths) == max_replans + 1
    (failed,) = events(ctx, "relocate_failed")
    assert failed["reason"] == f"path blocked {max_replans + 1} times"


def test_relocate_interrupted_stops_its_motion_and_plans_afresh_next_time(half_mapped):
    robot, ctx = explored(half_mapped)
    relocate = build("type: Relocate", ctx)
    relocate.tick_once()
    robot.step(2.0)
    relocate.stop(Status.INVALID)
    assert robot.stops == 1 and robot.path_status.value == "idle"
    relocate.tick_once()  # entered again: a new relocation, not "no longer following"
    assert relocate.status == Status.RUNNING and len(robot.paths) == 2
    assert len(events(ctx, "relocate")) == 2 and not events(ctx, "relocate_failed")


def test_the_relocation_subtree_explores_from_the_frontier_or_waits(half_mapped):
    """trees/subtrees/relocation.yaml: mode relocate -> relocate, then mode explore; a
    failed relocation -> mode idle (wait for the next command)."""
    robot, ctx = explored(half_mapped)
    subtree = build("include: subtrees/relocation.yaml", ctx)
    py_trees.blackboard.Blackboard.set("/r1/mode", "explore")
    subtree.tick_once()
    assert subtree.status == Status.FAILURE and robot.paths == []  # not asked to
    py_trees.blackboard.Blackboard.set("/r1/mode", "relocate")
    assert run(subtree, ctx, robot) == Status.FAILURE  # done: lower-priority blocks run
    assert bb("mode") == "explore" and events(ctx, "relocated")
    py_trees.blackboard.Blackboard.clear()
    grid, a, _ = syn.straight_tunnel(length_m=24)
    robot = FakeRobot(grid, body(a, 2.0))
    ctx = make_ctx(robot)
    subtree = build("include: subtrees/relocation.yaml", ctx)
    py_trees.blackboard.Blackboard.set("/r1/mode", "relocate")
    assert run(subtree, ctx, robot) == Status.FAILURE
    assert bb("mode") == "idle" and events(ctx, "relocate_failed")


# ------------------------------------------------------------------ DeployBreadcrumb


def test_no_breadcrumb_unless_requested(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0), breadcrumbs=4)
    ctx = make_ctx(robot)
    drop = build("type: DeployBreadcrumb", ctx)
    drop.tick_once()
    assert drop.status == Status.FAILURE
    py_trees.blackboard.Blackboard.set("/r1/breadcrumb_request", False)
    drop.tick_once()
    assert drop.status == Status.FAILURE
    assert robot.breadcrumbs == 4 and robot.drops == [] and ctx.events == []


def test_a_requested_breadcrumb_is_dropped_once(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0), breadcrumbs=4)
    ctx = make_ctx(robot)
    drop = build("type: DeployBreadcrumb", ctx)
    py_trees.blackboard.Blackboard.set("/r1/breadcrumb_request", True)
    drop.tick_once()
    assert drop.status == Status.SUCCESS
    assert bb("breadcrumb_request") is False  # the request is served
    assert robot.breadcrumbs == 3 and np.allclose(robot.drops, [robot.position])
    (dropped,) = events(ctx, "breadcrumb_dropped")
    assert dropped == {"agent": "r1", "node": "DeployBreadcrumb", "trigger": True, "name": "r1_crumb1",
                       "remaining": 3, "at": rounded(robot.position)}
    drop.tick_once()
    assert drop.status == Status.FAILURE and robot.breadcrumbs == 3  # one request, one breadcrumb


def test_a_drop_refused_with_none_left_gives_the_request_up(half_mapped):
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0), breadcrumbs=0)
    ctx = make_ctx(robot)
    drop = build("type: DeployBreadcrumb", ctx)
    py_trees.blackboard.Blackboard.set("/r1/breadcrumb_request", True)
    drop.tick_once()
    assert drop.status == Status.FAILURE
    (failed,) = events(ctx, "breadcrumb_failed")
    assert "no breadcrumbs left" in failed["reason"] and failed["gave_up"] is True
    assert bb("breadcrumb_request") is False  # not tried again on every tick
    assert not events(ctx, "breadcrumb_dropped")


def test_a_refused_drop_keeps_the_request_for_a_few_more_attempts(half_mapped):
    """A spot that does not take a breadcrumb (no mesh heard, no ground): the request
    stays for the tree to try elsewhere, up to max_attempts refusals in a row."""
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0), breadcrumbs=2)
    robot.has_ground = False
    ctx = make_ctx(robot)
    drop = build("type: DeployBreadcrumb\nmax_attempts: 3", ctx)
    py_trees.blackboard.Blackboard.set("/r1/breadcrumb_request", True)
    for _ in range(3):
        drop.tick_once()
        assert drop.status == Status.FAILURE
    assert [e["gave_up"] for e in events(ctx, "breadcrumb_failed")] == [False, False, True]
    assert bb("breadcrumb_request") is False and robot.breadcrumbs == 2


def test_a_refused_drop_backs_the_robot_up_and_drops_there(half_mapped):
    """trees/subtrees/breadcrumbs.yaml: refused where the robot stands, the robot backs
    up along its path and drops the breadcrumb where the drop is accepted."""
    grid, a, _ = half_mapped
    trail = [body(a, x) for x in np.arange(2.0, 12.01, 0.5)]
    robot = FakeRobot(grid, trail[-1], breadcrumbs=2, trail=trail)
    robot.has_ground = False
    ctx = make_ctx(robot)
    root = build("include: subtrees/breadcrumbs.yaml", ctx)
    py_trees.blackboard.Blackboard.set("/r1/breadcrumb_request", True)
    py_trees.blackboard.Blackboard.set("/r1/link_loss_points", [[30.0, 0.0, 1.0]])
    root.tick_once()
    assert root.status == Status.RUNNING and events(ctx, "backtrack")  # refused: backing up
    for _ in range(2):
        robot.step(1.0)
        ctx.clock.now_s += 1.0
        root.tick_once()
    robot.has_ground = True  # the spot 3 m back takes it
    assert run(root, ctx, robot) == Status.FAILURE  # the block is done: lower blocks run
    root.tick_once()
    assert len(robot.drops) == 1 and robot.breadcrumbs == 1 and bb("breadcrumb_request") is False
    assert np.linalg.norm(robot.drops[0] - body(a, 9.0)) < 0.2
    assert bb("link_loss_points") == []


def test_the_supervisors_drop_command_drops_a_breadcrumb(half_mapped):
    """ProcessOperatorCommands beside trees/subtrees/breadcrumbs.yaml, as in the ANYmal tree."""
    grid, a, _ = half_mapped
    robot = FakeRobot(grid, body(a, 8.0), breadcrumbs=4)
    ctx = make_ctx(robot)
    root = build("""
type: Parallel
policy: success_on_selected
selected: [Breadcrumbs]
children:
  - type: ProcessOperatorCommands
  - include: subtrees/breadcrumbs.yaml
""", ctx)
    root.setup_with_descendants()
    root.tick_once()
    assert robot.drops == []
    robot.radio.deliver("base", "command", {"command": "drop_breadcrumb"})
    root.tick_once()
    assert root.status == Status.FAILURE  # the block never holds the robot
    assert robot.breadcrumbs == 3 and len(robot.drops) == 1
    root.tick_once()
    assert robot.breadcrumbs == 3
