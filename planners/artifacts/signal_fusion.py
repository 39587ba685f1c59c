"""Onboard clustering of one robot's Bluetooth and CO2 readings into artifact reports
(CERBERUS paper, section 3.5, "Bluetooth and CO2 detection").

Raw values are normalised to [0, 1] over a predefined range per kind
(:class:`~.params.SignalParams`). Only readings above their kind's threshold start or
join clusters (a weaker one counts only as a reading after the peak). Bluetooth
readings are clustered by identifier (SSID); a CO2 reading joins the nearest CO2
cluster whose centre lies within ``cluster_distance_m``, else it starts a new one. A cluster's centre is the mean of the positions of its ``top_k`` strongest
readings, weighted by their normalised values. A cluster is reported once, when it
holds ``min_readings`` readings and its strongest reading is followed by
``after_peak_readings`` weaker ones (the robot has passed the source); later readings
join it without a second report (CERBERUS re-reported a CO2 cluster each time its
centre moved and flooded its supervisor with 30 reports in 5 minutes, section 4.2.2).

A Bluetooth identifier's class comes from ``classify`` (identifier -> class or None);
the default, :func:`ssid_class`, reads the simulator's names ("cell_phone_2" -> the
class before the last "_<number>") and keeps only ``bluetooth_classes``. Readings
whose identifier has no class (another robot's radio, say) are ignored.
"""
from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .params import SignalFusionParams, SignalParams
from .report import ArtifactReport

GAS_CLASS = "gas"
_NUMBERED = re.compile(r"^(?P<name>.+?)_\d+$")


def ssid_class(identifier: str, classes: tuple[str, ...]) -> str | None:
    """The artifact class an SSID names: the identifier without a trailing
    ``_<number>`` when that is one of ``classes``, else None."""
    m = _NUMBERED.match(identifier)
    name = m["name"] if m else identifier
    return name if name in classes else None


@dataclass
class SignalCluster:
    """Readings above threshold of one source: kind, identifier (None for CO2), class,
    the readings' positions (N, 3) and normalised values, and whether it was reported."""

    kind: str
    identifier: str | None
    artifact_class: str
    positions: list[np.ndarray] = field(default_factory=list)
    values: list[float] = field(default_factory=list)
    since_peak: int = 0
    reported: bool = False

    def strongest(self, top_k: int) -> np.ndarray:
        """Indices of the ``top_k`` strongest readings (the earlier of equals)."""
        return np.argsort(-np.asarray(self.values), kind="stable")[:top_k]

    def centre(self, top_k: int) -> np.ndarray:
        """Mean position of the ``top_k`` strongest readings, weighted by value."""
        i = self.strongest(top_k)
        weights = np.asarray(self.values)[i]
        points = np.asarray(self.positions)[i]
        if weights.sum() <= 0:                   # all at the bottom of the range: plain mean
            return points.mean(axis=0)
        return np.average(points, axis=0, weights=weights)


class SignalClusterer:
    """One robot's Bluetooth and CO2 clusters (see the module's docstring)."""

    def __init__(self, params: SignalFusionParams | None = None, robot: str | None = None,
                 classify: Callable[[str], str | None] | None = None) -> None:
        self.params = params or SignalFusionParams()
        self.robot = robot
        self.classify = classify or (lambda ssid: ssid_class(ssid, self.params.bluetooth_classes))
        self.clusters: list[SignalCluster] = []
        self._by_ssid: dict[str, SignalCluster] = {}

    def add(self, t_s: float, kind: str, identifier: str | None, position: np.ndarray,
            value: float) -> list[ArtifactReport]:
        """Cluster one reading (``kind`` "bluetooth" with its SSID, or "co2"; where the
        sensor was; the raw value in dBm or ppm). Returns the report this reading
        completes (at most one per cluster, ever), else []. ValueError for another
        kind or a Bluetooth reading without identifier."""
        kind_params = self._kind(kind)
        position = np.asarray(position, float).reshape(3)
        above = value >= kind_params.threshold
        if kind == "bluetooth":
            cluster = self._bluetooth_cluster(identifier, create=above)
        else:
            cluster = self._co2_cluster(position, create=above)
        if cluster is None:
            return []
        normalised = kind_params.normalise(value)
        if above:
            cluster.since_peak = 0 if normalised > max(cluster.values, default=-1.0) else cluster.since_peak + 1
            cluster.positions.append(position)
            cluster.values.append(normalised)
        else:
            cluster.since_peak += 1
        if cluster.reported or len(cluster.values) < kind_params.min_readings:
            return []
        if cluster.since_peak < kind_params.after_peak_readings:
            return []
        cluster.reported = True
        strength = float(np.mean(np.asarray(cluster.values)[cluster.strongest(kind_params.top_k)]))
        return [ArtifactReport(cluster.artifact_class, cluster.centre(kind_params.top_k), strength,
                               len(cluster.values), float(t_s), kind, self.robot)]

    def _kind(self, kind: str) -> SignalParams:
        if kind == "bluetooth":
            return self.params.bluetooth
        if kind == "co2":
            return self.params.co2
        raise ValueError(f"unknown signal kind {kind!r} (bluetooth or co2)")

    def _bluetooth_cluster(self, identifier: str | None, create: bool) -> SignalCluster | None:
        """The SSID's cluster; a new one when ``create`` and the SSID names a class."""
        if not identifier:
            raise ValueError("a bluetooth reading needs its identifier (SSID)")
        if identifier not in self._by_ssid and create:
            artifact_class = self.classify(identifier)
            if artifact_class is None:
                return None
            self._by_ssid[identifier] = SignalCluster("bluetooth", identifier, artifact_class)
            self.clusters.append(self._by_ssid[identifier])
        return self._by_ssid.get(identifier)

    def _co2_cluster(self, position: np.ndarray, create: bool) -> SignalCluster | None:
        """The nearest CO2 cluster within ``cluster_distance_m`` of ``position`` (the
        older of equals), else a new one when ``create``."""
        top_k = self.params.co2.top_k
        co2 = [c for c in self.clusters if c.kind == "co2"]
        if co2:
            dist = np.linalg.norm(np.array([c.centre(top_k) for c in co2]) - position, axis=1)
            i = int(np.argmin(dist))
            if dist[i] <= self.params.co2.cluster_distance_m:
                return co2[i]
        if not create:
            return None
        cluster = SignalCluster("co2", None, GAS_CLASS)
        self.clusters.append(cluster)
        return cluster


__all__ = ["GAS_CLASS", "SignalCluster", "SignalClusterer", "ssid_class"]
