"""Each robot's artifact sensors: its platform's suite, with the scenario's
``sensors:`` overrides checked (a mistake is one line at the key)."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...sim.artifact_sensors import ArtifactSensorSpec, SpecError
from ...skills.base import short_repr
from ..errors import DelveError, did_you_mean
from ..yamlio import YamlDict, plain

if TYPE_CHECKING:
    from ..scenario import RobotSpec

#: Each platform's sensors where they differ from ANYmal C's (the spec's defaults).
#: Aerial: one forward colour camera of 85 x 64 degrees, as RMF-Owl's FLIR Blackfly S
#: (CERBERUS paper, Section 2), and no payload; Bluetooth and CO2 as on ANYmal.
PLATFORM_SENSORS: dict[str, dict[str, Any]] = {
    "legged": {},
    "aerial": {"camera_names": ("front",), "camera_yaw_deg": (0.0,), "camera_pitch_deg": (0.0,),
               "camera_horizontal_fov_deg": 85.0, "camera_vertical_fov_deg": 64.0},
}
_FIELDS = {f.name: f for f in dataclasses.fields(ArtifactSensorSpec)}


def sensor_spec(robot: "RobotSpec") -> ArtifactSensorSpec:
    """Robot ``robot``'s sensor parameters: its platform's, then its overrides."""
    return ArtifactSensorSpec(**{**PLATFORM_SENSORS[robot.platform], **robot.sensors})


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _value_problem(name: str, value: Any) -> str | None:
    """Why ``value`` does not fit field ``name``'s kind (a number, an integer, a
    list of numbers or names), or None."""
    default = getattr(ArtifactSensorSpec(), name)
    if isinstance(default, tuple):
        if not isinstance(value, list) or not value:
            return f"must be a non-empty list, not {short_repr(value)}"
        kind = str if isinstance(default[0], str) else float
        if any(not isinstance(v, str) if kind is str else not _number(v) for v in value):
            return f"must be a list of {'names' if kind is str else 'numbers'}, not {short_repr(value)}"
        return None
    if isinstance(default, int) and not isinstance(default, bool):
        return None if isinstance(value, int) and not isinstance(value, bool) else \
            f"must be an integer, not {short_repr(value)}"
    return None if _number(value) else f"must be a number, not {short_repr(value)}"


def check_sensors(robot: YamlDict, index: int, platform: str, path: Path) -> dict[str, Any]:
    """Robot ``robot``'s ``sensors:`` overrides, checked against the sensor model;
    a DelveError at the key at fault."""
    section = robot.get("sensors")
    if section is None:
        return {}
    where = f"robots/{index}/sensors"
    overrides: dict[str, Any] = {}
    for key, value in section.items():
        if key not in _FIELDS:
            raise DelveError(f"{where}: unknown parameter {short_repr(key)}{did_you_mean(str(key), _FIELDS)}", path,
                             section.key_line(key))
        problem = _value_problem(key, value)
        if problem:
            raise DelveError(f"{where}/{key}: {problem}", path, section.key_line(key))
        value = plain(value)
        overrides[key] = tuple(value) if isinstance(value, list) else value
    try:
        ArtifactSensorSpec(**{**PLATFORM_SENSORS[platform], **overrides})
    except SpecError as err:
        line = section.key_line(err.field) if isinstance(section, YamlDict) else None
        raise DelveError(f"{where}/{err}", path, line or section.line) from None
    return overrides
