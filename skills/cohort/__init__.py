"""COHORT behaviours (Kulkarni et al. 2022, section IV-B): the hub on the base station
(:mod:`.hub`) and the robots' side. The algorithms are in :mod:`delve.planners.cohort`."""
from .hub import (ASSIGNMENT, HUB_SERVICE, REQUEST, SUBMAP, AnswerRepositionRequests, MergeSubmaps,
                  UpdateGlobalFrontiers, cohort_hub)

__all__ = ["ASSIGNMENT", "HUB_SERVICE", "REQUEST", "SUBMAP", "AnswerRepositionRequests", "MergeSubmaps",
           "UpdateGlobalFrontiers", "cohort_hub"]
from .lost_link import CohortTimer, ExplorationOver, ReturnToLinkPoint
from .robot import CallHub, FollowHubPath, SendSubmaps

__all__ += ["CallHub", "CohortTimer", "ExplorationOver", "FollowHubPath", "ReturnToLinkPoint", "SendSubmaps"]
