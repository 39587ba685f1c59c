"""GBPlanner2: graph-based exploration path planning for legged and aerial robots.

Kulkarni et al. 2022 (section IV-A, Algorithms 1-3, Table I) and the CERBERUS SubT
Final paper (section 3.3.1). Pure algorithms over numpy occupancy grids
(:class:`delve.planners.occupancy.Grid`); randomness only from the
``numpy.random.Generator`` a caller passes in.

Modules: ``config`` (parameters, Table I presets), ``bounds`` (adaptive local bounding
box), ``local_map`` (collision checks, ground projection), ``graph`` (Algorithm 2,
Dijkstra), ``gain`` (Algorithm 3, path gain), ``path_improvement``, ``local_planner``
(Algorithm 1), ``global_planner`` (global graph, repositioning, homing, goals),
``planner`` (both layers per iteration), ``synthetic`` (small test worlds).
"""
from .bounds import LocalBound, adaptive_local_bound
from .config import ANYMAL_C, PRESETS, RMF_OBELIX, GBPlannerConfig
from .gain import compute_vertex_gains, exploration_gains, sensor_rays, volumetric_gain
from .global_planner import Frontier, GlobalPlanner, GlobalPlanResult, HomingCheck
from .graph import LocalGraph, ShortestPaths, build_local_graph, shortest_paths
from .local_map import LocalMap
from .local_planner import LocalPlanner, LocalPlanResult, PlanDiagnostics
from .path_improvement import improve_path, truncate_path
from .planner import GBPlanner, PlanResult

__all__ = [
    "ANYMAL_C",
    "PRESETS",
    "RMF_OBELIX",
    "Frontier",
    "GBPlanner",
    "GBPlannerConfig",
    "GlobalPlanResult",
    "GlobalPlanner",
    "HomingCheck",
    "LocalBound",
    "LocalGraph",
    "LocalMap",
    "LocalPlanResult",
    "LocalPlanner",
    "PlanDiagnostics",
    "PlanResult",
    "ShortestPaths",
    "adaptive_local_bound",
    "build_local_graph",
    "compute_vertex_gains",
    "exploration_gains",
    "improve_path",
    "sensor_rays",
    "shortest_paths",
    "truncate_path",
    "volumetric_gain",
]
