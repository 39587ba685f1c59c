"""CSIRO 3D frontier exploration (Williams et al., issue 14): pure planning core.

Frontiers straight from LiDAR points by direct visibility (Section III-A), their
sequential update (Section III-B, Algorithm 2), observer planning, sharing and selection.
"""
from .frontier_types import Frontier, FrontierMesh
from .observer import Observer, ObserverCandidates, observation_rewards, observer_candidates, plan_observer
from .params import CsiroFrontierParams
from .point_cache import PointCache
from .segmentation import segment_frontiers
from .selection import (FailedFrontiers, GoalProgress, UavMomentum, UgvChoice, select_uav_frontier,
                        select_ugv_frontier, uav_frontier_complete)
from .selection_params import CsiroSelectionParams
from .sequential import FrontierUpdate, SequentialFrontiers, Viewpoint
from .sharing import FrontierKey, FrontierSummary, TrajectoryPoints, discount_places, discounted_rewards, summarise
from .visibility_mesh import visible_mesh

__all__ = [
    "CsiroFrontierParams", "Frontier", "FrontierMesh", "FrontierUpdate", "PointCache", "SequentialFrontiers",
    "Viewpoint", "segment_frontiers", "visible_mesh",
    "CsiroSelectionParams", "FailedFrontiers", "FrontierKey", "FrontierSummary", "GoalProgress", "Observer",
    "ObserverCandidates", "TrajectoryPoints", "UavMomentum", "UgvChoice", "discount_places", "discounted_rewards",
    "observation_rewards", "observer_candidates", "plan_observer", "select_uav_frontier", "select_ugv_frontier",
    "summarise", "uav_frontier_complete",
]
