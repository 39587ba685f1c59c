"""Artifact fusion (CERBERUS SubT Final paper, section 3.5 "Artifacts scoring"):
onboard, camera detections located by rays into the robot's voxel map and fused
into tracks with a binary Bayes filter per class, Bluetooth and CO2 readings
clustered; at the base station, reports of all robots merged into candidates and a
submission policy against the report budget. Pure numpy; nothing of delve outside
``planners``.
"""
from .camera_fusion import ArtifactTrack, ArtifactTracker
from .candidates import Candidate, Candidates
from .params import CameraFusionParams, CandidateParams, SignalFusionParams, SignalParams, SubmissionParams
from .ray_hits import locate
from .report import ARTIFACT_CLASSES, SOURCES, ArtifactReport
from .signal_fusion import SignalCluster, SignalClusterer, ssid_class
from .submission import choose

__all__ = ["ARTIFACT_CLASSES", "SOURCES", "ArtifactReport", "ArtifactTrack", "ArtifactTracker",
           "CameraFusionParams", "Candidate", "CandidateParams", "Candidates", "SignalCluster", "SignalClusterer",
           "SignalFusionParams", "SignalParams", "SubmissionParams", "choose", "locate", "ssid_class"]
