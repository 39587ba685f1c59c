"""GBPlanner2 parameters, with the two robots of the paper's Table I as presets.

Names follow the papers (Kulkarni et al. 2022, "Autonomous Teamed Exploration of
Subterranean Environments using Legged and Aerial Robots", section IV-A and Table I;
Dang et al. 2020 for GBPlanner1's path gain and global planner). Units are in the
names. Parameters that Table I does not give take the values of the open-source
planner's configurations for the same kind of robot.

Table I:

============================  ===============  ================
Parameter                     ANYmal C         RMF-Obelix
============================  ===============  ================
r_V (map resolution)          0.2 m            0.3 m
N_V,max                       1000             500
[F_H, F_V], d_max             [360, 30]°, 30 m [360, 90]°, 30 m
rho (clustering radius)       0 (disabled)     1 m
T_end                         70 min           8.5 min
============================  ===============  ================

and gamma_H = 5 for the hanging vertices, mu_V = 50 m for the local point cloud.
"""
from __future__ import annotations

import math
import reprlib
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

#: Robot types the planner knows: legged robots walk on the ground, aerial ones fly.
ROBOT_TYPES = ("legged", "aerial")


@dataclass(frozen=True)
class GBPlannerConfig:
    """Every parameter of GBPlanner2's local and global planners.

    Invalid values raise ``ValueError`` at construction (``__post_init__``).
    """

    # --- robot -------------------------------------------------------------------
    #: ``legged`` (ground robot: vertices and edges projected onto the ground) or ``aerial``.
    robot_type: str = "legged"
    #: Map resolution r_V the preset was tuned for; the planner itself uses the grid's.
    voxel_size_m: float = 0.2
    #: Robot bounding box (x, y, z) used for collision checking; unknown voxels are not free.
    robot_box_size_m: tuple[float, float, float] = (0.8, 0.8, 0.2)
    #: Legged: height of the body centre (the planned point) above the ground.
    body_height_m: float = 0.5
    #: Legged: ground farther than this below the body centre does not support it
    #: (the vertex is *hanging*); also the depth the ground projection searches.
    ground_search_depth_m: float = 1.2
    #: Legged: radius of the circle around the projected point whose columns are also
    #: searched for ground (ground voxels mapped as free by mistake).
    ground_circle_radius_m: float = 0.4
    #: Legged: number of points on that circle.
    ground_circle_points: int = 8
    #: Legged: unknown ground within this radius under the robot counts as ground (the
    #: LiDAR cannot see the ground right around the robot that stands on it); 0: off.
    assumed_ground_radius_m: float = 2.5
    #: Legged: the steepest inclination an edge may have (over ``inclination_window_m``).
    max_inclination_deg: float = 30.0
    #: Legged: horizontal length over which the inclination of a projected edge is
    #: measured (voxel-quantised ground needs a window longer than a voxel).
    inclination_window_m: float = 1.0
    #: Legged: highest step between neighbouring ground points along an edge.
    max_step_m: float = 0.3
    #: Speed used to turn path lengths into times (homing, repositioning).
    speed_mps: float = 1.0

    # --- local bounding box (adaptive, PCA of the local point cloud) --------------
    #: mu_V: radius of the local point cloud whose PCA orients the local bounding box.
    local_pointcloud_range_m: float = 50.0
    #: Spacing at which voxels of the local point cloud are taken for the PCA.
    local_pointcloud_spacing_m: float = 0.6
    #: Percentile of the points' distances along each principal axis that sets the
    #: box's half extent on that axis.
    bounding_box_percentile: float = 95.0
    #: Smallest side of the local bounding box, per principal axis (largest first).
    bounding_box_size_min_m: tuple[float, float, float] = (6.0, 4.0, 3.0)
    #: Largest side of the local bounding box.
    bounding_box_size_max_m: float = 35.0

    # --- local graph (Algorithm 2) -------------------------------------------------
    #: N_V,max: graph building stops at this many vertices.
    num_vertices_max: int = 1000
    #: N_E,max: graph building stops at this many edges.
    num_edges_max: int = 12000
    #: Sampling budget (random points drawn in the local box) for one graph.
    num_samples_max: int = 30000
    #: Shortest admissible edge; samples closer than this to an earlier one are dropped.
    edge_length_min_m: float = 0.2
    #: Longest admissible edge.
    edge_length_max_m: float = 3.0
    #: delta: radius within which a new vertex is connected to existing ones.
    neighbour_radius_m: float = 2.5
    #: At most this many nearest vertices within delta are tried for connections.
    neighbours_max: int = 12

    # --- sensor and volumetric gain (Algorithm 3) ---------------------------------
    #: F_H: horizontal field of view of the depth sensor.
    sensor_fov_horizontal_deg: float = 360.0
    #: F_V: vertical field of view of the depth sensor.
    sensor_fov_vertical_deg: float = 30.0
    #: d_max: the sensor range modelled for the gain.
    sensor_range_m: float = 30.0
    #: Height of the sensor above the planned point.
    sensor_offset_z_m: float = 0.0
    #: Angular spacing of the gain rays, horizontally.
    gain_ray_resolution_horizontal_deg: float = 12.0
    #: Angular spacing of the gain rays, vertically.
    gain_ray_resolution_vertical_deg: float = 10.0
    #: Vertex k casts its ring of rays turned by (k mod this) / this of the ray spacing:
    #: neighbouring vertices together sample the field of view this many times finer.
    gain_ray_interleave: int = 4
    #: Ray-marching step as a multiple of the voxel size (at most 1: no voxel skipped).
    gain_ray_step_voxels: float = 1.0
    #: gamma_H: the gain of a hanging vertex is scaled by exp(-gamma_H).
    hanging_vertex_penalty: float = 5.0
    #: Compute the gain only on the leaf vertices of the shortest-path tree.
    leaf_only_gain: bool = False
    #: rho: vertices within this radius of one whose gain was computed take its gain
    #: (0 disables clustering).
    clustering_radius_m: float = 0.0

    # --- path gain and path improvement (Algorithm 1) ----------------------------
    #: gamma_D: gain of a vertex discounted by exp(-gamma_D * distance along the path).
    path_length_penalty_per_m: float = 0.07
    #: gamma_S: path gain scaled by exp(-gamma_S * deviation from the exploring direction)
    #: (deviation is dimensionless: mean offset from the straight line / mean arc length).
    path_direction_penalty: float = 0.3
    #: Improve the best path (shortcut, then push away from obstacles).
    path_improvement_enable: bool = True
    #: Largest distance a waypoint is pushed away from obstacles.
    path_safety_extension_m: float = 0.5
    #: Passes of the push-away step.
    path_improvement_iterations: int = 4
    #: The commanded path is cut to this length (the planner is re-triggered at its end).
    traverse_length_max_m: float = 12.0

    # --- global planner ----------------------------------------------------------
    #: Local gain below this counts as a low-gain iteration.
    low_gain_threshold_m3: float = 20.0
    #: Repositioning to the best frontier after this many low-gain iterations in a row.
    low_gain_iterations_max: int = 3
    #: A local vertex with at least this gain becomes a frontier of the global graph.
    frontier_gain_min_m3: float = 60.0
    #: At most this many frontiers are added to the global graph per iteration.
    frontiers_per_iteration_max: int = 5
    #: Frontiers closer than this to an existing one are not added.
    frontier_spacing_m: float = 4.0
    #: New global vertices closer than this to an existing one reuse it.
    global_vertex_merge_radius_m: float = 0.4
    #: The robot or a goal is connected to global vertices within this distance.
    global_connection_radius_m: float = 5.0
    #: Frontier choice: gain divided by (path length + this), so near frontiers win ties.
    frontier_distance_offset_m: float = 10.0
    #: Homing margin added to the time the way home takes.
    homing_margin_s: float = 60.0
    #: Homing also keeps time for one more local step out and back.
    homing_include_next_step: bool = True

    def __post_init__(self) -> None:
        # Sequences from YAML or JSON arrive as lists: keep the config hashable.
        for name in ("robot_box_size_m", "bounding_box_size_min_m"):
            value = getattr(self, name)
            if isinstance(value, list):
                object.__setattr__(self, name, tuple(value))
        problems = _type_problems(self) or _problems(self)
        if problems:
            raise ValueError("invalid GBPlannerConfig: " + "; ".join(problems))

    # --- presets and derived values ------------------------------------------------
    @classmethod
    def anymal_c(cls, **overrides: Any) -> GBPlannerConfig:
        """Table I's legged robot, ANYmal C (VLP-16; 6-core i7)."""
        return cls.preset("anymal_c", **overrides)

    @classmethod
    def rmf_obelix(cls, **overrides: Any) -> GBPlannerConfig:
        """Table I's aerial robot, RMF-Obelix (OS0-64; ARM A311D)."""
        return cls.preset("rmf_obelix", **overrides)

    @classmethod
    def preset(cls, name: str, **overrides: Any) -> GBPlannerConfig:
        """A preset by name: ``anymal_c`` / ``legged`` or ``rmf_obelix`` / ``aerial``,
        with ``overrides`` (e.g. a YAML mapping); unknown names raise ValueError."""
        key = PRESET_ALIASES.get(name, name)
        if key not in PRESETS:
            raise ValueError(f"unknown GBPlanner2 preset {name!r} (known: {', '.join(sorted(PRESET_ALIASES))})")
        _check_names(overrides)
        return cls(**{**PRESETS[key], **overrides})

    def replace(self, **changes: Any) -> GBPlannerConfig:
        """A copy with ``changes`` (validated)."""
        _check_names(changes)
        return replace(self, **changes)

    def with_robot_limits(
        self,
        *,
        speed_mps: float | None = None,
        body_height_m: float | None = None,
        radius_m: float | None = None,
        max_inclination_deg: float | None = None,
        max_step_m: float | None = None,
    ) -> GBPlannerConfig:
        """A copy adapted to a robot's own limits (e.g. the robot interface's Mobility).

        ``radius_m`` sets the horizontal sides of the collision box to twice the radius.
        """
        changes: dict[str, Any] = {}
        if speed_mps is not None:
            changes["speed_mps"] = float(speed_mps)
        if body_height_m is not None and self.is_legged:
            changes["body_height_m"] = float(body_height_m)
        if radius_m is not None:
            side = 2.0 * float(radius_m)
            changes["robot_box_size_m"] = (side, side, self.robot_box_size_m[2])
        if max_inclination_deg is not None and self.is_legged:
            changes["max_inclination_deg"] = float(max_inclination_deg)
        if max_step_m is not None and self.is_legged and max_step_m > 0:
            changes["max_step_m"] = float(max_step_m)
        return self.replace(**changes)

    @property
    def is_legged(self) -> bool:
        return self.robot_type == "legged"

    @property
    def hanging_gain_factor(self) -> float:
        """exp(-gamma_H)."""
        return math.exp(-self.hanging_vertex_penalty)

    @property
    def clustering_enabled(self) -> bool:
        return self.clustering_radius_m > 0.0

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def _check_names(values: dict[str, Any]) -> None:
    unknown = set(values) - {f.name for f in fields(GBPlannerConfig)}
    if unknown:
        raise ValueError(f"unknown GBPlannerConfig parameter(s): {', '.join(sorted(map(str, unknown)))}")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


