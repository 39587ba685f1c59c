"""CSIRO 3D frontier exploration (Williams et al., issue 14): the robots' and the base station's
behaviours. The algorithms are in :mod:`delve.planners.csiro`."""
from .explore_sync import ReturnToComms, ReturnToRegion, SyncDue, Uplink
from .follow import FollowFrontierGoal
from .frontiers import UpdateFrontiers
from .selection import SelectUavFrontier, SelectUgvFrontier
from .sharing import BASE_SERVICE, CollectFrontiers, ShareFrontiers
from .state import CONFIG_SERVICE, STATE_SERVICE, CsiroConfig, CsiroState, csiro_state

__all__ = ["BASE_SERVICE", "CONFIG_SERVICE", "STATE_SERVICE", "CollectFrontiers", "CsiroConfig", "CsiroState",
           "FollowFrontierGoal", "ReturnToComms", "ReturnToRegion", "SelectUavFrontier", "SelectUgvFrontier",
           "ShareFrontiers", "SyncDue", "UpdateFrontiers", "Uplink", "csiro_state"]
