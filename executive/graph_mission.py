"""Missions on graph worlds (COPS): robots on a network of locations, the base
station as the COPS leader, a datagram radio over communication edges.

The loop, events and outputs are the voxel mission's (:class:`Mission`); what
differs is the world, the robots, the radio and the figures: coverage is the
fraction of locations explored, and the report adds the COPS plans.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..sim.graph_world import GraphRadioNetwork, GraphRadioSpec, GraphRobot, GraphWorld
from ..sim.platforms import PLATFORMS
from .cops_report import cops_figures, declared_lost
from .runner import BASE, Mission, Sample
from .scenario import Scenario



class GraphMission(Mission):
    """A scenario on a :class:`GraphWorld`."""

    def __init__(self, scenario: Scenario, *, seed: int | None = None, duration_s: float | None = None,
                 world: GraphWorld | None = None):
        self._begin(scenario, seed, duration_s, world)
        self.cops = True
        self.radio = GraphRadioNetwork(GraphRadioSpec(**scenario.radio), self.world,
                                       np.random.default_rng(self.seed), lambda: self.clock.now_s)
        self.robots: dict[str, GraphRobot] = {}
        for spec in scenario.robots:
            platform = PLATFORMS[spec.platform]
            start = np.asarray(spec.start, float) if spec.start is not None else self.world.start
            holder: dict[str, GraphRobot] = {}
            radio = self.radio.add(spec.name, lambda h=holder: h["r"].position)
            holder["r"] = self.robots[spec.name] = GraphRobot(
                spec.name, replace(platform, **spec.overrides), self.world,
                start, radio, spec.endurance_s)
        base_pos = (np.asarray(scenario.base_position, float) if scenario.base_position is not None
                    else self.world.start)
        self.base_position = base_pos
        base_radio = self.radio.add(BASE, lambda: base_pos)
        self.base_location = self.world.location_at(base_pos)
        team = {n: self.world.location_at(r.position) for n, r in self.robots.items()}
        self._add_agents({"team": team, "base_location": self.base_location}, radio=base_radio, team=team,
                         base_location=self.base_location,
                         initial_topology=self.world.explored_topology([self.base_location]))
        self.truth = np.arange(len(self.world))

    # ---- the loop's hooks ---------------------------------------------------------
    def _sense(self, now: float) -> None:
        """Robots explore as they arrive at locations (in ``GraphRobot.step``)."""

    def _sample(self, now: float) -> None:
        n = len(self.world)
        team: set[str] = set()
        per_robot = {}
        for name, robot in self.robots.items():
            team |= set(robot.explored)
            per_robot[name] = round(len(robot.explored) / n, 5)
        st = self.base_state()
        base = len(st.knowledge.topology.explored) / n if st is not None else 0.0
        self.state.samples.append(Sample(
            t=now, team=round(len(team) / n, 5), base=round(base, 5), robots=per_robot,
            positions={k: [round(float(v), 3) for v in r.position] for k, r in self.robots.items()},
            linked={k: self.radio.linked(k, BASE) for k in self.robots}))

    # ---- figures --------------------------------------------------------------------
    def world_figures(self) -> dict[str, Any]:
        """The report's graph-world figures: locations and the COPS plans."""
        base_done = next((s.t for s in self.state.samples if s.base >= 1.0), None)
        st = self.base_state()
        return {
            "locations": len(self.world),
            "locations_explored": len(set().union(*(r.explored for r in self.robots.values()))),
            "locations_known_at_base": len(st.knowledge.topology.explored) if st is not None else 0,
            "all_known_at_base_s": base_done,
            "lost_robots": sorted(self.lost),
            "stranded_robots": self.stranded,
            "declared_lost": declared_lost(self.state.events),
            "cops": cops_figures(self.state.events),
        }

    def robot_figures(self, name: str) -> dict[str, Any]:
        robot = self.robots[name]
        return {"transitions": robot.transitions, "locations_explored": len(robot.explored),
                "lost": name in self.lost, "messages_dropped": robot.radio.dropped}

