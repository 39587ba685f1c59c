"""COPS: information-consistent multi-robot plans under intermittent connectivity.

Pure planning core (networkx / numpy / pulp): the mobility-communication network,
the intermittent-connectivity integer program, Problem 1 (pre-exploration) and
Problem 2 (post-exploration), clustering for large networks, plans as plain data
and the plan validator.
"""
from .cycle import exploration_tasks, plan_cycle
from .distances import information_distance
from .errors import InfeasibleProblem, PlanningError, SolverTimeout
from .ilp import plan_cost, solve_connectivity
from .ilp_problem import ConnectivityProblem, SolverOptions
from .ilp_solvers import available_solver
from .network import (MCNetwork, Robot, add_team, dead_ends, network_from_dict, tunnel_network_graph)
from .plan import MASTER, Communication, CyclePlan, ExplorationTask, Plan, Requirement, Step
from .plan_extraction import reconstruct_communications
from .post_exploration import solve_post_exploration
from .pre_exploration import solve_pre_exploration
from .rewards import FrontierReward
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