#: What a field's annotation asks of its value, and how a message says it.
_FIELD_TYPES = {
    "bool": (lambda v: isinstance(v, bool), "true or false"),
    "int": (lambda v: isinstance(v, int) and not isinstance(v, bool), "an integer"),
    "float": (_is_number, "a number"),
    "str": (lambda v: isinstance(v, str), "a string"),
    "tuple[float, float, float]": (lambda v: isinstance(v, (tuple, list)) and len(v) == 3 and all(map(_is_number, v)),
                                   "three numbers"),
}


def _type_problems(c: GBPlannerConfig) -> list[str]:
    """Values of the wrong type (from YAML overrides), before the checks compare them."""
    out = []
    for f in fields(c):
        check, words = _FIELD_TYPES.get(str(f.type), (None, ""))
        value = getattr(c, f.name)
        if check is not None and not check(value):
            out.append(f"{f.name} must be {words}, got {reprlib.repr(value)}")
    return out


def _problems(c: GBPlannerConfig) -> list[str]:
    out: list[str] = []

    def positive(name: str) -> None:
        v = getattr(c, name)
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            out.append(f"{name} must be > 0, got {v!r}")

    def non_negative(name: str) -> None:
        v = getattr(c, name)
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            out.append(f"{name} must be >= 0, got {v!r}")

    for name in ("leaf_only_gain", "path_improvement_enable", "homing_include_next_step"):
        if not isinstance(getattr(c, name), bool):
            out.append(f"{name} must be true or false, got {getattr(c, name)!r}")
    if c.robot_type not in ROBOT_TYPES:
        out.append(f"robot_type must be one of {ROBOT_TYPES}, got {c.robot_type!r}")
    for name in (
        "voxel_size_m", "body_height_m", "ground_search_depth_m", "inclination_window_m",
        "max_step_m", "speed_mps", "local_pointcloud_range_m",
        "local_pointcloud_spacing_m", "bounding_box_size_max_m", "edge_length_max_m",
        "neighbour_radius_m", "sensor_range_m", "gain_ray_resolution_horizontal_deg",
        "gain_ray_resolution_vertical_deg", "gain_ray_step_voxels", "traverse_length_max_m",
        "global_connection_radius_m", "path_safety_extension_m", "frontier_distance_offset_m",
    ):
        positive(name)
    for name in (
        "ground_circle_radius_m", "assumed_ground_radius_m", "edge_length_min_m", "hanging_vertex_penalty",
        "clustering_radius_m", "path_length_penalty_per_m", "path_direction_penalty",
        "low_gain_threshold_m3", "frontier_gain_min_m3", "frontier_spacing_m",
        "global_vertex_merge_radius_m", "homing_margin_s", "sensor_offset_z_m",
    ):
        non_negative(name)
    for name in ("num_vertices_max", "num_edges_max", "num_samples_max", "neighbours_max", "gain_ray_interleave",
                 "low_gain_iterations_max", "frontiers_per_iteration_max"):
        v = getattr(c, name)
        if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
            out.append(f"{name} must be an integer >= 1, got {v!r}")
    for name in ("ground_circle_points", "path_improvement_iterations"):
        v = getattr(c, name)
        if not (isinstance(v, int) and not isinstance(v, bool) and v >= 0):
            out.append(f"{name} must be an integer >= 0, got {v!r}")
    if len(tuple(c.robot_box_size_m)) != 3 or any(not (s > 0) for s in c.robot_box_size_m):
        out.append(f"robot_box_size_m must be three sides > 0, got {c.robot_box_size_m!r}")
    if len(tuple(c.bounding_box_size_min_m)) != 3 or any(not (s > 0) for s in c.bounding_box_size_min_m):
        out.append(f"bounding_box_size_min_m must be three sides > 0, got {c.bounding_box_size_min_m!r}")
    elif max(c.bounding_box_size_min_m) > c.bounding_box_size_max_m:
        out.append("bounding_box_size_min_m must not exceed bounding_box_size_max_m")
    if not (0 < c.sensor_fov_horizontal_deg <= 360):
        out.append(f"sensor_fov_horizontal_deg must be in (0, 360], got {c.sensor_fov_horizontal_deg!r}")
    if not (0 < c.sensor_fov_vertical_deg <= 180):
        out.append(f"sensor_fov_vertical_deg must be in (0, 180], got {c.sensor_fov_vertical_deg!r}")
    if not (0 < c.max_inclination_deg < 90):
        out.append(f"max_inclination_deg must be in (0, 90), got {c.max_inclination_deg!r}")
    if not (0 < c.bounding_box_percentile <= 100):
        out.append(f"bounding_box_percentile must be in (0, 100], got {c.bounding_box_percentile!r}")
    if c.gain_ray_step_voxels > 1.0:
        out.append("gain_ray_step_voxels must be <= 1 (a longer step skips thin walls)")
    if c.edge_length_min_m >= c.edge_length_max_m:
        out.append("edge_length_min_m must be below edge_length_max_m")
    return out


