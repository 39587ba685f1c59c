"""delve.skills.artifacts: the robot's fusion and reporting behaviours and the base
station's collection and submission, on the fake robot and radio."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from delve.planners.gbplanner2 import synthetic as syn
from delve.skills.artifacts import ARTIFACT_REPORT
from delve.skills.base import AgentContext
from py_trees.common import Status

from .fakes import Clock, FakeRadio, FakeRobot, bb, body, build, events, make_ctx


@dataclass(frozen=True)
class Detection:
    t_s: float
    camera: str
    artifact_class: str
    confidence: float
    origin: np.ndarray
    rays: np.ndarray


@dataclass(frozen=True)
class Reading:
    t_s: float
    kind: str
    identifier: str | None
    position: np.ndarray
    value: float


@pytest.fixture(scope="module")
def tunnel():
    return syn.straight_tunnel(length_m=20)


@pytest.fixture()
def robot(tunnel):
    grid, a, _ = tunnel
    return FakeRobot(grid, body(a, 5.0))


def toward_wall(robot, t_s: float, label: str = "backpack", spread: float = 0.05) -> Detection:
    """A detection whose box's rays fan out around the direction across the tunnel."""
    rng = np.random.default_rng(int(t_s * 10))
    rays = np.array([0.0, 1.0, -0.3]) + rng.uniform(-spread, spread, (16, 3))
    return Detection(t_s, "left", label, 0.9, robot.position, rays / np.linalg.norm(rays, axis=1, keepdims=True))


def test_camera_detections_are_located_in_the_map_and_reported_once(robot):
    ctx = make_ctx(robot)
    fuse = build("type: FuseCameraDetections", ctx)
    for t in range(6):
        robot.camera_detections = [toward_wall(robot, float(t))]
        ctx.clock.now_s = float(t)
        fuse.tick_once()
        assert fuse.status == Status.RUNNING
    (report,) = bb("artifact_reports")
    assert report["artifact_class"] == "backpack" and report["source"] == "camera" and report["robot"] == "r1"
    # on the wall across the tunnel (2 m to the side), not at the robot
    assert abs(report["position"][1] - robot.position[1]) == pytest.approx(2.0, abs=0.5)
    assert len(events(ctx, "artifact_reported")) == 1


def test_a_lone_detection_and_rays_into_nothing_make_no_report(robot):
    ctx = make_ctx(robot)
    fuse = build("type: FuseCameraDetections", ctx)
    robot.camera_detections = [toward_wall(robot, 0.0),
                               Detection(0.5, "up", "drill", 0.9, robot.position,
                                         np.tile([1.0, 0.0, 0.0], (16, 1)))]  # along the open tunnel
    fuse.tick_once()
    assert bb("artifact_reports", default=[]) == []


def test_bluetooth_readings_make_one_report_of_the_beacons_class(robot):
    ctx = make_ctx(robot)
    fuse = build("type: FuseSignalReadings", ctx)
    for t in range(16):  # the robot passes the beacon: the signal rises, then falls
        robot.signal_readings = [Reading(float(t), "bluetooth", "cube_1", robot.position + [t * 0.5, 0, 0],
                                         -50.0 - 2.0 * abs(t - 4))]
        fuse.tick_once()
    (report,) = bb("artifact_reports")
    assert report["artifact_class"] == "cube" and report["source"] == "bluetooth"


def test_reports_are_sent_once_and_wait_in_the_outbox_while_the_link_is_down(robot):
    ctx = make_ctx(robot)
    tree = build("""
type: Parallel
name: Artifacts
policy: success_on_all
children:
  - type: FuseSignalReadings
  - type: SendArtifactReports
""", ctx)
    robot.radio.link_up = False
    for t in range(12):
        robot.signal_readings = [Reading(float(t), "co2", None, robot.position, 4000.0 - 50.0 * abs(t - 3))]
        tree.tick_once()
    tree.tick_once()
    sent = [m for m in robot.radio.sent if m.kind == ARTIFACT_REPORT]
    assert len(sent) == 1 and sent[0].data["artifact_class"] == "gas"
    assert robot.radio.pending == 1  # kept until a link carries it


class FakeReferee:
    def __init__(self, reports_left: int = 45):
        self.reports_left = reports_left
        self.mission_end_s = 3600.0
        self.submitted: list[tuple] = []

    def submit(self, artifact_class, position, reporters=()):
        self.submitted.append((artifact_class, np.asarray(position), reporters))
        self.reports_left -= 1

        @dataclass
        class Verdict:
            scored: bool = True
            error_m: float | None = 1.0
            reason: str = "scored"

        return Verdict()


def base_ctx(referee) -> AgentContext:
    log: list = []
    ctx = AgentContext(name="base", namespace="/base", clock=Clock(), log=lambda e, **f: log.append((e, f)),
                       services={"radio": FakeRadio("base"), "referee": referee})
    ctx.events = log  # type: ignore[attr-defined]
    return ctx


def base_tree(ctx):
    """The base station's artifact behaviours, submitting every new candidate at once."""
    return build("""
type: Parallel
name: Base
policy: success_on_all
children:
  - type: CollectArtifactReports
  - type: SubmitArtifacts
    policy: immediate
""", ctx)


def report(robot: str, position, cls: str = "drill", t_s: float = 1.0) -> dict:
    return {"artifact_class": cls, "position": list(position), "probability": 0.97, "detections": 3, "t_s": t_s,
            "source": "camera", "robot": robot}


def test_the_base_station_merges_two_robots_reports_into_one_submission():
    referee = FakeReferee()
    ctx = base_ctx(referee)
    tree = base_tree(ctx)
    radio = ctx.services["radio"]
    radio.deliver("r2", ARTIFACT_REPORT, report("r2", [10.0, 0.0, 1.0]))
    radio.deliver("r1", ARTIFACT_REPORT, report("r1", [11.0, 0.5, 1.0]))
    radio.deliver("r1", "goal_unreachable", {"goal": [0, 0, 0]})
    tree.tick_once()
    tree.tick_once()
    (submitted,) = referee.submitted
    assert submitted[0] == "drill" and submitted[2] == ("r2", "r1")
    assert len(events(ctx, "artifact_delivered")) == 2
    (verdict,) = events(ctx, "artifact_submitted")
    assert verdict["scored"] and verdict["robots"] == ["r2", "r1"]


def test_no_more_submissions_than_reports_left():
    referee = FakeReferee(reports_left=1)
    ctx = base_ctx(referee)
    tree = base_tree(ctx)
    for i in range(3):
        ctx.services["radio"].deliver("r1", ARTIFACT_REPORT, report("r1", [30.0 * i, 0.0, 1.0]))
    for _ in range(3):
        tree.tick_once()
    assert len(referee.submitted) == 1
