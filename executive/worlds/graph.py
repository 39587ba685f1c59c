"""Graph worlds (COPS locations): robots drive tunnel by tunnel and explore the
locations they reach, a datagram radio over communication edges, coverage in
locations."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from ...sim.clock import SimClock
from ...sim.graph_radio import GraphRadioNetwork, GraphRadioSpec
from ...sim.graph_robot import GraphRobot
from ...sim.graph_world import GraphWorld
from ...sim.platforms import PLATFORMS
from ...skills.base import AgentContext, short_repr
from ..errors import DelveError
from ..yamlio import YamlDict, file_problem, line_of_key_named
from . import graph_sources
from .base import BASE, Coverage, TeamNetwork, WorldBackend, WorldDescription, only_keys
from .graph_check import describe_graph_world
from .graph_plot import plot_graph_map

if TYPE_CHECKING:
    from ..runner import Mission
    from ..scenario import Scenario

#: Radio settings that mean something on a graph world (communication edges decide links).
RADIO_KEYS = ("loss", "update_period_s")


class GraphBackend(WorldBackend):
    """A graph world: ``world: {generator: tunnel_graph, ...}`` or ``world: {network:
    FILE}``. Coverage is the fraction of locations explored; the base station knows
    what its team strategy says it knows. Each robot is its own ``NetworkView``."""

    KEYS = ("generator", "network")
    COVERAGE_LABEL = "fraction of locations explored"
    UNSUPPORTED_FAULTS = ("map_artifact",)

    @classmethod
    def generators(cls) -> dict[str, Any]:
        return {"tunnel_graph": graph_sources.tunnel_graph}

    @classmethod
    def claims(cls, world: Mapping[str, Any]) -> bool:
        return "network" in world or world.get("generator") in cls.generators()

    @classmethod
    def check(cls, doc: YamlDict, path: Path, has_base_tree: bool) -> None:
        """A readable network file, a base station tree (the leader), no voxel-world
        radio settings or faults."""
        world = doc["world"]
        if "network" in world:
            only_keys(world, ("network",), "world: unknown parameter", path)
            net_path = path.parent / world["network"]
            problem = file_problem(net_path)
            if problem:
                raise DelveError(f"network file {problem}: {short_repr(world['network'])[1:-1]}", path,
                                 world.key_line("network"))
            graph_sources.load_network_world(net_path)
        super().check(doc, path, has_base_tree)
        if not has_base_tree:
            raise DelveError("a graph world needs a base station tree (base_station: tree: ...), the COPS leader",
                             path, doc.key_line("base_station") or doc.key_line("world"))
        for key in doc.get("radio", {}):
            if key not in RADIO_KEYS:
                raise DelveError(f"radio: {short_repr(key)} does not apply to a graph world (communication edges "
                                 f"decide links; use {', '.join(RADIO_KEYS)})", path, doc["radio"].key_line(key))

    @classmethod
    def build_world(cls, scenario: "Scenario", seed: int) -> GraphWorld:
        spec = dict(scenario.world)
        try:
            if "network" in spec:
                return graph_sources.load_network_world(scenario.path.parent / spec["network"])
            generate = cls.generators()[spec.pop("generator")]
            spec.setdefault("seed", seed)
            return generate(**spec)
        except ValueError as err:
            where = scenario.doc["world"]
            raise DelveError(f"world: {err}", scenario.path, line_of_key_named(where, str(err)) or where.line) from None

    @classmethod
    def describe(cls, scenario: "Scenario", world: GraphWorld) -> WorldDescription:
        return describe_graph_world(scenario, world)

    # ---- a mission ----------------------------------------------------------------
    def __init__(self, scenario: "Scenario", world: GraphWorld, seed: int, clock: SimClock):
        self.world = world
        self.radio = GraphRadioNetwork(GraphRadioSpec(**scenario.radio), world, np.random.default_rng(seed),
                                       lambda: clock.now_s)
        self.robots: dict[str, GraphRobot] = {}
        for spec in scenario.robots:
            start = np.asarray(spec.start, float) if spec.start is not None else world.start
            holder: dict[str, GraphRobot] = {}
            radio = self.radio.add(spec.name, lambda h=holder: h["r"].position)
            holder["r"] = self.robots[spec.name] = GraphRobot(
                spec.name, replace(PLATFORMS[spec.platform], **spec.overrides), world, start, radio, spec.endurance_s)
        self.base_position = (np.asarray(scenario.base_position, float) if scenario.base_position is not None
                              else world.start)
        self._base_radio = self.radio.add(BASE, lambda: self.base_position)

    def base_services(self) -> dict[str, Any]:
        return {"radio": self._base_radio}

    def explored(self) -> set[str]:
        """The locations some robot explored."""
        return set().union(*(r.explored for r in self.robots.values()))

    def coverage(self, explored_at_base: set[str]) -> Coverage:
        n = len(self.world)
        return Coverage(team=round(len(self.explored()) / n, 5), base=round(len(explored_at_base) / n, 5),
                        robots={name: round(len(r.explored) / n, 5) for name, r in self.robots.items()})

    def network(self, contexts: dict[str, AgentContext], cell_m: float) -> TeamNetwork:
        """Robots are their own views; the team starts where it stands, and the base
        station knows its own location explored."""
        base_location = self.world.location_at(self.base_position)
        return TeamNetwork(views=dict(self.robots),
                           team={n: self.world.location_at(r.position) for n, r in self.robots.items()},
                           base_location=base_location,
                           initial_topology=self.world.explored_topology([base_location]))

    def figures(self, mission: "Mission") -> dict[str, Any]:
        return {"locations": len(self.world), "locations_explored": len(self.explored()),
                "all_known_at_base_s": next((s.t for s in mission.state.samples if s.base >= 1.0), None),
                "lost_robots": sorted(mission.lost)}

    def robot_figures(self, name: str, lost: Mapping[str, str]) -> dict[str, Any]:
        robot = self.robots[name]
        return {"transitions": robot.transitions, "locations_explored": len(robot.explored),
                "lost": name in lost, "messages_dropped": robot.radio.dropped}

    def plot_map(self, mission: "Mission", path: Path) -> None:
        plot_graph_map(mission, mission.team.explored_at_base(), path)
