"""The same scenario and seed give the same report, byte for byte, wall clock aside,
on a quiet machine and on a busy one."""
import json
import multiprocessing
import os
from pathlib import Path

import pytest
from delve import SCENARIOS_DIR
from delve.executive.outputs import strip_wall_clock

from .conftest import DATA, run_scenario


@pytest.fixture(scope="module")
def small_tunnel(tmp_path_factory) -> tuple[dict, Path]:
    """small_tunnel.yaml's report and output folder, run once for this module."""
    out = tmp_path_factory.mktemp("small_tunnel")
    return run_scenario(DATA / "small_tunnel.yaml", out)[1], out


def test_same_seed_same_report_and_log(small_tunnel, tmp_path):
    a, out = small_tunnel
    _, b = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "b")
    assert json.dumps(strip_wall_clock(a)) == json.dumps(strip_wall_clock(b))
    assert (out / "log.jsonl").read_bytes() == (tmp_path / "b" / "log.jsonl").read_bytes()


def test_another_seed_gives_another_run(small_tunnel, tmp_path):
    a, _ = small_tunnel
    _, c = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "c", seed=99)
    assert c["seed"] == 99
    assert strip_wall_clock(a) != strip_wall_clock(c)


def test_the_cerberus_stack_is_deterministic_too(tmp_path):
    """GBPlanner2's random graphs, the lossy radio and the supervisor script included."""
    _, a = run_scenario(SCENARIOS_DIR / "cerberus_modes.yaml", tmp_path / "a")
    _, b = run_scenario(SCENARIOS_DIR / "cerberus_modes.yaml", tmp_path / "b")
    assert strip_wall_clock(a) == strip_wall_clock(b)
    assert (tmp_path / "a" / "log.jsonl").read_bytes() == (tmp_path / "b" / "log.jsonl").read_bytes()


def _spin(stop) -> None:
    while not stop.is_set():
        pass


def _without_wall_clock(log: str) -> list[dict]:
    events = [json.loads(line) for line in log.splitlines()]
    for e in events:
        e.pop("solve_time_s", None)
    return events


def test_cops_plans_do_not_depend_on_the_machine_s_load(tmp_path):
    """cops_under_load's solves are large enough that the former wall-clock limits bound
    under load (its plans then differed from a quiet run's). Its limits are counted in
    work now: run once as the suite runs it (beside another test worker under `make
    test`), then with every core spinning, it gives the same report and log (solve times
    aside), and no safety stop fired."""
    _, quiet = run_scenario(DATA / "cops_under_load.yaml", tmp_path / "quiet")
    ctx = multiprocessing.get_context("spawn")
    stop = ctx.Event()
    spinners = [ctx.Process(target=_spin, args=(stop,), daemon=True) for _ in range(os.cpu_count() or 2)]
    for p in spinners:
        p.start()
    try:
        _, busy = run_scenario(DATA / "cops_under_load.yaml", tmp_path / "busy")
    finally:
        stop.set()
        for p in spinners:
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()
    assert quiet["cops"]["safety_stops"] == 0 and quiet["cops"]["reproducible"]
    assert quiet["cops"]["plans_valid"] == quiet["cops"]["cycles"] >= 4 and quiet["succeeded"]
    assert strip_wall_clock(busy) == strip_wall_clock(quiet)
    assert _without_wall_clock((tmp_path / "busy" / "log.jsonl").read_text()) == \
        _without_wall_clock((tmp_path / "quiet" / "log.jsonl").read_text())
