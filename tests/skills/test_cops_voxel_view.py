"""delve.skills.cops.voxel_view: the COPS network of a SimRobot's onboard map."""
from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from delve.planners.cops.topology import Topology
from delve.sim.platforms import AERIAL, LEGGED
from delve.sim.radio import RadioNetwork, RadioSpec
from delve.sim.robot import SimRobot
from delve.sim.world import World
from delve.sim.worldgen_geometry import VoxelCanvas, carve_tunnel, free_space_mesh
from delve.skills.cops.voxel_view import MIN_PROGRESS_M, VoxelNetworkView

V = 0.2
DT_S = 0.2          # one sim step, one sweep of the sensors


@pytest.fixture(scope="module")
def tunnel() -> World:
    """A straight tunnel along x from 0 to 40 m, 4 m wide and 3 m high (cells c0..c4)."""
    canvas = VoxelCanvas(np.array([0.0, 0.0, 0.0]), np.array([40.0, 8.0, 3.0]), V)
    carve_tunnel(canvas, [0.5, 4.0, 0.0], [39.5, 4.0, 0.0], 4.0, 3.0)
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="cops-voxel", voxel_size_m=V, origin=canvas.origin, free=canvas.free, mesh=mesh,
                 start=[3.0, 4.0, 0.01])


def robot_in(world: World, platform=LEGGED) -> SimRobot:
    net = RadioNetwork(RadioSpec(), world, np.random.default_rng(0), lambda: 0.0)
    holder: dict[str, SimRobot] = {}
    radio = net.add("r1", lambda: holder["r"].position)
    robot = holder["r"] = SimRobot("r1", platform, world, np.array([3.0, 4.0, 0.0]), radio)
    return robot


def walk(robot: SimRobot, to_x: float) -> None:
    """Walk along the tunnel's axis to ``to_x``, scanning at every step."""
    robot.scan()
    robot.follow_path(np.array([[to_x, 4.0, robot.position[2]]]))
    while robot.path_status == "following":
        robot.step(DT_S)
        robot.scan()


@pytest.fixture(scope="module")
def scanned(tunnel):
    robot = robot_in(tunnel)
    walk(robot, 13.0)
    return robot, VoxelNetworkView(robot)


def test_topology_of_a_scanned_tunnel(scanned):
    _, view = scanned
    topo = Topology.from_dict(view.topology())
    assert {"c0_0_0", "c1_0_0"} <= set(topo.locations)
    assert ("c0_0_0", "c1_0_0") in topo.mobility and ("c0_0_0", "c1_0_0") in topo.communication
    g = nx.Graph(list(topo.mobility))
    assert nx.is_connected(g)
    assert topo.frontiers(), "the tunnel goes on beyond what the robot has mapped"
    assert "c0_0_0" in topo.explored


def test_location_is_the_robots_cell(scanned):
    robot, view = scanned
    assert view.location() == "c1_0_0"
    ground = view.ground_point()
    assert ground[2] == pytest.approx(robot.position[2] - LEGGED.body_height_m + 0.5 * V)


def test_route_to_a_neighbouring_location(scanned):
    robot, view = scanned
    goal = view.target("c0_0_0")             # the robot's home: c0_0_0 holds it
    path = view.route("c0_0_0")
    assert path is not None and path.shape[1] == 3
    assert np.linalg.norm(path[0] - robot.position) < 1.0
    assert np.linalg.norm(path[-1][:2] - goal[:2]) < 0.5
    assert path[-1][2] == pytest.approx(goal[2] + LEGGED.body_height_m - 0.5 * V)
    assert view.route("c9_9_9") is None


def test_a_robot_goes_home_to_its_own_start_in_the_home_cell(scanned):
    robot, view = scanned
    home = view.ground_points(robot.home[None])[0]
    assert view.target("c0_0_0") == pytest.approx(home)
    assert view.target("c1_0_0") == pytest.approx(view.current().locations["c1_0_0"])
    assert view.target("c9_9_9") is None
    assert not view.arrived("c0_0_0")


def test_extraction_is_cached_per_map_version(tunnel):
    robot = robot_in(tunnel)
    robot.scan()
    view = VoxelNetworkView(robot)
    first = view.topology()
    assert view.topology() == first and view.location() is not None and view.extractions == 1
    robot.scan()
    view.topology()
    assert view.extractions == 2


def test_aerial_robot_flies_through_its_cells(tunnel):
    robot = robot_in(tunnel, AERIAL)
    walk(robot, 12.0)
    view = VoxelNetworkView(robot)
    topo = view.current()
    assert view.location() == "c1_0_0" and ("c0_0_0", "c1_0_0") in topo.mobility
    path = view.route("c0_0_0")
    assert path is not None and np.linalg.norm(path[-1] - view.target("c0_0_0")) < 1.0


def test_bad_cell_size_is_refused(tunnel):
    with pytest.raises(ValueError, match="cell_m"):
        VoxelNetworkView(robot_in(tunnel), cell_m=0.0)


