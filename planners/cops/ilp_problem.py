"""The input of one integer program: the connectivity problem at a fixed horizon,
and how it is to be solved."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping

from .network import MCNetwork
from .plan import Requirement

if TYPE_CHECKING:
    from .meter import Meter


@dataclass(frozen=True)
class SolverOptions:
    """How each integer program is solved.

    ``solver``: ``"highs"``, ``"cbc"`` or None (HiGHS when installed, else CBC);
    ``mip_gap`` is the relative gap at which a solve stops; ``workers``: independent
    problems (clusters) solved at once.

    **Work limits** bound every result, so that the same problem gives the same plan
    on a quiet machine and on a busy one (:mod:`.budget`). HiGHS calls back at fixed
    points of its search, its *checkpoints*: after presolve, after each round of cuts
    at the root, and after each node or dive of the tree. A checkpoint after the root
    LP counts as *checkpoint work* (rows / 2000)², at least 0.5: a round or a node
    re-solves the LP, with more and dearer simplex iterations on a larger model
    (:func:`~.ilp_solvers.checkpoint_weight`). A solve stops after ``max_nodes``
    branch-and-bound nodes or ``max_work`` checkpoint work (feasibility probes of the
    horizon searches: ``probe_max_nodes``, ``probe_max_work``), and a solve that
    holds a plan stops when the plan has not improved for ``stall_work`` (nor for half
    the work it took to find it). The root LP is not cut: HiGHS calls back before and
    after it, never during it; so a warm-started model of more than
    ``search_max_rows`` rows, whose root LP alone would take tens of seconds, is not
    searched (its completed warm start is the plan). ``total_work`` bounds one planning call
    (``plan_cycle``, ``solve_pre_exploration``, ``solve_post_exploration``,
    ``solve_recall``) in simplex iterations summed over its solves: once it is spent
    no further probe or horizon is tried, and a solve that must still run (at the
    horizon found) gets :data:`~.budget.MIN_SOLVE_WORK`. The best plan found within
    the limits is returned, with its optimality gap. None disables a limit.

    **Safety stops** (wall clock) only guard against a machine far slower than
    expected: ``time_limit_s`` per solve (``probe_time_limit_s`` per probe) and
    ``total_time_limit_s`` per planning call. They are generous, and a result
    that one of them cut short may differ from run to run: every one that fires
    is counted (``meter``, :class:`~.meter.Meter`) and reported.
    """

    mip_gap: float | None = 0.01
    solver: str | None = None
    threads: int = 1
    workers: int = 2
    max_nodes: int | None = 500
    max_work: float | None = 300.0
    stall_work: float | None = 30.0
    probe_max_nodes: int | None = 100
    probe_max_work: float | None = 40.0
    search_max_rows: int | None = 30000
    total_work: int | None = 12000
    time_limit_s: float | None = 300.0
    probe_time_limit_s: float | None = 50.0
    total_time_limit_s: float | None = 100.0
    meter: "Meter | None" = field(default=None, compare=False, repr=False)


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
    it, so a solve stopped by its limits returns at least that plan.
    ``time_weight`` is a tiny cost per action and step index: of equally good plans
    the earliest wins, which lets a search solve once at a generous horizon and cut
    the plan after its last action. ``objective_bound`` is an upper bound on the
    objective known without solving (e.g. from shortest paths): a completed warm
    start within ``mip_gap`` of it is the answer, without a search.
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
    objective_bound: float | None = None

    def holding(self, r: str) -> set[str]:
        return set(self.holdings.get(r, {r}))
