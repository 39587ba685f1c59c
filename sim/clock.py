"""The simulation clock: a fixed step, advanced only by the runner."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class SimClock:
    """Sim time in seconds; ``step()`` advances it by ``dt_s``.

    Time is kept as an integer step count so that it never drifts with float sums.
    """

    dt_s: float
    steps: int = 0

    def __post_init__(self) -> None:
        if not self.dt_s > 0:
            raise ValueError(f"dt_s must be > 0, got {self.dt_s}")

    @property
    def now_s(self) -> float:
        return round(self.steps * self.dt_s, 9)

    def step(self) -> float:
        self.steps += 1
        return self.now_s
