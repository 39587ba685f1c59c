"""COPS: information-consistent multi-robot plans under intermittent connectivity.

Pure planning core (networkx / numpy / pulp): the mobility-communication network,
the intermittent-connectivity integer program, Problem 1 (pre-exploration) and
Problem 2 (post-exploration), clustering for large networks, plans as plain data
and the plan validator.
"""
from .ilp import (ConnectivityProblem, InfeasibleProblem, PlanningError, SolverOptions, SolverTimeout,
                  available_solver, information_distance, plan_cost, reconstruct_communications,
                  solve_connectivity)
from .network import (MCNetwork, Robot, add_team, dead_ends, network_from_dict, tunnel_network_graph)
from .plan import MASTER, Communication, CyclePlan, ExplorationTask, Plan, Requirement, Step
from .problems import (FrontierReward, exploration_tasks, plan_cycle, solve_post_exploration,
                       solve_pre_exploration)
from .validator import Violation, validate_plan

__all__ = [
    "MASTER", "Communication", "ConnectivityProblem", "CyclePlan", "ExplorationTask", "FrontierReward",
    "exploration_tasks",
    "InfeasibleProblem", "MCNetwork", "Plan", "PlanningError", "Requirement", "Robot", "SolverOptions",
    "SolverTimeout", "Step", "Violation", "add_team", "available_solver", "dead_ends",
    "information_distance", "network_from_dict", "plan_cost", "plan_cycle", "reconstruct_communications",
    "solve_connectivity", "solve_post_exploration", "solve_pre_exploration", "tunnel_network_graph",
    "validate_plan",
]
