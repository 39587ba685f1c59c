"""Parameters of the artifact pipeline, with their defaults and where each comes from.

The CERBERUS paper (section 3.5, 4.2.2) describes the methods but gives numbers for
few of them: the 5 m scoring radius, the 45 reports and 60 minutes of the Prize
Round, and the CO2 thresholds (1500 ppm used, "too low"; 3000 ppm DARPA's figure).
Every other default below is chosen here and says why. Each dataclass checks its
values and raises ValueError with a one-line message naming the field.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .report import ARTIFACT_CLASSES

#: The SubT scoring radius (m): a report scores within this of the artifact.
SCORING_RADIUS_M = 5.0
#: The Prize Round: 45 reports in 60 minutes (paper, section 4.2.2).
PRIZE_ROUND_REPORTS = 45
PRIZE_ROUND_S = 3600.0


def _check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def _probability(name: str, value: float, *, open_interval: bool = True) -> None:
    ok = 0.0 < value < 1.0 if open_interval else 0.0 <= value <= 1.0
    _check(ok, f"{name}: {value} must be in {'(0, 1)' if open_interval else '[0, 1]'}")


@dataclass(frozen=True)
class CameraFusionParams:
    """Onboard fusion of camera detections (paper, "Detection filtering").

    - ``association_radius_m`` (2.0, chosen): radius of the "virtual sphere" around a
      track's centre; a detection inside it is the same object. Wider than the
      spread of ray-located detections of one object (a few voxels) and well inside
      the 5 m scoring radius, so that two artifacts 4 m apart stay two tracks.
    - ``prior`` (0.1, chosen): the prior probability of each class for a new track,
      one in ten (the ten classes).
    - ``hit_likelihood`` (0.7, chosen): P(the detector labels c | the object is c).
    - ``false_likelihood`` (0.1, chosen): P(the detector labels c | it is not c).
      A detection labelled c adds log(hit / false) to c's log-odds and
      log((1 - hit) / (1 - false)) to every other class's. With these defaults a
      track needs three consistent detections to pass the threshold (two leave it
      at 0.85): a lone false positive, or two at one place, is never reported.
    - ``class_likelihoods`` (none): per-class (hit, false) overrides, e.g. a lower hit
      for a class the detector confuses (the paper found the phone "generally
      unreliable" visually).
    - ``report_threshold`` (0.95, chosen): a track is reported once a class's
      probability reaches this.
    - ``min_confidence`` (0.5, chosen: the usual score threshold of a YOLO detector):
      detections with a lower detector confidence are dropped.
    - ``min_ray_hits`` (3, chosen): rays of a bounding box that must hit the map for
      the detection to be located (:func:`~.ray_hits.locate`).
    """

    association_radius_m: float = 2.0
    prior: float = 0.1
    hit_likelihood: float = 0.7
    false_likelihood: float = 0.1
    class_likelihoods: dict[str, tuple[float, float]] = field(default_factory=dict)
    report_threshold: float = 0.95
    min_confidence: float = 0.5
    min_ray_hits: int = 3

    def __post_init__(self) -> None:
        _check(self.association_radius_m > 0,
               f"association_radius_m: {self.association_radius_m} must be > 0")
        _check(self.min_ray_hits >= 1, f"min_ray_hits: {self.min_ray_hits} must be >= 1")
        for name in ("prior", "report_threshold"):
            _probability(name, getattr(self, name))
        _probability("min_confidence", self.min_confidence, open_interval=False)
        for c in self.class_likelihoods:
            _check(c in ARTIFACT_CLASSES, f"class_likelihoods: unknown artifact class {c!r}")
        default = ("", (self.hit_likelihood, self.false_likelihood))
        for c, (hit, false) in [default, *self.class_likelihoods.items()]:
            where = f"class_likelihoods[{c}]" if c else "hit_likelihood/false_likelihood"
            _probability(where, hit)
            _probability(where, false)
            _check(hit > false, f"{where}: the hit likelihood {hit} must exceed the false one {false}")

    def likelihoods(self) -> tuple[np.ndarray, np.ndarray]:
        """(hit, false) likelihoods per class, arrays in :data:`ARTIFACT_CLASSES` order."""
        default = (self.hit_likelihood, self.false_likelihood)
        pairs = [self.class_likelihoods.get(c, default) for c in ARTIFACT_CLASSES]
        hit, false = np.array(pairs, dtype=float).T
        return hit, false


@dataclass(frozen=True)
class SignalParams:
    """Clustering of one kind of signal reading (paper, "Bluetooth and CO2 detection").

    - ``raw_min``, ``raw_max``: the "predefined range"; a raw value v is normalised
      to clip((v - raw_min) / (raw_max - raw_min), 0, 1).
    - ``threshold``: raw value (dBm, ppm) a reading must reach to start or join a
      cluster; a weaker one only counts towards ``after_peak_readings``.
    - ``cluster_distance_m``: a reading farther than this from every cluster's centre
      starts a new cluster (CO2); None clusters by identifier alone (Bluetooth SSID).
    - ``min_readings``: readings above threshold a cluster needs to be reported.
    - ``after_peak_readings``: readings of the source (above threshold or not, within
      the cluster) that must follow the cluster's strongest one before it is
      reported: the robot has passed the source. The paper reports on
      ``min_readings`` alone but moved and re-sent a cluster's position as readings
      came in; a single report made on the approach lands where the robot first
      heard the source. 0 gives the paper's rule.
    - ``top_k``: the cluster's centre is the mean of the positions of its ``top_k``
      strongest readings, weighted by their normalised values ("updated using the
      largest measured values"); the report's probability is their mean normalised
      value (a measure of how close the robot came, not a calibrated probability).
    """

    raw_min: float
    raw_max: float
    threshold: float
    min_readings: int = 5
    after_peak_readings: int = 3
    top_k: int = 5
    cluster_distance_m: float | None = None

    def __post_init__(self) -> None:
        _check(self.raw_max > self.raw_min, f"raw_max: {self.raw_max} must exceed raw_min {self.raw_min}")
        _check(self.min_readings >= 1, f"min_readings: {self.min_readings} must be >= 1")
        _check(self.after_peak_readings >= 0, f"after_peak_readings: {self.after_peak_readings} must be >= 0")
        _check(self.top_k >= 1, f"top_k: {self.top_k} must be >= 1")
        _check(self.cluster_distance_m is None or self.cluster_distance_m > 0,
               f"cluster_distance_m: {self.cluster_distance_m} must be > 0")

    def normalise(self, raw: float) -> float:
        """``raw`` mapped into [0, 1] over [raw_min, raw_max]."""
        return float(np.clip((raw - self.raw_min) / (self.raw_max - self.raw_min), 0.0, 1.0))


@dataclass(frozen=True)
class SignalFusionParams:
    """Bluetooth and CO2 clustering (all values chosen, the paper gives no numbers
    except for CO2).

    - ``bluetooth``: normalised over [-100, -40] dBm (the usable span of a BLE
      receiver's RSSI); threshold -72 dBm (4.5 m from a -59 dBm-at-1-m phone in free
      space); five readings, top five; reported eight readings (8 s at 1 Hz) after
      the peak; clustered by SSID. Tuned on delve's sensor model (4 dB noise): a
      robot driving past a phone and a cube, 8 seeds, placed 16 of 16 reports
      within 5 m (median error 0.65 m); -80 dBm with three readings after the peak
      placed about half, reported on noise 10-20 m short.
    - ``co2``: normalised over [400, 5000] ppm (outdoor ambient to the 8-hour
      exposure limit); threshold 2000 ppm, between the 1500 ppm that flooded
      CERBERUS's supervisor with reports and DARPA's 3000 ppm (which delve's gas
      room holds: a threshold there would miss half its readings); five readings,
      top five, three readings (6 s at 0.5 Hz) after the peak; a new cluster beyond
      10 m of every cluster (about a room's size).
    - ``bluetooth_classes``: the classes a Bluetooth beacon can belong to.
    """

    bluetooth: SignalParams = SignalParams(raw_min=-100.0, raw_max=-40.0, threshold=-72.0, after_peak_readings=8)
    co2: SignalParams = SignalParams(raw_min=400.0, raw_max=5000.0, threshold=2000.0, cluster_distance_m=10.0)
    bluetooth_classes: tuple[str, ...] = ("cell_phone", "cube")

    def __post_init__(self) -> None:
        _check(self.co2.cluster_distance_m is not None,
               "co2.cluster_distance_m: CO2 readings cluster by distance")
        for c in self.bluetooth_classes:
            _check(c in ARTIFACT_CLASSES, f"bluetooth_classes: unknown artifact class {c!r}")


@dataclass(frozen=True)
class CandidateParams:
    """The base station's merge of reports into candidates.

    - ``merge_radius_m`` (4.0, chosen): a report of the same class this close to a
      candidate's position is the same artifact. Two reports of one artifact, each
      within ~2 m of it (camera tracks) can be 4 m apart; Bluetooth estimates are
      coarser (paper, Figure 20) but still land inside the scoring radius.
    - ``resubmit_distance_m`` (2.5, chosen: half the scoring radius): a candidate
      that was submitted and did not score is submitted again only once its position
      has moved this far from every position it was submitted at, so the new
      5 m ball covers mostly new ground.
    """

    merge_radius_m: float = 4.0
    resubmit_distance_m: float = SCORING_RADIUS_M / 2

    def __post_init__(self) -> None:
        _check(self.merge_radius_m > 0, f"merge_radius_m: {self.merge_radius_m} must be > 0")
        _check(self.resubmit_distance_m > 0, f"resubmit_distance_m: {self.resubmit_distance_m} must be > 0")


SUBMISSION_POLICIES = ("immediate", "best_first")


@dataclass(frozen=True)
class SubmissionParams:
    """The base station's submission policy (the Human Supervisor's filter, section
    4.2.2: he "filtered the reports received ... and decided which artifact to
    report").

    - ``policy``: "immediate" submits every new candidate at once; "best_first"
      (default) ranks them and holds weak ones back (:func:`~.submission.choose`).
    - ``strong_probability`` (0.5, chosen): a candidate at least this probable is
      strong. Camera reports (at least ``report_threshold``) always are; signal
      reports are when the robot came close (their probability is a normalised
      strength).
    - ``confirm_robots`` (2, chosen): a candidate reported by this many robots is
      strong whatever its probability.
    - ``reserve_rate_per_s`` (45 / 3600, the Prize Round's budget spread over its
      hour): weak candidates are submitted only while the reports left exceed a
      reserve of floor(rate x time to the end) for strong candidates still to come;
      the reserve falls to zero in the last 1 / rate seconds (80 s).
    """

    policy: str = "best_first"
    strong_probability: float = 0.5
    confirm_robots: int = 2
    reserve_rate_per_s: float = PRIZE_ROUND_REPORTS / PRIZE_ROUND_S

    def __post_init__(self) -> None:
        _check(self.policy in SUBMISSION_POLICIES,
               f"policy: {self.policy!r} is not one of {', '.join(SUBMISSION_POLICIES)}")
        _probability("strong_probability", self.strong_probability, open_interval=False)
        _check(self.confirm_robots >= 1, f"confirm_robots: {self.confirm_robots} must be >= 1")
        _check(self.reserve_rate_per_s >= 0, f"reserve_rate_per_s: {self.reserve_rate_per_s} must be >= 0")


__all__ = ["PRIZE_ROUND_REPORTS", "PRIZE_ROUND_S", "SCORING_RADIUS_M", "SUBMISSION_POLICIES",
           "CameraFusionParams", "CandidateParams", "SignalFusionParams", "SignalParams", "SubmissionParams"]
