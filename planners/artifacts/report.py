"""An artifact report: what a robot sends to the base station over the radio once it
is confident of an artifact (CERBERUS paper, section 3.5: "a single report was sent
to the Base Station"), and the SubT Final's artifact classes."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import xyz

#: The SubT Final's artifact classes, exactly these strings.
ARTIFACT_CLASSES = ("survivor", "cell_phone", "backpack", "drill", "fire_extinguisher",
                    "vent", "gas", "helmet", "rope", "cube")
#: Where a report's evidence came from.
SOURCES = ("camera", "bluetooth", "co2")
#: Decimals kept on the radio: positions to the centimetre (far below the 0.2 m voxels
#: and the 5 m scoring radius), probabilities to 1e-4, times to the millisecond.
POSITION_DIGITS = 2
PROBABILITY_DIGITS = 4
TIME_DIGITS = 3


@dataclass(frozen=True, eq=False)
class ArtifactReport:
    """One robot's report of one artifact: its class, position (3,) in the world frame
    (m), the fused probability of that class, the number of detections or readings
    behind it, the sim time of the report (s), the evidence's source and the
    reporting robot's name. ``position`` is stored as a read-only float array;
    reports compare by identity (use :meth:`to_dict` to compare contents).
    Raises ValueError (one line) for an unknown class or source, a probability
    outside [0, 1], fewer than one detection or a position that is not 3 finite
    numbers."""

    artifact_class: str
    position: np.ndarray
    probability: float
    detections: int
    t_s: float
    source: str
    robot: str | None = None

    def __post_init__(self) -> None:
        if self.artifact_class not in ARTIFACT_CLASSES:
            raise ValueError(f"unknown artifact class {self.artifact_class!r} "
                             f"(one of {', '.join(ARTIFACT_CLASSES)})")
        if self.source not in SOURCES:
            raise ValueError(f"unknown report source {self.source!r} (one of {', '.join(SOURCES)})")
        if not 0.0 <= self.probability <= 1.0:
            raise ValueError(f"report probability {self.probability} is outside [0, 1]")
        if self.detections < 1:
            raise ValueError(f"a report needs at least one detection, not {self.detections}")
        position = np.array(self.position, dtype=float).reshape(-1)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise ValueError(f"report position must be 3 finite numbers, not {self.position!r}")
        position.flags.writeable = False
        object.__setattr__(self, "position", position)

    def to_dict(self) -> dict:
        """Plain JSON-able values for the radio, rounded (see ``*_DIGITS``)."""
        return {"artifact_class": self.artifact_class, "position": xyz(self.position, POSITION_DIGITS),
                "probability": round(float(self.probability), PROBABILITY_DIGITS),
                "detections": int(self.detections), "t_s": round(float(self.t_s), TIME_DIGITS),
                "source": self.source, "robot": self.robot}

    @classmethod
    def from_dict(cls, data: dict) -> ArtifactReport:
        """The report that :meth:`to_dict` wrote; ValueError (one line) for a missing
        key or a bad value."""
        try:
            return cls(artifact_class=data["artifact_class"], position=np.asarray(data["position"], float),
                       probability=float(data["probability"]), detections=int(data["detections"]),
                       t_s=float(data["t_s"]), source=data["source"], robot=data.get("robot"))
        except KeyError as missing:
            raise ValueError(f"artifact report lacks {missing}") from None


__all__ = ["ARTIFACT_CLASSES", "SOURCES", "ArtifactReport"]
