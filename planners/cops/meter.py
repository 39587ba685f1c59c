"""The work meter of a planning call: simplex iterations, solves and the safety
stops that fired, counted in the call's meter and in every enclosing one."""
from __future__ import annotations

import threading


class Meter:
    """Work done by the solves of a planning call (simplex iterations, solves) and the
    safety stops that fired, each also counted in the enclosing call's meter
    (``parent``). Thread-safe: clusters are solved at once."""

    def __init__(self, parent: Meter | None = None) -> None:
        self.parent = parent
        self.work = 0
        self.solves = 0
        self.safety_stops: list[str] = []
        self._lock = threading.Lock()

    def add(self, work: int = 0, solves: int = 0, safety_stop: str | None = None) -> None:
        m: Meter | None = self
        while m is not None:
            with m._lock:
                m.work += int(work)
                m.solves += solves
                if safety_stop:
                    m.safety_stops.append(safety_stop)
            m = m.parent

    def figures(self) -> dict:
        """``work``, ``solves`` and ``safety_stops`` (a count), for a plan's meta."""
        return {"work": self.work, "solves": self.solves, "safety_stops": len(self.safety_stops)}