def test_routes_lead_towards_every_location_the_map_shows(scanned):
    """Where the graph does not reach a location yet (floor seen only in rings far
    ahead), the route ends at the reachable node nearest it."""
    robot, view = scanned
    here = view.location()
    for name, pos in view.current().locations.items():
        if name == here:
            continue
        path = view.route(name)
        assert path is not None, name
        ahead = np.linalg.norm(path[-1] - pos)
        assert ahead < np.linalg.norm(robot.position - pos) - MIN_PROGRESS_M


def test_arrival_is_at_the_position_not_only_in_the_cell(tunnel):
    robot = robot_in(tunnel)
    walk(robot, 9.0)                           # into c1_0_0, whose position is near x = 12 m
    view = VoxelNetworkView(robot)
    assert view.location() == "c1_0_0" and not view.arrived("c1_0_0")
    robot.follow_path(view.route("c1_0_0"))
    while robot.path_status == "following":
        robot.step(DT_S)
    assert view.arrived("c1_0_0") and not view.arrived("c0_0_0") and not view.arrived("c9_9_9")


def test_the_lattice_origin_names_the_cells(scanned):
    robot, _ = scanned
    view = VoxelNetworkView(robot, lattice_origin=np.array([-4.0, 0.0, 0.0]))
    assert view.location() == "c2_0_0"         # x = 13 m lies in [12, 20)
    assert view.cell_of(np.array([[3.9, 4.0, 0.1], [4.0, 4.0, 0.1]])) == ["c0_0_0", "c1_0_0"]


def test_the_revision_moves_with_extractions_and_visits(tunnel):
    robot = robot_in(tunnel)
    robot.scan()
    view = VoxelNetworkView(robot)
    first = view.revision
    assert view.revision == first
    walk(robot, 10.0)
    assert view.revision != first and "c1_0_0" in view.current().explored


def test_a_robot_at_a_locations_position_is_there_whatever_cell_its_ground_point_is_in(tunnel):
    """A floor crossing a cell boundary can put the ground point of a robot standing
    at a location's position into the cell below: arrival decides."""
    robot = robot_in(tunnel)
    walk(robot, 7.0)                           # in c0_0_0, near its boundary with c1_0_0
    view = VoxelNetworkView(robot)
    assert view.location() == "c0_0_0"
    topo = view.current()
    topo.locations["c1_0_0"] = tuple(view.ground_point() + [1.0, 0.0, -0.3])
    assert view.arrived("c1_0_0") and view.location() == "c1_0_0"


@pytest.fixture(scope="module")
def yard() -> World:
    """A corridor 4 m wide along y = 14 m from x = 0.5 to 12 m into a 24 m x 24 m yard
    (x 12..36 m, y 2..26 m), 3 m high."""
    canvas = VoxelCanvas(np.array([0.0, 0.0, 0.0]), np.array([38.0, 28.0, 3.0]), V)
    carve_tunnel(canvas, [0.5, 14.0, 0.0], [12.5, 14.0, 0.0], 4.0, 3.0)
    carve_tunnel(canvas, [12.0, 14.0, 0.0], [36.0, 14.0, 0.0], 24.0, 3.0)
    mesh = free_space_mesh(canvas.free, canvas.origin, V)
    return World(name="cops-yard", voxel_size_m=V, origin=canvas.origin, free=canvas.free, mesh=mesh,
                 start=[3.0, 14.0, 0.01])


def test_the_explored_cells_of_a_yard_are_one_location_that_every_cell_name_of_it_reaches(yard):
    net = RadioNetwork(RadioSpec(), yard, np.random.default_rng(0), lambda: 0.0)
    holder: dict[str, SimRobot] = {}
    robot = holder["r"] = SimRobot("r1", LEGGED, yard, np.array([3.0, 14.0, 0.0]),
                                   net.add("r1", lambda: holder["r"].position))
    view = VoxelNetworkView(robot, lattice_origin=np.array([-1.0, 10.0, -4.0]))   # c0_0_0 centred on the start
    robot.scan()

    def walk_to(x: float, y: float) -> None:
        robot.follow_path(np.array([[x, y, robot.position[2]]]))
        while robot.path_status == "following":
            robot.step(DT_S)
            robot.scan()

    walk_to(24.0, 14.0)                        # along the yard's middle: cells c1..c3 of row 0 visited
    topo = view.current()
    assert view.location() == "c1_0_0"         # named after its cell nearest the base's
    assert topo.members("c1_0_0") == ["c1_0_0", "c2_0_0", "c3_0_0"]
    assert view.resolve("c3_0_0") == "c1_0_0" and view.resolve("c9_9_9") is None
    assert view.target("c3_0_0") == pytest.approx(view.target("c1_0_0"))
    assert topo.frontiers() == {"c1_0_0"}      # the yard's cells not explored yet stay locations
    assert "c2_1_0" in topo.unexplored_exits("c1_0_0")
    for x, y in ((24.0, 5.0), (32.0, 5.0), (32.0, 22.0), (16.0, 22.0), (16.0, 5.0)):
        walk_to(x, y)
    topo = view.current()
    assert sorted(topo.locations) == ["c0_0_0", "c1_0_0"]      # the base's cell and the yard
    assert len(topo.members("c1_0_0")) == 12 and "c0_0_0" not in topo.members("c1_0_0")
    assert topo.neighbours("c0_0_0") == ["c1_0_0"] and topo.frontiers() == set()
