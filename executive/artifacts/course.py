"""The artifacts of a mission: ground truth in the world, each robot's sensors over
it, and the referee the base station submits to. Only this module and the referee
see where the artifacts are; robots get sensor readings, the base station verdicts.

A scenario without ``artifacts:`` gets :class:`NoArtifacts`, which does nothing, so
the runner treats both alike."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ...sim.artifact_sensors import ArtifactSensors
from ...sim.artifacts import Artifact
from ...sim.referee import Referee, Score
from ...skills.artifacts.base_station import REFEREE
from ..worlds.height_bands import ALL_HEIGHTS, HeightBand
from .figures import artifact_figures
from .plots import draw_artifacts, plot_scores
from .sensors import sensor_spec
from .setup import ArtifactSetup

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...sim.clock import SimClock
    from ..runner import Mission
    from ..scenario import Scenario


class RefereeDesk:
    """The referee as the base station's service: submissions are timed by the sim
    clock, and each is logged (``artifact_scored`` for a point)."""

    def __init__(self, referee: Referee, clock: "SimClock", mission_end_s: float, log: Callable[..., None]):
        self.referee = referee
        self.clock = clock
        self.mission_end_s = mission_end_s
        self.log = log
        #: The robots that reported each submission, in the order of ``referee.scores``.
        self.reporters: list[tuple[str, ...]] = []

    @property
    def reports_left(self) -> int:
        return self.referee.reports_left

    def submit(self, artifact_class: str, position: np.ndarray, reporters: tuple[str, ...] = ()) -> Score:
        """The referee's verdict on a report; ``reporters``: the robots behind it."""
        score = self.referee.submit(self.clock.now_s, artifact_class, position)
        self.reporters.append(tuple(reporters))
        if score.scored:
            self.log("artifact_scored", artifact=score.artifact, artifact_class=artifact_class,
                     error_m=round(float(score.error_m), 2), points=self.referee.score)
        return score


class NoArtifacts:
    """A mission without artifacts: no sensing, no referee, no figures."""

    artifacts: list[Artifact] = []

    def sense(self, now_s: float) -> None:
        pass

    def base_services(self) -> dict[str, Any]:
        return {}

    def figures(self, mission: "Mission") -> dict[str, Any]:
        """The report's ``artifacts`` section (none)."""
        return {}

    def draw(self, ax: "Axes", mission: "Mission", band: HeightBand = ALL_HEIGHTS) -> None:
        """Mark the artifacts at ``band``'s heights on the top-down map (none)."""

    def write_plots(self, mission: "Mission", out: Path) -> list[Path]:
        """Write the artifact pictures into ``out`` (none); the files written."""
        return []


class ArtifactCourse(NoArtifacts):
    """The artifacts placed in ``world`` by ``setup``, a sensor suite per robot (its
    platform's, with the scenario's ``sensors:`` overrides), and the referee."""

    def __init__(self, scenario: "Scenario", setup: ArtifactSetup, world: Any, robots: dict[str, Any],
                 first_start: np.ndarray, seed: int, clock: "SimClock", mission_end_s: float,
                 log: Callable[..., None]):
        self.setup = setup
        self.robots = robots
        self.artifacts = setup.place(world, first_start, seed)
        self.referee = Referee(self.artifacts, report_limit=setup.report_limit, radius_m=setup.score_radius_m)
        self.desk = RefereeDesk(self.referee, clock, mission_end_s, log)
        self.log = log
        self.sensors: dict[str, ArtifactSensors] = {}
        for i, spec in enumerate(scenario.robots):
            rng = np.random.default_rng([seed, 0xA27, i])
            self.sensors[spec.name] = ArtifactSensors(world, self.artifacts, sensor_spec(spec), rng)
        log("artifacts_placed", count=len(self.artifacts),
            classes={c: sum(a.artifact_class == c for a in self.artifacts)
                     for c in sorted({a.artifact_class for a in self.artifacts})})

    def sense(self, now_s: float) -> None:
        """Each working robot's sensors at its true pose (the payload's cameras where
        it points); the readings go to the robot, for its fusion behaviours."""
        for name, robot in self.robots.items():
            if not robot.alive or robot.parked:
                continue
            pose = np.array([*robot.true_position, robot.yaw_rad])
            sensors = self.sensors[name]
            known = len(sensors.detected)
            robot.receive_artifact_readings(sensors.sense(now_s, pose, robot.payload))
            if len(sensors.detected) > known:  # first detections, in the order they came
                for artifact in list(sensors.detected)[known:]:
                    self.log("artifact_detected", robot=name, artifact=artifact)

    def base_services(self) -> dict[str, Any]:
        return {REFEREE: self.desk}

    def figures(self, mission: "Mission") -> dict[str, Any]:
        return artifact_figures(mission, self)

    def draw(self, ax: "Axes", mission: "Mission", band: HeightBand = ALL_HEIGHTS) -> None:
        draw_artifacts(ax, mission, self, band)

    def write_plots(self, mission: "Mission", out: Path) -> list[Path]:
        plot_scores(mission, self, out / "scored.png")
        return [out / "scored.png"]


def artifact_course(scenario: "Scenario", world: Any, robots: dict[str, Any], first_start: np.ndarray, seed: int,
                    clock: "SimClock", mission_end_s: float, log: Callable[..., None]) -> NoArtifacts:
    """The mission's artifacts: an :class:`ArtifactCourse` when the scenario has an
    ``artifacts:`` section, else :class:`NoArtifacts`."""
    if scenario.artifacts is None:
        return NoArtifacts()
    return ArtifactCourse(scenario, scenario.artifacts, world, robots, first_start, seed, clock, mission_end_s, log)
