"""The frontier data shared by every CSIRO stage (generation, observer planning, selection)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FrontierMesh:
    """The visible surface from one viewpoint (or a merge of several).

    vertices (V, 3) float64; triangles (T, 3) int64 indices into vertices;
    frontier (T,) bool, True for frontier triangles; viewpoint (3,) the sensor position.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    frontier: np.ndarray
    viewpoint: np.ndarray


@dataclass(frozen=True)
class Frontier:
    """One segmented frontier (Algorithm 1 output).

    points (K, 3) triangle centroids of the segment; normals (K, 3) unit normals pointing out
    of the known space; areas (K,) triangle areas in m^2; mean (3,) and cov (3, 3) the
    area-weighted Gaussian of the points (used for the KL correspondence and for sharing).
    """

    id: int
    points: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    mean: np.ndarray
    cov: np.ndarray

    @property
    def area(self) -> float:
        """Total area of the segment in m^2."""
        return float(np.sum(self.areas))
