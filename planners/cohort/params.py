"""COHORT parameters (Kulkarni et al. 2022, section IV-B), the paper's values as defaults.

One frozen dataclass shared by the hub (``planners/cohort``, ``skills/cohort/hub.py``) and
the robots (``skills/cohort/robot.py``); the team strategy builds it from the scenario's
``team:`` block and hands it to every agent as service ``cohort_params``.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class CohortParams:
    """Every COHORT parameter; names follow the paper, units are in the names.

    Invalid values raise ``ValueError`` at construction (``__post_init__``); the strategy
    checks the same ranges with file/line messages before it builds one.
    """

    #: A submap is cut when this much time has passed since it began ...
    submap_window_s: float = 45.0
    #: ... or the robot moved this far from where it began.
    submap_displacement_m: float = 20.0
    #: r_C: resolution of the common map the hub computes global frontiers on.
    resolution_m: float = 0.4
    #: f_min: frontier clusters with fewer points (voxels at r_C) are dropped.
    f_min: int = 250
    #: N_C: vertices sampled per submap for the global graph G_C.
    n_vertices: int = 200
    #: rho_C: edges of G_C join vertices at most this far apart.
    edge_radius_m: float = 4.0
    #: T_C: a robot calls the hub every T_C seconds of exploration.
    period_s: float = 50.0
    #: T_C^e: without a link and with its box unexplored, a robot explores this much longer.
    extra_explore_s: float = 150.0
    #: n_C: the share (percent) of frontier clusters, largest first, a robot may be sent to.
    best_share_pct: float = 50.0
    #: D: size (x, y, z) of the exploration box given with a new frontier.
    box_m: tuple[float, float, float] = (360.0, 360.0, 20.0)

    def __post_init__(self) -> None:
        positive = {
            "submap_window_s": self.submap_window_s,
            "submap_displacement_m": self.submap_displacement_m,
            "resolution_m": self.resolution_m,
            "edge_radius_m": self.edge_radius_m,
            "period_s": self.period_s,
        }
        for name, value in positive.items():
            if not value > 0:
                raise ValueError(f"{name} must be > 0, got {value}")
        if self.f_min < 1 or self.n_vertices < 1:
            raise ValueError(f"f_min and n_vertices must be >= 1, got {self.f_min}, {self.n_vertices}")
        if self.extra_explore_s < 0:
            raise ValueError(f"extra_explore_s must be >= 0, got {self.extra_explore_s}")
        if not 0 < self.best_share_pct <= 100:
            raise ValueError(f"best_share_pct must be in (0, 100], got {self.best_share_pct}")
        if len(self.box_m) != 3 or not all(v > 0 for v in self.box_m):
            raise ValueError(f"box_m must be three sizes > 0, got {self.box_m}")
