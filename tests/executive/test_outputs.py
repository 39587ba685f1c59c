"""delve.executive.outputs: the report's coverage milestones."""
from __future__ import annotations

import pytest
from delve.executive.outputs import coverage_reached_s
from delve.executive.runner import Sample


def samples(team: list[float], base: list[float]) -> list[Sample]:
    """One sample every 10 s from t = 0."""
    return [Sample(t=10.0 * i, team=tm, base=b, robots={}, positions={}, linked={})
            for i, (tm, b) in enumerate(zip(team, base))]


def test_the_first_time_a_coverage_is_reached_is_interpolated_between_samples():
    s = samples([0.0, 0.5, 0.95, 0.95], [0.0, 0.0, 0.2, 0.92])
    assert coverage_reached_s(s, 0.9) == pytest.approx(10.0 + 10.0 * 0.4 / 0.45, abs=1e-3)
    assert coverage_reached_s(s, 0.9, "base") == pytest.approx(20.0 + 10.0 * 0.7 / 0.72, abs=1e-3)


def test_a_coverage_never_reached_is_none_and_one_reached_at_once_its_first_sample():
    s = samples([0.95, 0.95], [0.1, 0.3])
    assert coverage_reached_s(s, 0.9) == 0.0
    assert coverage_reached_s(s, 0.9, "base") is None
