"""Camera detections located in the robot's own map and fused per track."""
from __future__ import annotations

from typing import Any

from py_trees.common import Status

from ...planners.artifacts import ArtifactTracker, CameraFusionParams, locate
from ..base import Param
from .reporting import ReportingSkill


class FuseCameraDetections(ReportingSkill):
    """Detection filtering (paper, Section 3.5): each camera detection the robot made
    since the last tick is located by casting the rays through its bounding box into
    the onboard voxel map (the median of their first hits), then fused into the
    robot's tracks (an association sphere, the averaged centre, a binary Bayes filter
    per class); a track whose class passes ``report_threshold`` is reported once.

    Writes ``artifact_reports`` (appends). Returns RUNNING (a background task)."""

    PARAMS = {
        "association_radius_m": Param(float, CameraFusionParams.association_radius_m,
                                      "a detection this close to a track's centre is the same object",
                                      exclusive_minimum=0),
        "report_threshold": Param(float, CameraFusionParams.report_threshold,
                                  "a track is reported once a class is this probable", exclusive_minimum=0,
                                  maximum=0.999999),
        "max_range_m": Param(float, 60.0, "rays are cast this far into the map", exclusive_minimum=0),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.tracker = ArtifactTracker(CameraFusionParams(association_radius_m=self.p["association_radius_m"],
                                                          report_threshold=self.p["report_threshold"]),
                                       robot=ctx.name)

    def update(self) -> Status:
        detections = self.robot.take_camera_detections()
        if detections:
            m = self.robot.onboard_map
            occupancy, origin, voxel = m.occupancy, m.origin, m.voxel_size_m
            for d in detections:
                where = locate(occupancy, origin, voxel, d.origin, d.rays, self.p["max_range_m"],
                               self.tracker.params.min_ray_hits)
                if where is not None:
                    self.add_reports(self.tracker.add(d.t_s, d.artifact_class, d.confidence, where))
        return Status.RUNNING
