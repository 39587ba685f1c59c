"""Voxel worlds (procedural generators and meshes): robots with LiDAR and onboard
voxel maps, a radio with path loss and breadcrumbs, coverage of the free volume."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from ...planners.cops.topology import Topology
from ...sim import worldgen
from ...sim.clock import SimClock
from ...sim.platforms import PLATFORMS
from ...sim.radio import RadioNetwork, RadioSpec
from ...sim.robot import SimRobot
from ...sim.voxel_map import UNKNOWN, VoxelMap
from ...sim.world import World
from ...sim.worldfile import from_file
from ...skills.base import AgentContext, short_repr
from ...skills.cops.voxel_view import VoxelNetworkView
from ...skills.navigation import navigator
from ..errors import DelveError
from ..yamlio import YamlDict, file_problem, line_of_key_named
from .base import BASE, Coverage, TeamNetwork, WorldBackend, WorldDescription, only_keys
from .voxel_check import describe_voxel_world, place_starts
from .voxel_coverage import TruthCoverage
from .voxel_plot import plot_voxel_map
from .voxel_preview import draw_preview

if TYPE_CHECKING:
    from ..runner import Mission
    from ..scenario import RobotSpec, Scenario

#: What a ``world: {mesh: ...}`` mapping may hold besides the file (docs/worlds.md).
MESH_OPTIONS = ("mesh", "scale", "up_axis", "voxel_size_m", "start", "seed", "ceiling_m", "scan_origins",
                "trajectory", "inflation_m")


class VoxelBackend(WorldBackend):
    """A voxel world: ``world: {generator: tunnel_network | cave, ...}`` or
    ``world: {mesh: FILE, ...}``. Coverage is the fraction of the free volume
    reachable from the first robot's start that the robots' LiDARs observed; the
    base station knows what reached its map (service ``map``)."""

    KEYS = ("generator", "mesh")
    #: Counted on the maps as they are at each sample: a voxel a map later reads as rock,
    #: or a local map reset, takes its share back (the curve may fall).
    COVERAGE_LABEL = "share of the free volume known as free"
    ARTIFACTS = True

    @classmethod
    def generators(cls) -> dict[str, Any]:
        return {"tunnel_network": worldgen.tunnel_network, "cave": worldgen.cave,
                "subt_final": worldgen.subt_final}

    @classmethod
    def claims(cls, world: Mapping[str, Any]) -> bool:
        return "mesh" in world or world.get("generator") in cls.generators()

    @classmethod
    def check(cls, doc: YamlDict, path: Path, has_base_tree: bool) -> None:
        if "mesh" in doc["world"]:
            only_keys(doc["world"], MESH_OPTIONS, "world: unknown parameter", path)
        super().check(doc, path, has_base_tree)

    @classmethod
    def build_world(cls, scenario: "Scenario", seed: int) -> World:
        spec, where = dict(scenario.world), scenario.doc["world"]
        try:
            if "mesh" in spec:
                given = scenario.path.parent / spec.pop("mesh")
                problem = file_problem(given)
                if problem and problem != "is a directory":  # a folder: a Gazebo model
                    raise DelveError(f"mesh file {problem}: {short_repr(str(given))[1:-1]}", scenario.path,
                                     where.key_line("mesh"))
                mesh = given.resolve()
                spec.pop("seed", None)
                if "trajectory" in spec:
                    given = spec["trajectory"]
                    problem = file_problem(scenario.path.parent / given)
                    if problem:
                        raise DelveError(f"trajectory file {problem}: {short_repr(given)[1:-1]}", scenario.path,
                                         where.key_line("trajectory"))
                    spec["trajectory"] = (scenario.path.parent / given).resolve()
                seeds = [r.start for r in scenario.robots if r.start is not None]
                return from_file(mesh, seeds=seeds, **spec)
            generate = cls.generators()[spec.pop("generator")]
            spec.setdefault("seed", seed)
            return generate(**spec)
        except ValueError as err:
            raise DelveError(f"world: {err}", scenario.path, line_of_key_named(where, str(err)) or where.line) from None

    # ---- a mission ----------------------------------------------------------------
    def __init__(self, scenario: "Scenario", world: World, seed: int, clock: SimClock):
        self.scenario, self.world = scenario, world
        self.radio = RadioNetwork(RadioSpec(**scenario.radio), world, np.random.default_rng(seed),
                                  lambda: clock.now_s)
        self.robots: dict[str, SimRobot] = {}
        self._next_scan: dict[str, float] = {}
        #: Where each robot starts (the ground point under it).
        self.starts: dict[str, np.ndarray] = {}
        for spec, placed in zip(scenario.robots, place_starts(scenario, world)):
            if placed.error is not None:
                raise placed.error
            self.starts[spec.name] = placed.landing.start
            self.robots[spec.name] = self._robot(spec, placed.landing.start)
            self._next_scan[spec.name] = 0.0
        base_pos = np.asarray(scenario.base_position if scenario.base_position is not None
                              else world.start + np.array([0.0, 0.0, 1.0]), dtype=float)
        self.base_position = base_pos
        self.base_map = VoxelMap(world.free.shape, world.origin, world.voxel_size_m)
        self._base_radio = self.radio.add(BASE, lambda: base_pos, breadcrumbs=0)
        reach = world.reachable_free(self.first_start())
        #: Flat indices of the free voxels the team should explore (ground truth).
        self.truth = np.flatnonzero(reach.reshape(-1))
        self._coverage = TruthCoverage(self.truth)

    def _robot(self, spec: "RobotSpec", start: np.ndarray) -> SimRobot:
        base = PLATFORMS[spec.platform]
        platform = replace(base, **spec.overrides, lidar=replace(base.lidar, **spec.lidar))
        holder: dict[str, SimRobot] = {}
        # Aerial robots are WiFi clients of the mesh, not relays (CERBERUS section 3.4).
        radio = self.radio.add(spec.name, lambda: holder["r"].true_position, breadcrumbs=spec.breadcrumbs,
                               relay=not platform.aerial)
        robot = SimRobot(spec.name, platform, self.world, start, radio, spec.endurance_s)
        holder["r"] = robot
        return robot

    @classmethod
    def describe(cls, scenario: "Scenario", world: World) -> WorldDescription:
        return describe_voxel_world(scenario, world)

    @classmethod
    def preview(cls, scenario: "Scenario", world: World, out: Path) -> list[Path]:
        return draw_preview(scenario, world, place_starts(scenario, world), out)

    def first_start(self) -> np.ndarray:
        """The ground point under the first robot's start."""
        r = next(iter(self.robots.values()))
        return r.home - np.array([0.0, 0.0, r.mobility.body_height_m])

    def base_services(self) -> dict[str, Any]:
        return {"radio": self._base_radio, "map": self.base_map}

    def sense(self, now_s: float) -> None:
        for name, robot in self.robots.items():
            # A parked robot stands powered down: it no longer scans.
            if robot.alive and not robot.parked and now_s + 1e-9 >= self._next_scan[name]:
                self._scan(name, now_s)

    def _scan(self, name: str, now_s: float) -> None:
        robot = self.robots[name]
        robot.scan()
        self._next_scan[name] = now_s + 1.0 / robot.mobility.lidar.rate_hz

    def coverage(self, explored_at_base: set[str]) -> Coverage:
        cov = self._coverage
        per_robot = {name: round(cov.fraction(name, robot.onboard_map), 5) for name, robot in self.robots.items()}
        return Coverage(team=round(cov.team_fraction, 5),
                        base=round(cov.fraction(BASE, self.base_map, in_team=False), 5), robots=per_robot)

    def network(self, contexts: dict[str, AgentContext], cell_m: float) -> TeamNetwork:
        """Every robot's network view uses one lattice, with a cell centred on the first
        robot's start, and the radio's range; each robot's start location and the
        initial topology come from its first scan, taken here, at the base, where all
        robots hear it."""
        corner = self.first_start() - 0.5 * cell_m
        initial, team, views = Topology(), {}, {}
        for name, robot in self.robots.items():
            view = VoxelNetworkView(robot, cell_m=cell_m, lattice_origin=corner, comm_range_m=self.radio.spec.range_m,
                                    navigator=navigator(contexts[name], robot))
            views[name] = view
            self._scan(name, 0.0)
            initial.merge(view.current())
            team[name] = view.location()
            if team[name] is None:
                spec = next(s for s in self.scenario.robots if s.name == name)
                raise DelveError(f"robot '{name}' does not stand in a location of the COPS network "
                                 f"at its start", self.scenario.path, spec.line)
        base_location = view.cell_of(self.first_start()[None])[0]
        return TeamNetwork(views, team, base_location, initial.to_dict())

    def figures(self, mission: "Mission") -> dict[str, Any]:
        """The world's free volume and, for a team, ``overlap_fraction``: the share of
        the volume the team observed that more than one robot observed."""
        out: dict[str, Any] = {"free_volume_m3": round(len(self.truth) * self.world.voxel_size_m ** 3, 1)}
        if len(self.robots) > 1:
            seen_by = np.zeros(len(self.truth), dtype=np.uint16)
            for robot in self.robots.values():
                seen_by += robot.onboard_map.occupancy.reshape(-1)[self.truth] == 0
            seen = np.count_nonzero(seen_by)
            out["overlap_fraction"] = round(np.count_nonzero(seen_by > 1) / seen, 5) if seen else 0.0
        return out

    def robot_figures(self, name: str, lost: Mapping[str, str]) -> dict[str, Any]:
        start = {"start": [round(float(c), 3) for c in self.starts[name]],
                 "moving_s": round(self.robots[name].moving_s, 1)}
        return {**start, "lost": name in lost} if lost else start

    def map_undelivered(self, name: str) -> int:
        """Voxels robot ``name`` knows (free or rock) that are unknown in the base map."""
        onboard = self.robots[name].onboard_map.occupancy
        return int(np.count_nonzero((onboard != UNKNOWN) & (self.base_map.occupancy == UNKNOWN)))

    def plot_map(self, mission: "Mission", path: Path) -> None:
        plot_voxel_map(mission, self.truth, path)
