"""COHORT: the hub side of the teamed exploration of Kulkarni et al. 2022, section IV-B.

Pure algorithms over numpy occupancy grids: ``params`` (CohortParams).
"""
from .params import CohortParams

__all__ = ["CohortParams"]
