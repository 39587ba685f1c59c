"""COHORT: the hub side of the teamed exploration of Kulkarni et al. 2022, section IV-B.

Pure algorithms over numpy occupancy grids: ``params`` (CohortParams), ``common_map``
(the common map at r_C over the fine base map), ``frontiers`` (wavefront per submap,
re-check, 26-connected clusters, f_min), ``global_graph`` (G_C), ``reposition`` (the
target, path and box for a calling robot) and ``hub`` (the hub's state, tying them).
"""
from .common_map import CommonMap, align_submap
from .frontiers import GlobalFrontiers, cluster_frontiers, map_frontier, near_surface, recheck, submap_frontier
from .global_graph import GlobalGraph, segments_free, submap_rng, thin_trajectory
from .hub import HOME, AssignmentRecord, CohortHub, SubmapInfo
from .params import CohortParams
from .reposition import Reposition, choose_frontier, exploration_box

__all__ = [
    "HOME",
    "AssignmentRecord",
    "CohortHub",
    "CohortParams",
    "CommonMap",
    "GlobalFrontiers",
    "GlobalGraph",
    "Reposition",
    "SubmapInfo",
    "align_submap",
    "choose_frontier",
    "cluster_frontiers",
    "exploration_box",
    "map_frontier",
    "near_surface",
    "recheck",
    "segments_free",
    "submap_frontier",
    "submap_rng",
    "thin_trajectory",
]
