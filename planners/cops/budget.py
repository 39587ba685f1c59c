"""The limits of one planning call (``plan_cycle``, ``solve_pre_exploration``, ...),
shared out over its solves.

Results depend only on work, never on the wall clock: every solve is bounded by
branch-and-bound nodes and checkpoint work (:class:`SolveLimits`), and a call by
the simplex iterations of its solves (``SolverOptions.total_work``), which
decides how many probes of a horizon search are made. Seconds remain as safety
stops only (``time_limit_s``, ``total_time_limit_s``): when one fires, the
:class:`Meter` of the call (and of every call enclosing it) counts it, so that the
caller can report a result that may not be reproducible.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

from .ilp_problem import SolverOptions
from .meter import Meter

#: However little work is left, a solve that must run (the plan at the horizon found)
#: gets this much checkpoint work: presolve, the root LP and a round or two after it.
MIN_SOLVE_WORK = 3
#: However little of a safety stop is left, a solve gets this long (s).
MIN_SAFETY_S = 1.0
#: Share of a cycle's work budget given to pre-exploration (post-exploration gets the rest).
PRE_SHARE = 0.55


@dataclass(frozen=True)
class SolveLimits:
    """The limits of one solve: work (nodes, checkpoint work, stall, all deterministic)
    and a wall-clock safety stop (``time_limit_s``); see :class:`SolverOptions`."""

    max_nodes: int | None = None
    max_work: float | None = None
    stall_work: float | None = None
    time_limit_s: float | None = None
    max_rows: int | None = None

    @classmethod
    def of(cls, opts: SolverOptions, probe: bool = False) -> SolveLimits:
        """The limits ``opts`` give a solve (a feasibility probe: ``probe``)."""
        if probe:
            return cls(opts.probe_max_nodes, opts.probe_max_work, None, opts.probe_time_limit_s,
                       opts.search_max_rows)
        return cls(opts.max_nodes, opts.max_work, opts.stall_work, opts.time_limit_s, opts.search_max_rows)


class Budget:
    """The work left of ``options.total_work`` (simplex iterations) and the safety
    stop ``options.total_time_limit_s`` of one planning call. Its solves use
    :attr:`opts`, whose meter counts the call's work (and its parents' too)."""

    def __init__(self, opts: SolverOptions) -> None:
        self.meter = Meter(opts.meter)
        self.opts = replace(opts, meter=self.meter)
        self.total = opts.total_work
        total_s = opts.total_time_limit_s
        self.end = None if total_s is None else time.perf_counter() + total_s
        self._stopped = False

    def left(self) -> int | None:
        """Work left (simplex iterations); None without a budget."""
        return None if self.total is None else max(self.total - self.meter.work, 0)

    def spent(self, reserve: int = 0) -> bool:
        """Whether no more than ``reserve`` work is left, or the safety stop has passed
        (counted once as a safety stop): a search stops here."""
        left = self.left()
        if left is not None and left <= reserve:
            return True
        if self.end is not None and time.perf_counter() > self.end:
            if not self._stopped:
                self._stopped = True
                self.meter.add(safety_stop=f"planning call ran past its safety stop of "
                                          f"{self.opts.total_time_limit_s:g} s")
            return True
        return False

    def limits(self, probe: bool = False) -> SolveLimits:
        """Limits of the next solve: those of the options, with at most
        :data:`MIN_SOLVE_WORK` once the call's work is spent, and a safety stop cut to
        the call's time left (at least :data:`MIN_SAFETY_S`)."""
        lim = SolveLimits.of(self.opts, probe)
        left = self.left()
        if left is not None and left <= 0:
            w = lim.max_work
            lim = replace(lim, max_work=MIN_SOLVE_WORK if w is None else min(w, MIN_SOLVE_WORK))
        if self.end is not None:
            cut = max(self.end - time.perf_counter(), MIN_SAFETY_S)
            lim = replace(lim, time_limit_s=cut if lim.time_limit_s is None else min(lim.time_limit_s, cut))
        return lim

    def options(self, share: float = 1.0) -> SolverOptions:
        """Options for a sub-problem that may use ``share`` of the work left (and the
        time left of the safety stop); its work is counted here too."""
        left = self.left()
        total_s = None if self.end is None else max(self.end - time.perf_counter(), MIN_SAFETY_S)
        return replace(self.opts, total_work=None if left is None else int(left * share),
                       total_time_limit_s=total_s)
