"""COPS: communication-preserving, information-consistent plans made at the base
station and executed by every robot's Figure 4 tree (``skills/cops/``,
``planners/cops/``).

On any world that gives a mobility-communication network
(:meth:`WorldBackend.network`), the strategy hands each robot its ``NetworkView``,
and robots and base station the team's start locations and the base location; the
base station also gets the topology known at the start. The mission is over when the
base station's tree has finished and every robot's (robots the final plan could not
reach aside), or as soon as the base station fails (no plan).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from py_trees.common import Status

from ...planners.cops.extraction import DEFAULT_CELL_M
from ...skills.base import Param
from ...skills.cops import CopsSkill, CopsState
from ..worlds import BASE
from .base import TeamStrategy
from .cops_report import cops_figures, declared_lost, gone_home, solve_time_figures

if TYPE_CHECKING:
    from ..agent import Agent
    from ..runner import Mission


def _cops_skill(root: Any) -> CopsSkill | None:
    """The first COPS behaviour of a tree (it reads the agent's COPS state)."""
    return next((b for b in root.iterate() if isinstance(b, CopsSkill)), None)


class Cops(TeamStrategy):
    """The COPS plug-in. Report: locations known and explored at the base station,
    robots the final plan could not reach, robots declared lost, robots that left
    the plan for home, and every plan."""

    PARAMS = {"cell_m": Param(float, DEFAULT_CELL_M, "size of a location where the world is cut into "
                                                     "locations (voxel worlds' lattice cell), metres",
                              exclusive_minimum=0.0, maximum=1e3)}
    WALL_CLOCK_FIELDS = ("cops_solve_time_s",)
    FAILURE_EVENTS = ("cops_no_plan", "cops_invalid_plan", "return_without_plan")
    NEEDS_BASE_TREE = True

    def __init__(self, **params: Any):
        super().__init__(**params)
        self._leader: CopsSkill | None = None

    @classmethod
    def implied_by(cls, base_tree_types: set[type]) -> bool:
        return any(issubclass(t, CopsSkill) for t in base_tree_types)

    def start(self, mission: "Mission") -> None:
        robots = {name: mission.agents[name].ctx for name in mission.robots}
        net = mission.backend.network(robots, self.params["cell_m"])
        for name, ctx in robots.items():
            ctx.services.update(network_view=net.views[name], team=net.team, base_location=net.base_location)
        base = mission.agents[BASE]
        base.ctx.services.update(team=net.team, base_location=net.base_location,
                                 initial_topology=net.initial_topology)
        self._leader = _cops_skill(base.root)

    def base_state(self) -> CopsState | None:
        """The base station's COPS state (None before its first tick)."""
        return self._leader.stored_state() if self._leader is not None else None

    def stranded(self) -> list[str]:
        """Robots the final plan (the recall) could not reach."""
        st = self.base_state()
        return list(st.plan.meta.get("stranded", ())) if st is not None and st.final and st.plan else []

    def done(self, mission: "Mission") -> bool:
        base = mission.agents[BASE]
        if base.root.status == Status.FAILURE:
            return True
        stranded = set(self.stranded())
        return base.finished and all(a.finished or a.name in stranded for a in mission.robot_agents)

    def judged_agents(self, mission: "Mission") -> list["Agent"]:
        """The robots and the base station (the leader)."""
        return [*mission.robot_agents, mission.agents[BASE]]

    def restarted(self, mission: "Mission", name: str) -> None:
        if name == BASE:
            self._leader = _cops_skill(mission.agents[BASE].root)

    def robot_figures(self, mission: "Mission", name: str) -> dict[str, Any]:
        """What the robot holds that never reached the base station (what a lost robot
        took with it): ``locations_undelivered``, locations it knows explored that the
        base station does not, and on voxel worlds ``map_chunks_undelivered``, the
        pieces of its own map the base station's knowledge lacks, besides
        ``map_voxels_undelivered``. Graph-world radios drop datagrams (COPS sends
        again until acknowledged), so ``messages_undelivered`` stays 0 there."""
        skill = _cops_skill(mission.agents[name].root)
        st = skill.stored_state() if skill is not None else None
        base = self.base_state()
        held = set(st.knowledge.topology.explored) if st is not None else set()
        figures = {**super().robot_figures(mission, name),
                   "locations_undelivered": len(held - self.explored_at_base())}
        if mission.backend.map_undelivered(name) is not None:
            own = {k for k in (st.knowledge.map_chunks if st is not None else {}) if k.startswith(f"{name}/")}
            at_base = set(base.knowledge.map_chunks) if base is not None else set()
            figures["map_chunks_undelivered"] = len(own - at_base)
        return figures

    def explored_at_base(self) -> set[str]:
        st = self.base_state()
        return set(st.knowledge.topology.explored) if st is not None else set()

    def figures(self, mission: "Mission") -> dict[str, Any]:
        st = self.base_state()
        topology = st.knowledge.topology if st is not None else None
        return {"locations_known_at_base": len(topology.locations) if topology else 0,
                "locations_explored_at_base": len(topology.explored) if topology else 0,
                "stranded_robots": self.stranded(),
                "declared_lost": declared_lost(mission.state.events),
                "gone_home": gone_home(mission.state.events),
                "cops": cops_figures(mission.state.events)}

    def wall_clock_figures(self, mission: "Mission") -> dict[str, Any]:
        return solve_time_figures(mission.state.events)
