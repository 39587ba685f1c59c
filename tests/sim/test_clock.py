import pytest

from delve.sim.clock import SimClock


def test_clock_counts_steps_without_drift():
    c = SimClock(0.1)
    for _ in range(36000):
        c.step()
    assert c.now_s == 3600.0


def test_clock_rejects_bad_step():
    with pytest.raises(ValueError):
        SimClock(0.0)
