"""Parameters of CSIRO's observer planning, frontier sharing and frontier selection
(Williams et al., Sections III-C, III-D and IV), with the paper's values as defaults.

Every value comes from the paper unless its line says "chosen"; the paper gives no
number for those. The dataclass checks its values and raises ValueError with a
one-line message naming the field.
"""
from __future__ import annotations

from dataclasses import dataclass


def _check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


@dataclass(frozen=True)
class CsiroSelectionParams:
    """Observer planning (III-C), shared frontier discounts (III-D), UGV and UAV
    selection (IV-A, IV-B).

    Observer planning:

    - ``eta_norm_deg`` (30): a mesh vertex is traversable when its normal is within
      this angle of the z axis (equation 10).
    - ``eta_trav_m`` (0.5): ... and no non-traversable vertex lies within this
      distance (equation 11).
    - ``observer_spacing_m`` (0.8): traversable vertices are sub-sampled to one per
      neighbourhood of this size.
    - ``reduced_dynamic_range`` (True): equation 12 with d_max^3 / r^2 replaced by
      d_max^2 / r, which the paper found to select better.
    - ``reward_min_range_m`` (0.5, chosen: eta_trav): the range r of equation 12 is
      at least this, so an observer next to a triangle does not get an unbounded reward.

    Sharing and discounts:

    - ``rho`` (0.2), ``eta_d_m`` (6.0): the discount d_{rho, eta_d} of equation 14, rho
      at a visited place, 1 from eta_d on.
    - ``trajectory_period_s`` (5.0): a trajectory point is kept every this often.
    - ``share_period_s`` (5.0): summaries and trajectory points are shared this often
      while a link exists.

    Selection:

    - ``progress_m`` (1.0), ``progress_window_s`` (15.0): navigation to a goal has
      failed when the closest approach to it improves by less than ``progress_m`` in
      ``progress_window_s`` (Algorithm 3; the UAV's blacklist uses the same rule).
    - ``rho_fail`` (0.2, chosen: the paper names the penalty but not its value; the
      same factor as a visited place): a failed frontier's reward is multiplied by this
      until the frontier is updated.
    - ``ugv_min_distance_m`` (1.0, chosen: the frontier update distance d_min): the
      distance of equation 15 is at least this, so a frontier beside the robot does not
      get an unbounded utility.
    - ``uav_same_frontier_gain`` (4, s_f), ``uav_momentum_weight`` (2, w): the momentum
      p_f = s_f * w^(v . v') of equation 16.
    - ``uav_z_weight`` (2): the z component of the UAV's distance is multiplied by this.
    - ``uav_max_size_m`` (5, eta_size): the frontier size term of equation 16 is at most
      this.
    - ``uav_blacklist_m`` (3, eta_blacklist): the distance of equation 16 is at least
      this, and a frontier whose centre the UAV comes this close to is complete.
    - ``uav_min_area_m2`` (1.7): smaller frontiers are not selected by the UAV.
    """

    eta_norm_deg: float = 30.0
    eta_trav_m: float = 0.5
    observer_spacing_m: float = 0.8
    reduced_dynamic_range: bool = True
    reward_min_range_m: float = 0.5
    rho: float = 0.2
    eta_d_m: float = 6.0
    trajectory_period_s: float = 5.0
    share_period_s: float = 5.0
    progress_m: float = 1.0
    progress_window_s: float = 15.0
    rho_fail: float = 0.2
    ugv_min_distance_m: float = 1.0
    uav_same_frontier_gain: float = 4.0
    uav_momentum_weight: float = 2.0
    uav_z_weight: float = 2.0
    uav_max_size_m: float = 5.0
    uav_blacklist_m: float = 3.0
    uav_min_area_m2: float = 1.7

    def __post_init__(self) -> None:
        _check(0.0 < self.eta_norm_deg < 90.0, f"eta_norm_deg: {self.eta_norm_deg} must be in (0, 90)")
        for name in ("eta_trav_m", "observer_spacing_m", "reward_min_range_m", "eta_d_m", "trajectory_period_s",
                     "share_period_s", "progress_m", "progress_window_s", "ugv_min_distance_m", "uav_z_weight",
                     "uav_max_size_m", "uav_blacklist_m"):
            value = getattr(self, name)
            _check(value > 0, f"{name}: {value} must be > 0")
        for name in ("rho", "rho_fail"):
            value = getattr(self, name)
            _check(0.0 < value <= 1.0, f"{name}: {value} must be in (0, 1]")
        for name in ("uav_same_frontier_gain", "uav_momentum_weight"):
            value = getattr(self, name)
            _check(value >= 1.0, f"{name}: {value} must be >= 1")
        _check(self.uav_min_area_m2 >= 0, f"uav_min_area_m2: {self.uav_min_area_m2} must be >= 0")


__all__ = ["CsiroSelectionParams"]
