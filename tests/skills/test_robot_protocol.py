"""delve.skills.robot: every robot that skills may be handed, the simulator's and the
tests' fake, has every member the Robot protocol declares (and its radio, mobility
and onboard map theirs)."""
from __future__ import annotations

from typing import Protocol

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.sim.graph_robot import GraphRobot
from delve.sim.platforms import LEGGED
from delve.sim.radio import RadioNetwork, RadioSpec
from delve.sim.robot import SimRobot
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_tunnel, free_space_mesh
from delve.skills.robot import MapView, Mobility, Radio, Robot

from ..sim import graph_fixtures
from .fakes import FakeRobot


def protocol_members(protocol: type) -> set[str]:
    """The names a protocol declares: its annotations, methods and properties (those of
    the protocols it extends too), without private names."""
    names: set[str] = set()
    for cls in protocol.__mro__:
        if cls is Protocol or not getattr(cls, "_is_protocol", False):
            continue
        names |= set(getattr(cls, "__annotations__", {}))
        names |= {n for n, v in vars(cls).items() if callable(v) or isinstance(v, property)}
    return {n for n in names if not n.startswith("_")}


def missing(obj: object, protocol: type) -> list[str]:
    """The members of ``protocol`` that ``obj`` lacks (looked up with ``dir``, so no
    property is evaluated)."""
    return sorted(protocol_members(protocol) - set(dir(obj)))


def sim_robot() -> SimRobot:
    canvas = VoxelCanvas(np.array([0.0, 0.0, 0.0]), np.array([12.0, 6.0, 3.0]), 0.25)
    carve_tunnel(canvas, [0.5, 3.0, 0.0], [11.5, 3.0, 0.0], 4.0, 3.0)
    world = World(name="protocol", voxel_size_m=0.25, origin=canvas.origin, free=canvas.free,
                  mesh=free_space_mesh(canvas.free, canvas.origin, 0.25), start=[2.0, 3.0, 0.01])
    net = RadioNetwork(RadioSpec(), world, np.random.default_rng(0), lambda: 0.0)
    holder: dict[str, SimRobot] = {}
    radio = net.add("r1", lambda: holder["r"].position)
    robot = holder["r"] = SimRobot("r1", LEGGED, world, np.array([2.0, 3.0, 0.0]), radio)
    return robot


def graph_robot() -> GraphRobot:
    robot, _net, _clock = graph_fixtures.robot(graph_fixtures.world())
    return robot


def fake_robot() -> FakeRobot:
    grid, a, _ = syn.straight_tunnel(length_m=10)
    return FakeRobot(grid, np.asarray(a, float) + np.array([2.0, 0.0, 0.5]))


ROBOTS = {"SimRobot": sim_robot, "GraphRobot": graph_robot, "FakeRobot": fake_robot}


def test_the_protocol_declares_what_skills_use():
    members = protocol_members(Robot)
    assert {"position", "onboard_map", "follow_path", "stop", "path_status", "blocked_reason", "radio",
            "payload"} <= members
    assert "command_id" in members and "__init__" not in members


@pytest.mark.parametrize("make", ROBOTS.values(), ids=list(ROBOTS))
def test_every_robot_has_every_member_of_the_robot_protocol(make):
    robot = make()
    assert missing(robot, Robot) == []
    assert missing(robot.radio, Radio) == []
    assert missing(robot.mobility, Mobility) == []
    assert isinstance(robot.blocked_reason, str)


@pytest.mark.parametrize("make", [sim_robot, fake_robot], ids=["SimRobot", "FakeRobot"])
def test_every_voxel_robot_has_a_map_view(make):
    assert missing(make().onboard_map, MapView) == []
