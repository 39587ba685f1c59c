"""Parameters of CSIRO's frontier generation and sequential update (Williams et al., Sections
III-A and III-B), with the paper's values as defaults."""
from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class CsiroFrontierParams:
    """The frontier-generation stage.

    Paper values: d_vox 0.3 m, d_max 9 m, eta_subsample 1.5 m, gamma -0.018, eta_disc 0.8 m,
    eta_area 0.2 m^2, d_min 1 m, T_min 0.5 s, d_vp 5 m, eta_vis 5 mm. The paper gives no value for
    eta_dia (the largest distance of a segment's triangle from its anchor); 4 m keeps the segment
    at the open end of a 5 m wide drift in one piece. The sensor's elevations default to a fixed
    Velodyne Puck's +-15 deg; a skill sets them from the robot's LiDAR. ``blind_frontiers`` (not in
    the paper, whose sensor sees nearly every elevation): whether the sphere points a robot sees
    in the cones its sensor is blind to are frontier points too; a skill sets it for a flying robot,
    which can rise or sink to see them (a shaft straight above). ``assignment_max_kl`` bounds
    the KL divergence of an old/new correspondence (not in the paper, which assigns every pair the
    assignment picks: infinity).
    """

    d_vox_m: float = 0.3
    d_max_m: float = 9.0
    eta_subsample_m: float = 1.5
    gamma: float = -0.018
    eta_disc_m: float = 0.8
    eta_area_m2: float = 0.2
    eta_dia_m: float = 4.0
    d_min_m: float = 1.0
    t_min_s: float = 0.5
    d_vp_m: float = 5.0
    eta_vis_m: float = 0.005
    elevation_min_deg: float = -15.0
    elevation_max_deg: float = 15.0
    blind_frontiers: bool = False
    assignment_max_kl: float = math.inf

    def __post_init__(self) -> None:
        check_frontier_params(self)

    @property
    def sphere_spacing_rad(self) -> float:
        """Angular spacing of the sphere points S(a, d_max) (the paper gives none): eta_disc / 2
        apart at d_max, so that even the diagonal between neighbours is no discontinuity."""
        return 0.5 * self.eta_disc_m / self.d_max_m


#: Fields that must be > 0 (distances, areas, times).
_POSITIVE = ("d_vox_m", "d_max_m", "eta_disc_m", "eta_area_m2", "eta_dia_m", "d_vp_m", "eta_vis_m",
             "assignment_max_kl")
#: Fields that must be >= 0.
_NON_NEGATIVE = ("eta_subsample_m", "d_min_m", "t_min_s")


def check_frontier_params(p: CsiroFrontierParams) -> None:
    """Raise ValueError naming the first parameter out of range (gamma must be negative, distances
    positive, elevations within [-90, 90] deg and min below max, eta_subsample at most d_max)."""
    values = {f.name: getattr(p, f.name) for f in fields(p)}
    if not isinstance(values.pop("blind_frontiers"), bool):
        raise ValueError(f"blind_frontiers must be true or false, got {p.blind_frontiers!r}")
    for name, v in values.items():
        if not isinstance(v, (int, float)) or isinstance(v, bool) or math.isnan(v):
            raise ValueError(f"{name} must be a number, got {v!r}")
    for name in _POSITIVE:
        if values[name] <= 0:
            raise ValueError(f"{name} must be > 0, got {values[name]}")
    for name in _NON_NEGATIVE:
        if values[name] < 0:
            raise ValueError(f"{name} must be >= 0, got {values[name]}")
    if p.gamma >= 0.0:
        raise ValueError(f"gamma must be negative (paper: -0.018), got {p.gamma}")
    if p.eta_subsample_m > p.d_max_m:
        raise ValueError(f"eta_subsample_m ({p.eta_subsample_m}) must not exceed d_max_m ({p.d_max_m})")
    for name in ("elevation_min_deg", "elevation_max_deg"):
        if not -90.0 <= values[name] <= 90.0:
            raise ValueError(f"{name} must be within [-90, 90] deg, got {values[name]}")
    if p.elevation_min_deg >= p.elevation_max_deg:
        raise ValueError(f"elevation_min_deg ({p.elevation_min_deg}) must be below elevation_max_deg "
                         f"({p.elevation_max_deg})")


__all__ = ["CsiroFrontierParams", "check_frontier_params"]
