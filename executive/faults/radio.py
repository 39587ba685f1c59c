"""Radio faults: a blackout of one radio or one link, and a breadcrumb that dies."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ...skills.base import Param
from ..errors import DelveError
from .base import BASE_STATION, LINK, OPTIONAL, ROBOT, Fault, FaultContext, Target

if TYPE_CHECKING:
    from ..runner import Mission
    from ..yamlio import YamlDict


class RadioHold(Fault):
    """A fault that holds radios off the air or links cut while it lasts. Overlapping
    faults add up: a radio is back when no active fault holds it any more."""

    def radios_down(self) -> set[str]:
        """Radios (agent names, ``base``) this fault holds off the air."""
        return set()

    def links_cut(self) -> set[tuple[str, str]]:
        """Links (sorted pairs of agent names) this fault holds cut."""
        return set()

    @staticmethod
    def apply(mission: "Mission") -> None:
        """Set every radio's blackout and the cut links from the active faults."""
        holds = mission.faults.holding(RadioHold)
        down = set().union(*(f.radios_down() for f in holds))
        for name, endpoint in mission.radio.endpoints.items():
            endpoint.blackout = name in down
        mission.radio.cut_links.clear()
        mission.radio.cut_links.update(*(f.links_cut() for f in holds))

    def start(self, mission: "Mission") -> dict[str, Any]:
        self.apply(mission)
        return {}

    def end(self, mission: "Mission") -> dict[str, Any]:
        self.apply(mission)
        return {}


class RadioBlackout(RadioHold):
    """A radio goes off the air: one robot's (``robot``), the base station's
    (``base_station: true``), or one link between two agents (``link: [a, b]``, where
    ``base`` is the base station; routes through other radios still work). Messages
    wait in their outboxes as out of range (a graph world's datagrams are lost).
    Until ``duration_s`` has passed, for good without it."""

    KIND = "radio_blackout"
    TARGETS = (ROBOT, LINK, BASE_STATION)
    DURATION = OPTIONAL

    def radios_down(self) -> set[str]:
        from ..worlds import BASE

        if self.target.kind == LINK:
            return set()
        return {BASE if self.target.kind == BASE_STATION else self.target.names[0]}

    def links_cut(self) -> set[tuple[str, str]]:
        return {tuple(sorted(self.target.names))} if self.target.kind == LINK else set()


class BreadcrumbDies(Fault):
    """Breadcrumb number ``number`` that ``robot`` drops (1: its first) stops relaying
    at ``at_s``, or as soon as it is dropped if that is later. For good."""

    KIND = "breadcrumb_dies"
    PARAMS = {"number": Param(int, 1, "which of the robot's drops (1: its first)", minimum=1, maximum=1000)}
    WORLDS = ("voxel",)

    @classmethod
    def check(cls, item: "YamlDict", target: Target, ctx: FaultContext) -> None:
        carried = ctx.robots[target.names[0]].breadcrumbs
        number = item.get("number", cls.PARAMS["number"].default)
        if carried < number:
            where = "number" if "number" in item else "robot"
            raise DelveError(f"fault {cls.KIND!r}: robot {target.names[0]!r} carries {carried} breadcrumbs, "
                             f"it never drops number {number} (set its 'breadcrumbs')", ctx.path,
                             item.key_line(where))

    @property
    def breadcrumb(self) -> str:
        """The breadcrumb's radio name (as the radio names a robot's drops)."""
        return f"{self.robot}_breadcrumb_{self.p['number']}"

    def __init__(self, *args: Any, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.dead = False

    def start(self, mission: "Mission") -> dict[str, Any]:
        self.step(mission, mission.clock.now_s, announce=False)
        return {"breadcrumb": self.breadcrumb, "dropped": self.dead}

    def step(self, mission: "Mission", now_s: float, announce: bool = True) -> None:
        if self.dead or self.breadcrumb not in mission.radio.breadcrumbs:
            return
        mission.radio.dead_breadcrumbs.add(self.breadcrumb)
        self.dead = True
        if announce:
            mission.log("breadcrumb_died", breadcrumb=self.breadcrumb, robot=self.robot)