#: Table I, ANYmal C (legged): 0.2 m voxels, 1000 vertices, 360x30 deg, 30 m, rho disabled, 70 min.
ANYMAL_C: dict[str, Any] = {
    "robot_type": "legged",
    "voxel_size_m": 0.2,
    "num_vertices_max": 1000,
    "num_edges_max": 12000,
    "sensor_fov_horizontal_deg": 360.0,
    "sensor_fov_vertical_deg": 30.0,
    "sensor_range_m": 30.0,
    "clustering_radius_m": 0.0,
    "leaf_only_gain": False,
    "hanging_vertex_penalty": 5.0,
    "robot_box_size_m": (0.8, 0.8, 0.2),
    "body_height_m": 0.5,
    "speed_mps": 1.0,
    "max_inclination_deg": 30.0,
    "gain_ray_resolution_vertical_deg": 10.0,
}

#: Table I, RMF-Obelix (aerial): 0.3 m voxels, 500 vertices, 360x90 deg, 30 m, rho = 1 m, 8.5 min.
RMF_OBELIX: dict[str, Any] = {
    "robot_type": "aerial",
    "voxel_size_m": 0.3,
    "num_vertices_max": 500,
    "num_edges_max": 7000,
    "sensor_fov_horizontal_deg": 360.0,
    "sensor_fov_vertical_deg": 90.0,
    "sensor_range_m": 30.0,
    "clustering_radius_m": 1.0,
    "leaf_only_gain": True,
    "hanging_vertex_penalty": 5.0,
    "robot_box_size_m": (0.6, 0.6, 0.4),
    "speed_mps": 1.0,
    "edge_length_max_m": 4.0,
    "neighbour_radius_m": 4.0,
    "gain_ray_resolution_vertical_deg": 15.0,
    "path_length_penalty_per_m": 0.1,
    "path_direction_penalty": 0.2,
    "bounding_box_size_min_m": (6.0, 4.0, 4.0),
    "traverse_length_max_m": 10.0,
    "homing_margin_s": 30.0,
}

PRESETS: dict[str, dict[str, Any]] = {"anymal_c": ANYMAL_C, "rmf_obelix": RMF_OBELIX}
PRESET_ALIASES: dict[str, str] = {
    "anymal_c": "anymal_c", "legged": "anymal_c", "rmf_obelix": "rmf_obelix", "aerial": "rmf_obelix",
}
