"""The mission runner: builds world, robots and agents from a scenario and runs the
simulation until every robot's tree has finished or the scenario's time is up."""
from __future__ import annotations

import math
from collections import deque

from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np
import py_trees
from py_trees.common import Status

from ..sim.clock import SimClock
from ..sim.platforms import PLATFORMS
from ..sim.radio import RadioNetwork, RadioSpec
from ..sim.robot import SimRobot
from ..sim.voxel_map import VoxelMap
from ..sim.world import World
from ..planners.cops.extraction import DEFAULT_CELL_M
from ..planners.cops.topology import Topology
from ..skills.base import AgentContext
from ..skills.cops import CopsSkill
from ..skills.cops_voxel import VoxelNetworkView
from ..skills.navigation import navigator
from ..skills.operator import COMMAND
from .agent import Agent
from .cops_report import cops_figures, declared_lost, solve_time_figures
from .errors import DelveError
from .scenario import RobotSpec, Scenario
from .tree_loader import load_tree

BASE = "base"
#: Sim time the runner keeps the radio going after the trees finish, so that what
#: robots queued on their way home reaches the base station.
FLUSH_S = 30.0
_START_OFFSETS_M = [(0, 0), (1.2, 0), (-1.2, 0), (0, 1.2), (0, -1.2), (2.4, 0), (-2.4, 0), (2.4, 1.2),
                    (-2.4, 1.2), (2.4, -1.2), (-2.4, -1.2), (3.6, 0), (-3.6, 0)]


@dataclass
class Sample:
    """Coverage and robot states at one moment."""

    t: float
    team: float
    base: float
    robots: dict[str, float]
    positions: dict[str, list[float]]
    linked: dict[str, bool]


@dataclass
class MissionState:
    """Everything a run produced, for reports and plots."""

    events: list[dict[str, Any]] = field(default_factory=list)
    samples: list[Sample] = field(default_factory=list)


def create_mission(scenario: Scenario, **kw: Any) -> "Mission":
    """The mission of a scenario: on a graph world (COPS) or a voxel world."""
    if scenario.is_graph:
        from .graph_mission import GraphMission
        return GraphMission(scenario, **kw)
    return Mission(scenario, **kw)


