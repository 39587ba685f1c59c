"""The same scenario and seed give the same report, byte for byte, wall clock aside."""
import json

from delve import SCENARIOS_DIR
from delve.executive.outputs import strip_wall_clock

from .conftest import DATA, run_scenario


def test_same_seed_same_report_and_log(tmp_path):
    _, a = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "a")
    _, b = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "b")
    assert json.dumps(strip_wall_clock(a)) == json.dumps(strip_wall_clock(b))
    assert (tmp_path / "a" / "log.jsonl").read_bytes() == (tmp_path / "b" / "log.jsonl").read_bytes()


def test_another_seed_gives_another_run(tmp_path):
    _, a = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "a")
    _, c = run_scenario(DATA / "small_tunnel.yaml", tmp_path / "c", seed=99)
    assert c["seed"] == 99
    assert strip_wall_clock(a) != strip_wall_clock(c)


def test_the_cerberus_stack_is_deterministic_too(tmp_path):
    """GBPlanner2's random graphs, the lossy radio and the supervisor script included."""
    _, a = run_scenario(SCENARIOS_DIR / "cerberus_modes.yaml", tmp_path / "a")
    _, b = run_scenario(SCENARIOS_DIR / "cerberus_modes.yaml", tmp_path / "b")
    assert strip_wall_clock(a) == strip_wall_clock(b)
    assert (tmp_path / "a" / "log.jsonl").read_bytes() == (tmp_path / "b" / "log.jsonl").read_bytes()
