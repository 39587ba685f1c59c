"""Artifact behaviours (CERBERUS SubT Final paper, Section 3.5): onboard, camera
detections and signal readings fused into reports that go to the base station over
the radio; at the base station, reports merged into candidates and submitted to the
referee. The algorithms are in :mod:`delve.planners.artifacts`."""
from .base_station import CollectArtifactReports, SubmitArtifacts
from .camera import FuseCameraDetections
from .reporting import ARTIFACT_REPORT, SendArtifactReports
from .signals import FuseSignalReadings

__all__ = ["ARTIFACT_REPORT", "CollectArtifactReports", "FuseCameraDetections", "FuseSignalReadings",
           "SendArtifactReports", "SubmitArtifacts"]
