"""Onboard fusion of one robot's camera detections into artifact reports (CERBERUS
paper, section 3.5, "Detection filtering").

Each located detection (:func:`locate`) either falls inside the "virtual sphere"
(radius ``association_radius_m``) around an existing track's centre, and is the same
object, or starts a new track centred on it. A track's centre is the average of its
accepted detections. Each track runs a binary Bayes filter per class in log-odds:
a detection labelled c raises c's log-odds by log(hit / false) and lowers every other
class's by log((1 - hit) / (1 - false)). Once the labelled class's probability
reaches ``report_threshold`` the track is reported once, at its centre, and stops:
later detections inside its sphere are ignored ("to prevent duplicate reports").
Association ignores the label, as the paper's sphere does: two different artifacts
closer than the radius are one track.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .params import CameraFusionParams
from .ray_hits import locate
from .report import ARTIFACT_CLASSES, ArtifactReport

_CLASS_INDEX = {c: i for i, c in enumerate(ARTIFACT_CLASSES)}


@dataclass
class ArtifactTrack:
    """One object seen by one robot: the sum and count of its accepted detections'
    positions, the log-odds of each class (in :data:`ARTIFACT_CLASSES` order) and the
    class it was reported as (None until then)."""

    id: int
    position_sum: np.ndarray
    log_odds: np.ndarray
    detections: int = 1
    reported_class: str | None = None

    @property
    def centre(self) -> np.ndarray:
        return self.position_sum / self.detections

    def probabilities(self) -> dict[str, float]:
        """Each class's probability, by class name."""
        p = 1.0 / (1.0 + np.exp(-self.log_odds))
        return {c: float(v) for c, v in zip(ARTIFACT_CLASSES, p)}


class ArtifactTracker:
    """One robot's camera tracks (see the module's docstring). Deterministic: tracks
    are kept in creation order and ties go to the older track."""

    def __init__(self, params: CameraFusionParams | None = None, robot: str | None = None) -> None:
        self.params = params or CameraFusionParams()
        self.robot = robot
        hit, false = self.params.likelihoods()
        self._raise = np.log(hit / false)                 # per class, for a detection labelled that class
        self._lower = np.log((1.0 - hit) / (1.0 - false))  # per class, for a detection labelled another
        self._prior = float(np.log(self.params.prior / (1.0 - self.params.prior)))
        self.tracks: list[ArtifactTrack] = []

    def add(self, t_s: float, artifact_class: str, confidence: float,
            position: np.ndarray) -> list[ArtifactReport]:
        """Fuse one located detection (the detector's label and confidence, its (3,)
        world position). Returns the report this detection completes (at most one, and
        at most one per track ever), else []. Detections below ``min_confidence`` and
        those inside a reported track's sphere change nothing. ValueError for a label
        that is not an artifact class."""
        if artifact_class not in _CLASS_INDEX:
            raise ValueError(f"unknown artifact class {artifact_class!r}")
        if confidence < self.params.min_confidence:
            return []
        position = np.asarray(position, float).reshape(3)
        track = self._nearest(position)
        if track is None:
            prior = np.full(len(ARTIFACT_CLASSES), self._prior)
            track = ArtifactTrack(len(self.tracks), position.copy(), prior)
            self.tracks.append(track)
        elif track.reported_class is not None:
            return []
        else:
            track.position_sum += position
            track.detections += 1
        c = _CLASS_INDEX[artifact_class]
        update = self._lower.copy()
        update[c] = self._raise[c]
        track.log_odds += update
        probability = float(1.0 / (1.0 + np.exp(-track.log_odds[c])))
        if probability < self.params.report_threshold:
            return []
        track.reported_class = artifact_class
        return [ArtifactReport(artifact_class, track.centre, probability, track.detections, float(t_s),
                               "camera", self.robot)]

    def _nearest(self, position: np.ndarray) -> ArtifactTrack | None:
        """The track whose sphere holds ``position`` with the nearest centre (the older
        of equals), or None. A linear scan: a robot keeps tens of tracks, and their
        centres move with every detection (a KD-tree would be rebuilt each time)."""
        if not self.tracks:
            return None
        centres = np.array([t.centre for t in self.tracks])
        dist = np.linalg.norm(centres - position, axis=1)
        i = int(np.argmin(dist))
        return self.tracks[i] if dist[i] <= self.params.association_radius_m else None


__all__ = ["ArtifactTrack", "ArtifactTracker", "locate"]
