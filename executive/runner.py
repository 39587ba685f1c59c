"""The mission runner: one loop for every world and team method.

It asks the scenario's world backend (:mod:`delve.executive.worlds`) for the world,
the robots and the radio, and its team strategy (:mod:`delve.executive.teams`) for
services and for when the mission is over; then it steps the simulation, ticks the
agents that are due, injects the supervisor's commands and faults, and samples
coverage."""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

import numpy as np
import py_trees
from py_trees.common import Status

from ..sim.clock import SimClock
from ..skills.base import AgentContext
from ..skills.operator import COMMAND
from .agent import Agent
from .artifacts import NoArtifacts, artifact_course
from .faults import FaultSchedule
from .outcome import Outcome, mission_outcome
from .scenario import Scenario
from .tree_loader import load_tree
from .worlds import BASE, WorldBackend

#: Sim time the runner keeps the radio going after the trees finish, so that what
#: robots queued on their way home reaches the base station.
FLUSH_S = 30.0


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


class Mission:
    """A scenario made runnable: its world backend (world, robots, radio), its team
    strategy, and one agent per robot and for the base station."""

    def __init__(self, scenario: Scenario, *, seed: int | None = None, duration_s: float | None = None,
                 world: Any = None):
        self.scenario = scenario
        self.seed = scenario.seed if seed is None else seed
        self.duration_s = scenario.duration_s if duration_s is None else duration_s
        world = world if world is not None else scenario.build_world(seed=self.seed)
        scenario.check_starts(world)
        self.clock = SimClock(scenario.dt_s)
        self.state = MissionState()
        self.backend: WorldBackend = scenario.world_backend(scenario, world, self.seed, self.clock)
        self.team = scenario.team_strategy()
        self.artifacts: NoArtifacts = artifact_course(scenario, self.world, self.robots,
                                                      next(iter(self.robots.values())).home, self.seed, self.clock,
                                                      self.duration_s, self.log)
        self.agents: dict[str, Agent] = {}
        self._commands = deque(scenario.supervisor)
        self.faults = FaultSchedule(scenario.faults)
        #: Robots that died (a ``lost`` fault, a flat battery) and why.
        self.lost: dict[str, str] = {}
        self.finished_s: float | None = None
        #: Whether the run stopped at ``duration_s`` before the team strategy's end (set by :meth:`run`).
        self.timed_out: bool | None = None
        self._add_agents()
        self.team.start(self)

    @property
    def world(self) -> Any:
        return self.backend.world

    @property
    def robots(self) -> dict[str, Any]:
        return self.backend.robots

    @property
    def radio(self) -> Any:
        return self.backend.radio

    @property
    def base_position(self) -> np.ndarray:
        return self.backend.base_position

    # ---- construction -----------------------------------------------------------
    def _add_agents(self) -> None:
        """One agent per robot and, when the scenario has a base station tree, the
        base station's, each with the services of the world and the team strategy."""
        for spec in self.scenario.robots:
            ctx = self._context(spec.name, self.robots[spec.name])
            ctx.services.update(self.team.robot_services(spec.name))
            tree = load_tree(spec.tree, ctx, include_path=self.scenario.include_path)
            self.agents[spec.name] = Agent(spec.name, tree, 1.0 / spec.tick_hz, ctx, on_change=self._status_changed,
                                           next_tick_s=spec.deploy_at_s)
        if self.scenario.base_tree is not None:
            ctx = self._context(BASE, None)
            ctx.services.update(self.backend.base_services())
            ctx.services.update(self.team.base_services())
            ctx.services.update(self.artifacts.base_services())
            self.agents[BASE] = Agent(BASE, load_tree(self.scenario.base_tree, ctx,
                                                      include_path=self.scenario.include_path),
                                      1.0 / self.scenario.base_tick_hz, ctx, on_change=self._status_changed)

    def _context(self, name: str, robot: Any) -> AgentContext:
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
        """The agents of the robots that were not lost (a ``lost`` fault, a flat battery)."""
        return [a for n, a in self.agents.items() if n != BASE and n not in self.lost]

    def run(self, progress: Callable[["Mission"], None] | None = None, progress_period_s: float = 10.0) -> None:
        """Run until every robot's tree has finished or ``duration_s`` has passed,
        then keep the radio going for up to ``FLUSH_S`` to deliver what is queued."""
        next_sample = next_progress = 0.0
        self.log("mission_start", scenario=self.scenario.name, seed=self.seed)
        while True:
            now = self.clock.now_s
            self._supervise(now)
            self.backend.sense(now)
            self.artifacts.sense(now)
            self.radio.update()
            for agent in self.agents.values():
                if agent.name in self.lost:
                    continue
                if agent.tick_if_due(now) and agent.finished and agent.name in self.robots:
                    self.robots[agent.name].park()

            if now + 1e-9 >= next_sample:
                self._sample(now)
                next_sample = now + self.scenario.coverage_period_s
            if progress is not None and now + 1e-9 >= next_progress:
                progress(self)
                next_progress = now + progress_period_s
            if self.team.done(self) or now >= self.duration_s:
                break
            for name, robot in self.robots.items():
                robot.step(self.clock.dt_s)
                if not robot.alive and name not in self.lost:
                    self.lose(name, robot.blocked_reason or "endurance exhausted")
            self.clock.step()
        self.finished_s = self.clock.now_s
        self.timed_out = not self.team.done(self)
        self.log("mission_end", timed_out=self.timed_out)
        for agent in self.robot_agents:
            if not agent.finished:
                agent.stop()
        self._flush()
        self._sample(self.clock.now_s)
        if progress is not None:
            progress(self)

    def _supervise(self, now: float) -> None:
        """Send the supervisor's commands that are due; start, step and end faults."""
        while self._commands and self._commands[0].at_s <= now + 1e-9:
            c = self._commands.popleft()
            self.radio.endpoints[BASE].send(c.robot, COMMAND, {"command": c.command, "args": c.args})
            self.log("supervisor_command", robot=c.robot, command=c.command, **c.args)
        self.faults.update(self, now)

    # ---- what faults do to agents -----------------------------------------------------
    def lose(self, name: str, reason: str) -> None:
        """Robot ``name`` dies: it stops, its radio falls silent, its tree stops and no
        longer ticks; a ``robot_lost`` event gives ``reason``."""
        if name in self.lost:
            return
        self.robots[name].kill()
        self.agents[name].stop()
        self.lost[name] = reason
        self.log("robot_lost", robot=name, reason=reason)

    def restart_agent(self, name: str, resume_s: float) -> int:
        """Restart agent ``name``'s executive, as after a crash: its tree stops, its
        blackboard is cleared, the messages in its radio's inbox and outbox are lost,
        and a tree built afresh from its file ticks from ``resume_s`` on. Its services
        (the base map, the team's configuration) outlive the restart; the team
        strategy is told (:meth:`TeamStrategy.restarted`). Returns the messages lost."""
        old = self.agents[name]
        old.stop()
        ctx = self._context(name, old.ctx.robot)
        ctx.services.update(old.ctx.services)
        radio = self.radio.endpoints[name]
        lost = len(radio.inbox) + len(radio.outbox)
        radio.inbox.clear()
        radio.outbox.clear()
        specs = {r.name: r.tree for r in self.scenario.robots}
        tree = self.scenario.base_tree if name == BASE else specs[name]
        root = load_tree(tree, ctx, include_path=self.scenario.include_path)
        self.agents[name] = Agent(name, root, old.period_s, ctx, on_change=self._status_changed,
                                  next_tick_s=resume_s)
        self.team.restarted(self, name)
        return lost

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
        cov = self.backend.coverage(self.team.explored_at_base())
        self.state.samples.append(Sample(
            t=now, team=cov.team, base=cov.base, robots=cov.robots,
            positions={n: [round(float(v), 3) for v in r.position] for n, r in self.robots.items()},
            linked={n: self.radio.linked(n, BASE) for n in self.robots},
        ))

    # ---- results ----------------------------------------------------------------
    @cached_property
    def outcome(self) -> Outcome:
        """Whether the mission succeeded and why not (asked once it is over): its team
        strategy's judgement and the mission-level checks (:mod:`.outcome`)."""
        return mission_outcome(self)

    @property
    def succeeded(self) -> bool:
        """Whether the mission succeeded (:attr:`outcome`)."""
        return self.outcome.succeeded
