"""A scenario's ``artifacts:`` section: which artifacts the world hides and the
referee's rules, checked when the scenario is loaded and placed when the world is
built (a placement problem names the file and the line of the item at fault)."""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...sim.artifacts import ARTIFACT_CLASSES, Artifact, PlacementSpec, listed_artifacts, place_artifacts
from ..errors import DelveError, clip_message
from ..yamlio import YamlDict, plain

#: The Prize Round's report limit and scoring radius (CERBERUS paper, Section 3.5).
REPORT_LIMIT = 45
SCORE_RADIUS_M = 5.0


@dataclass(frozen=True)
class ArtifactSetup:
    """The checked ``artifacts:`` section: ``count`` artifacts of ``classes`` placed
    by ``seed`` (None: the scenario's) ``min_spacing_m`` apart, the listed ``items``,
    and the referee's ``report_limit`` and ``score_radius_m``."""

    path: Path
    doc: YamlDict
    count: int
    classes: tuple[str, ...]
    seed: int | None
    min_spacing_m: float
    items: tuple[dict[str, Any], ...]
    report_limit: int
    score_radius_m: float

    @classmethod
    def from_scenario(cls, doc: YamlDict, path: Path) -> "ArtifactSetup | None":
        """The scenario's section (its schema already checked), or None without one."""
        section = doc.get("artifacts")
        if section is None:
            return None
        if not section.get("count") and not section.get("items"):
            raise DelveError("artifacts: give 'count' (placed by seed) or 'items' (listed), or leave the section out",
                             path, doc.key_line("artifacts"))
        return cls(path=path, doc=section, count=int(section.get("count", 0)),
                   classes=tuple(section.get("classes", ARTIFACT_CLASSES)), seed=section.get("seed"),
                   min_spacing_m=float(section.get("min_spacing_m", PlacementSpec.min_spacing_m)),
                   items=tuple(plain(section.get("items", []))), report_limit=int(section.get("report_limit",
                                                                                          REPORT_LIMIT)),
                   score_radius_m=float(section.get("score_radius_m", SCORE_RADIUS_M)))

    def listed(self, world: Any) -> list[Artifact]:
        """The listed artifacts; a DelveError at the first item in rock or outside ``world``."""
        listed: list[Artifact] = []
        for i, item in enumerate(self.items):
            try:
                listed += listed_artifacts(world, [item])
            except ValueError as err:
                message = str(err).removeprefix("artifacts[0]: ")
                raise DelveError(f"artifacts/items/{i}: {clip_message(message)}", self.path,
                                 self.doc["items"].item_line(i)) from None
        return listed

    def place(self, world: Any, start: np.ndarray, seed: int) -> list[Artifact]:
        """The listed artifacts, then ``count`` more placed by seed in the free space
        reachable from ``start``; a DelveError at the item (or the ``count``) that
        cannot be placed."""
        listed = self.listed(world)
        placed: list[Artifact] = []
        if self.count:
            try:
                placed = place_artifacts(world, count=self.count, classes=self.classes,
                                         seed=seed if self.seed is None else self.seed, start=start,
                                         spec=PlacementSpec(min_spacing_m=self.min_spacing_m))
            except ValueError as err:
                raise DelveError(f"artifacts: {clip_message(err)}", self.path, self.doc.key_line("count")) from None
        return _renamed(listed + placed)


def _renamed(artifacts: list[Artifact]) -> list[Artifact]:
    """The artifacts named ``<class>_<n>``, counted per class in order, so that
    listed and placed artifacts never share a name."""
    seen: dict[str, int] = {}
    out = []
    for a in artifacts:
        seen[a.artifact_class] = seen.get(a.artifact_class, 0) + 1
        out.append(replace(a, name=f"{a.artifact_class}_{seen[a.artifact_class]}"))
    return out