class Mission:
    """A scenario made runnable: world, robots, radio, base station and agents."""

    def __init__(self, scenario: Scenario, *, seed: int | None = None, duration_s: float | None = None,
                 world: World | None = None):
        self._begin(scenario, seed, duration_s, world)
        rng = np.random.default_rng(self.seed)
        self.radio = RadioNetwork(RadioSpec(**scenario.radio), self.world, rng, lambda: self.clock.now_s)
        self.robots: dict[str, SimRobot] = {}
        self._next_scan: dict[str, float] = {}
        for i, spec in enumerate(scenario.robots):
            self.robots[spec.name] = self._robot(spec, i)
            self._next_scan[spec.name] = 0.0
        base_pos = np.asarray(scenario.base_position if scenario.base_position is not None
                              else self.world.start + np.array([0.0, 0.0, 1.0]), dtype=float)
        self.base_position = base_pos
        self.base_map = VoxelMap(self.world.free.shape, self.world.origin, self.world.voxel_size_m)
        base_radio = self.radio.add(BASE, lambda: base_pos, breadcrumbs=0)

        self._add_agents(radio=base_radio, map=self.base_map)
        self.cops = BASE in self.agents and any(isinstance(b, CopsSkill) for b in self.agents[BASE].root.iterate())
        if self.cops:
            self._start_cops()
        reach = self.world.reachable_free(self._first_start())
        self.truth = np.flatnonzero(reach.reshape(-1))

    # ---- construction -----------------------------------------------------------
    def _begin(self, scenario: Scenario, seed: int | None, duration_s: float | None, world: Any) -> None:
        """What every mission holds before its robots: scenario, seed, duration, world
        (built unless given, starts checked), clock, state, script and faults."""
        self.scenario = scenario
        self.seed = scenario.seed if seed is None else seed
        self.duration_s = scenario.duration_s if duration_s is None else duration_s
        self.world = world if world is not None else scenario.build_world(seed=self.seed)
        scenario.check_starts(self.world)
        self.clock = SimClock(scenario.dt_s)
        self.state = MissionState()
        self.agents: dict[str, Agent] = {}
        self._commands = deque(scenario.supervisor)
        self._faults = deque(scenario.faults)
        self.lost: set[str] = set()
        self.finished_s: float | None = None

    def _add_agents(self, robot_services: dict[str, Any] | None = None, **base_services: Any) -> None:
        """One agent per robot (with ``robot_services``) and, when the scenario has a
        base station tree, the base station's (with ``base_services``)."""
        for spec in self.scenario.robots:
            ctx = self._context(spec.name, self.robots[spec.name])
            ctx.services.update(robot_services or {})
            self.agents[spec.name] = Agent(spec.name, load_tree(spec.tree, ctx), 1.0 / spec.tick_hz, ctx,
                                           on_change=self._status_changed)
        if self.scenario.base_tree is not None:
            ctx = self._context(BASE, None)
            ctx.services.update(base_services)
            self.agents[BASE] = Agent(BASE, load_tree(self.scenario.base_tree, ctx),
                                      1.0 / self.scenario.base_tick_hz, ctx, on_change=self._status_changed)

    def _start_cops(self) -> None:
        """COPS on a voxel world. Every robot's network view uses one lattice, with a
        cell centred on the first robot's start, and the radio's range; the base
        station's team (robot -> start location), base location and initial topology
        come from the robots' first scans, taken here, at the base, where all robots
        hear it."""
        corner = self._first_start() - 0.5 * DEFAULT_CELL_M
        initial, team = Topology(), {}
        for name, robot in self.robots.items():
            ctx = self.agents[name].ctx
            view = VoxelNetworkView(robot, lattice_origin=corner, comm_range_m=self.radio.spec.range_m,
                                    navigator=navigator(ctx, robot))
            ctx.services["network_view"] = view
            robot.scan()
            self._next_scan[name] = 1.0 / robot.mobility.lidar.rate_hz
            initial.merge(view.current())
            team[name] = view.location()
            if team[name] is None:
                raise DelveError(f"robot '{name}' does not stand in a location of the COPS network "
                                 f"at its start", self.scenario.path, self._robot_line(name))
        base_location = view.cell_of(self._first_start()[None])[0]
        for name in self.robots:
            self.agents[name].ctx.services.update(team=team, base_location=base_location)
        self.agents[BASE].ctx.services.update(team=team, base_location=base_location,
                                              initial_topology=initial.to_dict())

    def _robot_line(self, name: str) -> int | None:
        return next(s.line for s in self.scenario.robots if s.name == name)

    def _first_start(self) -> np.ndarray:
        r = next(iter(self.robots.values()))
        return r.home - np.array([0.0, 0.0, r.mobility.body_height_m])

    def _robot(self, spec: RobotSpec, index: int) -> SimRobot:
        base = PLATFORMS[spec.platform]
        platform = replace(base, **spec.overrides, lidar=replace(base.lidar, **spec.lidar))
        start = np.asarray(spec.start, float) if spec.start is not None else self._free_start(index)
        holder: dict[str, SimRobot] = {}
        radio = self.radio.add(spec.name, lambda: holder["r"].position, breadcrumbs=spec.breadcrumbs)
        robot = SimRobot(spec.name, platform, self.world, start, radio, spec.endurance_s)
        holder["r"] = robot
        return robot

    def _free_start(self, index: int) -> np.ndarray:
        """A start on the floor near the world's start, a little apart for each robot."""
        free = [np.asarray(self.world.start) + np.array([dx, dy, 0.0]) for dx, dy in _START_OFFSETS_M]
        free = [p for p in free if self.world.start_problem(p + np.array([0, 0, 0.3])) is None]
        if index >= len(free):
            raise DelveError(f"no free start pose near the world's start for robot #{index + 1}",
                             self.scenario.path, self.scenario.robots[index].line)
        return free[index]

    def _context(self, name: str, robot: SimRobot | None) -> AgentContext:
        """A fresh context for agent ``name``; what an earlier mission in this process
        left under its blackboard namespace is cleared (py_trees' storage is global)."""
        storage = py_trees.blackboard.Blackboard.storage
        for key in [k for k in storage if k.startswith(f"/{name}/")]:
            del storage[key]
        return AgentContext(name=name, namespace=f"/{name}", clock=self.clock, log=self.log, robot=robot)

    # ---- events -----------------------------------------------------------------
    def log(self, event: str, **fields: Any) -> None:
        self.state.events.append({"t": self.clock.now_s, "event": event, **fields})

    def _status_changed(self, agent: Agent, node: py_trees.behaviour.Behaviour, old: Status, new: Status) -> None:
        self.log("status", agent=agent.name, node=node.name, old=old.value, new=new.value)

    # ---- running ----------------------------------------------------------------
    @property
    def robot_agents(self) -> list[Agent]:
        """The agents of the robots that were not lost (a ``lost`` fault)."""
        return [a for n, a in self.agents.items() if n != BASE and n not in self.lost]

    def _done(self) -> bool:
        """Whether the mission is over: every robot's tree has finished (lost ones
        aside). With COPS, the base station's tree too (robots the final plan could not
        reach aside), or as soon as the base station fails (no plan)."""
        if not self.cops:
            return all(a.finished for a in self.robot_agents)
        base = self.agents[BASE]
        if base.root.status == Status.FAILURE:
            return True
        stranded = set(self.stranded)
        return base.finished and all(a.finished or a.name in stranded for a in self.robot_agents)

    @property
    def stranded(self) -> list[str]:
        """Robots the final plan (the recall) could not reach."""
        st = self.base_state()
        return list(st.plan.meta.get("stranded", ())) if st is not None and st.final and st.plan else []

    def run(self, progress: Callable[["Mission"], None] | None = None, progress_period_s: float = 10.0) -> None:
        """Run until every robot's tree has finished or ``duration_s`` has passed,
        then keep the radio going for up to ``FLUSH_S`` to deliver what is queued."""
        next_sample = next_progress = 0.0
        self.log("mission_start", scenario=self.scenario.name, seed=self.seed)
        while True:
            now = self.clock.now_s
            self._supervise(now)
            self._sense(now)
            self.radio.update()
            for agent in self.agents.values():
                if agent.tick_if_due(now) and agent.finished and agent.name in self.robots:
                    self.robots[agent.name].park()

            if now + 1e-9 >= next_sample:
                self._sample(now)
                next_sample = now + self.scenario.coverage_period_s
            if progress is not None and now + 1e-9 >= next_progress:
                progress(self)
                next_progress = now + progress_period_s
            if self._done() or now >= self.duration_s:
                break
            for robot in self.robots.values():
                robot.step(self.clock.dt_s)
            self.clock.step()
        self.finished_s = self.clock.now_s
        timed_out = not self._done()
        self.log("mission_end", timed_out=timed_out)
        for agent in self.robot_agents:
            if not agent.finished:
                agent.stop()
        self._flush()
        self._sample(self.clock.now_s)
        if progress is not None:
            progress(self)

    def _supervise(self, now: float) -> None:
        """Send the supervisor's commands that are due, and inject due faults."""
        while self._commands and self._commands[0].at_s <= now + 1e-9:
            c = self._commands.popleft()
            self.radio.endpoints[BASE].send(c.robot, COMMAND, {"command": c.command, "args": c.args})
            self.log("supervisor_command", robot=c.robot, command=c.command, **c.args)
        while self._faults and self._faults[0].at_s <= now + 1e-9:
            f = self._faults.popleft()
            robot = self.robots[f.robot]
            if f.kind == "stuck":
                robot.jam(f.duration_s)
            elif f.kind == "lost":
                robot.kill()
                self.agents[f.robot].stop()
                self.lost.add(f.robot)
            else:
                robot.inject_map_artifact()
            self.log("fault", robot=f.robot, kind=f.kind, duration_s=f.duration_s)

    def _sense(self, now: float) -> None:
        for name, robot in self.robots.items():
            if robot.alive and now + 1e-9 >= self._next_scan[name]:
                robot.scan()
                self._next_scan[name] = now + 1.0 / robot.mobility.lidar.rate_hz

    def _flush(self) -> None:
        end = self.clock.now_s + FLUSH_S
        base = self.agents.get(BASE)
        while self.clock.now_s < end and any(ep.pending for ep in self.radio.endpoints.values()):
            self.clock.step()
            self.radio.update()
            if base is not None:
                base.tick_if_due(self.clock.now_s)
        if base is not None:
            base.tick_if_due(math.inf)

    def _sample(self, now: float) -> None:
        team = np.zeros(len(self.truth), dtype=bool)
        per_robot = {}
        for name, robot in self.robots.items():
            seen = robot.onboard_map.occupancy.reshape(-1)[self.truth] == 0
            per_robot[name] = round(float(seen.mean()) if len(seen) else 0.0, 5)
            team |= seen
        self.state.samples.append(Sample(
            t=now,
            team=round(float(team.mean()) if len(team) else 0.0, 5),
            base=round(self.base_map.known_fraction_of(self.truth), 5),
            robots=per_robot,
            positions={n: [round(float(v), 3) for v in r.position] for n, r in self.robots.items()},
            linked={n: self.radio.linked(n, BASE) for n in self.robots},
        ))

    # ---- results ----------------------------------------------------------------
    def world_figures(self) -> dict[str, Any]:
        """Report figures of the world kind (here: the reachable free volume) and, for
        COPS, the network and the plans."""
        out: dict[str, Any] = {"free_volume_m3": round(len(self.truth) * self.world.voxel_size_m ** 3, 1)}
        st = self.base_state()
        if st is not None:
            topo = st.knowledge.topology
            out.update(locations_known_at_base=len(topo.locations), locations_explored_at_base=len(topo.explored),
                       declared_lost=declared_lost(self.state.events), cops=cops_figures(self.state.events))
        return out

    def base_state(self) -> Any:
        """The base station's COPS state (None without COPS or before its first tick)."""
        return py_trees.blackboard.Blackboard.storage.get(f"/{BASE}/cops") if self.cops else None

    def robot_figures(self, name: str) -> dict[str, Any]:
        """Extra per-robot report figures of the world kind."""
        return {"lost": name in self.lost} if self.lost else {}

    def wall_clock_figures(self) -> dict[str, Any]:
        """Report figures that depend on the wall clock (COPS solve times)."""
        return solve_time_figures(self.state.events)

    @property
    def succeeded(self) -> bool:
        """Every robot's tree ended in SUCCESS (robots lost to a fault aside), and with
        COPS the base station's too."""
        return all(a.root.status == Status.SUCCESS for a in self.robot_agents) and (
            not self.cops or self.agents[BASE].root.status == Status.SUCCESS)
