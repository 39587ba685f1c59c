"""Shared helpers for scenario tests: run a scenario file to the end. Every test here
is marked ``slow`` (``pytest -m "not slow"`` leaves them out)."""
from pathlib import Path

import pytest

from delve.executive.outputs import write_outputs
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario

DATA = Path(__file__).parent / "data"


def run_scenario(path: Path, out: Path | None = None, *, endurance_s: dict[str, float] | None = None,
                 **kw) -> tuple[Mission, dict]:
    """Run a scenario, its robots' endurances replaced by ``endurance_s`` (by robot name) to
    keep a test short; write its outputs into ``out`` when given. Returns the mission and report."""
    scenario = load_scenario(path)
    assert set(endurance_s or ()) <= {r.name for r in scenario.robots}, "endurance_s names an unknown robot"
    for robot in scenario.robots:
        robot.endurance_s = (endurance_s or {}).get(robot.name, robot.endurance_s)
    mission = Mission(scenario, **kw)
    mission.run()
    report = write_outputs(mission, out, 1.0) if out is not None else None
    return mission, report


@pytest.fixture(scope="session")
def data_dir() -> Path:
    return DATA


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark every scenario test ``slow`` (a hook in this conftest sees every collected
    test, so it marks only those under this folder)."""
    here = Path(__file__).parent
    for item in items:
        if here in item.path.parents:
            item.add_marker(pytest.mark.slow)
