"""The time budget of one planning call (``SolverOptions.total_time_limit_s``), shared
out over its solves."""
from __future__ import annotations

import time
from dataclasses import replace

from .ilp_problem import SolverOptions

#: However little of ``total_time_limit_s`` is left, a solve gets at least this long.
MIN_SOLVE_TIME_S = 0.3
#: Share of a cycle's time budget given to pre-exploration (post-exploration gets the rest).
PRE_SHARE = 0.55


class Budget:
    """The time left of ``options.total_time_limit_s`` and the limit of the next solve."""

    def __init__(self, opts: SolverOptions) -> None:
        self.opts = opts
        total = opts.total_time_limit_s
        self.end = None if total is None else time.perf_counter() + total

    def left(self) -> float | None:
        return None if self.end is None else max(self.end - time.perf_counter(), 0.0)

    def limit(self, share: float = 1.0, probe: bool = False) -> float | None:
        """Time limit of the next solve: ``time_limit_s`` (``probe_time_limit_s``), cut to
        ``share`` of the time left (at least :data:`MIN_SOLVE_TIME_S`)."""
        lim = self.opts.probe_time_limit_s if probe else self.opts.time_limit_s
        left = self.left()
        if left is None:
            return lim
        cut = max(MIN_SOLVE_TIME_S, left * share)
        return cut if lim is None else min(lim, cut)

    def options(self, share: float = 1.0) -> SolverOptions:
        """Options for a sub-problem that may use ``share`` of the time left."""
        left = self.left()
        if left is None:
            return self.opts
        return replace(self.opts, total_time_limit_s=max(MIN_SOLVE_TIME_S, left * share))
