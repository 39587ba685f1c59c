"""Artifacts in a mission (issue 12): the scenario's ``artifacts:`` section, the
ground truth and each robot's sensors over it, the referee, and the artifacts'
figures and pictures."""
from .course import ArtifactCourse, NoArtifacts, artifact_course
from .sensors import check_sensors
from .setup import ArtifactSetup

__all__ = ["ArtifactCourse", "ArtifactSetup", "NoArtifacts", "artifact_course", "check_sensors"]
