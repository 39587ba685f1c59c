"""Frontier rewards R(s, k) for k robots exploring one frontier, with diminishing returns."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class FrontierReward:
    """R(s, k) for k robots at a frontier, with diminishing returns.

    The default is geometric: the k-th robot adds ``first * ratio**(k-1)``, so
    R(k+1) − R(k) < R(k) − R(k−1), i.e. R(k+1) < 2R(k) − R(k−1). ``table`` gives
    R(1), R(2), ... explicitly instead (it must be strictly concave with R(0) = 0).
    """

    first: float = 50.0
    ratio: float = 0.5
    table: tuple[float, ...] | None = None

    def marginals(self, k_max: int) -> tuple[float, ...]:
        """R(s, k) − R(s, k − 1) for k = 1..k_max."""
        if self.table is not None:
            vals = (0.0,) + tuple(float(v) for v in self.table)
            marg = tuple(vals[k] - vals[k - 1] for k in range(1, len(vals)))
            for k in range(1, len(marg)):
                if not marg[k] < marg[k - 1]:
                    raise ValueError(f"frontier reward table {list(self.table)} has no diminishing returns "
                                     f"at k={k + 1}: R(k+1) must be < 2R(k) - R(k-1)")
            return tuple(m for m in marg[:k_max] if m > 0)
        if not 0 < self.ratio < 1 or self.first <= 0:
            raise ValueError("frontier reward needs first > 0 and 0 < ratio < 1 (diminishing returns)")
        return tuple(self.first * self.ratio ** k for k in range(k_max))

    def value(self, k: int) -> float:
        return sum(self.marginals(k))
