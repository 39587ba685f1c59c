"""The input of one integer program: the connectivity problem at a fixed horizon,
and how it is to be solved."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from .network import MCNetwork
from .plan import Requirement


@dataclass(frozen=True)
class SolverOptions:
    """How each integer program is solved.

    ``solver``: ``"highs"``, ``"cbc"`` or None (HiGHS when installed, else CBC).
    ``time_limit_s`` bounds every solve (the best plan found so far is returned, with
    its optimality gap); ``mip_gap`` is the relative gap at which a solve stops;
    ``probe_time_limit_s`` bounds each feasibility probe of the horizon search.
    ``total_time_limit_s`` bounds one call of ``plan_cycle`` (or of
    ``solve_pre_exploration`` / ``solve_post_exploration``): every solve's limit is
    cut to its share of the time left, so the call returns about then with the best
    plans found (model building and a last short solve may overrun it a little);
    None for no bound. ``workers``: independent problems (clusters) solved at once.
    ``stall_time_s``: a solve that holds a plan stops when the plan has not improved
    for this long (nor for half the time it took to find it); None to disable.
    """

    time_limit_s: float | None = 30.0
    mip_gap: float | None = 0.01
    solver: str | None = None
    threads: int = 1
    probe_time_limit_s: float | None = 5.0
    total_time_limit_s: float | None = 10.0
    workers: int = 2
    stall_time_s: float | None = 2.0


@dataclass
class ConnectivityProblem:
    """An intermittent-connectivity problem at a fixed horizon.

    ``holdings`` gives the information labels each robot holds at t = 0 (default:
    its own name). ``location_rewards[s]`` are the marginal rewards
    R(s, 1) − R(s, 0), R(s, 2) − R(s, 1), ... for robots of ``reward_robots``
    (default: ``explorers``) holding m at s at T; robots so rewarded at a location of
    ``frontiers`` are sent exploring. ``master_sinks`` must hold m by T.

    ``warm_start`` gives trajectories (robot -> locations from t = 0, the last one
    held to T) of a plan believed feasible; the solver completes it and starts from
    it, so a solve stopped by its time limit returns at least that plan.
    ``time_weight`` is a tiny cost per action and step index: of equally good plans
    the earliest wins, which lets a search solve once at a generous horizon and cut
    the plan after its last action.
    """

    network: MCNetwork
    horizon: int
    positions: Mapping[str, str]
    masters: set[str]
    static: set[str] = field(default_factory=set)
    explorers: set[str] = field(default_factory=set)
    holdings: dict[str, set[str]] = field(default_factory=dict)
    requirements: list[Requirement] = field(default_factory=list)
    master_sinks: set[str] = field(default_factory=set)
    location_rewards: dict[str, tuple[float, ...]] = field(default_factory=dict)
    reward_robots: set[str] | None = None
    frontiers: set[str] = field(default_factory=set)
    collision_robots: set[str] = field(default_factory=set)
    collision_locations: set[str] = field(default_factory=set)
    final_positions: dict[str, str] = field(default_factory=dict)
    phase: str = "plan"
    options: SolverOptions = field(default_factory=SolverOptions)
    feasibility_only: bool = False
    warm_start: Mapping[str, list[str]] | None = None
    time_weight: float = 0.0

    def holding(self, r: str) -> set[str]:
        return set(self.holdings.get(r, {r}))
