"""delve.executive.worlds: backends claim worlds, and a new backend plugs in without
touching the runner."""
from pathlib import Path

import pytest

from delve.executive import worlds
from delve.executive.outputs import write_outputs
from delve.executive.runner import Mission
from delve.executive.scenario import load_scenario
from delve.executive.worlds import GraphBackend, VoxelBackend, backend_for, generator_names, register_world
from delve.sim.graph_world import GraphWorld

DATA = Path(__file__).parent.parent / "scenarios" / "data"


@pytest.mark.parametrize("world, backend", [
    ({"generator": "tunnel_network"}, VoxelBackend), ({"generator": "cave"}, VoxelBackend),
    ({"mesh": "m.ply"}, VoxelBackend), ({"generator": "tunnel_graph"}, GraphBackend),
    ({"network": "n.yaml"}, GraphBackend), ({"generator": "tunnel_netwrk"}, None)])
def test_the_backend_that_claims_a_world(world, backend):
    assert backend_for(world) is backend


def test_generator_names_cover_every_backend():
    assert {"tunnel_network", "cave", "tunnel_graph"} <= set(generator_names())


def two_forks(seed: int = 0) -> GraphWorld:
    """A base with two tunnels of two locations each; radio along each tunnel."""
    pos = {"b": (0, 0, 0), "l1": (0, 40, 0), "l2": (0, 80, 0), "r1": (40, 0, 0), "r2": (80, 0, 0)}
    tunnels = [("b", "l1"), ("l1", "l2"), ("b", "r1"), ("r1", "r2")]
    return GraphWorld(pos, tunnels, tunnels, "b")


class ForkBackend(GraphBackend):
    """A graph world with a generator of its own, registered by a test."""

    @classmethod
    def generators(cls):
        return {"two_forks": two_forks}


@pytest.fixture
def fork_backend():
    register_world("forks", ForkBackend)
    yield ForkBackend
    del worlds.WORLD_BACKENDS["forks"]


def test_a_registered_backend_runs_a_cops_mission_without_a_runner_change(fork_backend, tmp_path):
    scenario = tmp_path / "forks.yaml"
    scenario.write_text(f"""name: forks
seed: 1
duration_s: 3000
dt_s: 1.0
world: {{generator: two_forks}}
team: {{strategy: cops}}
base_station: {{tree: {DATA / 'cops_base_fast.yaml'}}}
robots:
  - {{name: a, platform: legged, tree: {DATA.parents[2] / 'trees' / 'cops_robot.yaml'}, tick_hz: 1.0}}
  - {{name: c, platform: legged, tree: {DATA.parents[2] / 'trees' / 'cops_robot.yaml'}, tick_hz: 1.0}}
""")
    sc = load_scenario(scenario, include_path=[DATA])
    assert sc.world_backend is ForkBackend
    mission = Mission(sc)
    mission.run()
    rep = write_outputs(mission, tmp_path / "out", 1.0)
    assert rep["succeeded"] and rep["locations"] == 5 and rep["locations_explored"] == 5
    assert rep["coverage_fraction"] == 1.0 and rep["base_coverage_fraction"] == 1.0
    assert all(r["returned_home"] for r in rep["robots"])
    assert (tmp_path / "out" / "map.png").stat().st_size > 0


def test_a_backend_refuses_what_it_cannot_do(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(f"""name: bad
world: {{generator: tunnel_graph, n_locations: 5}}
team: {{strategy: cops}}
base_station: {{tree: {DATA / 'cops_base_fast.yaml'}}}
radio: {{range_m: 50}}
robots:
  - {{name: a, platform: legged, tree: {DATA.parents[2] / 'trees' / 'cops_robot.yaml'}}}
""")
    from delve.executive.errors import DelveError
    with pytest.raises(DelveError, match="'range_m' does not apply to a graph world") as err:
        load_scenario(bad, include_path=[DATA])
    assert err.value.line == 5


def test_a_voxel_team_reports_the_share_it_observed_twice(tmp_path):
    """Two robots standing at one start see nearly the same tunnel: most of what the team
    observed, more than one robot observed. One robot alone has no overlap figure."""
    def figures(robots: str):
        scenario = tmp_path / "team.yaml"
        scenario.write_text(f"""name: team
seed: 3
duration_s: 4
world: {{generator: tunnel_network, total_length_m: 60, loops: 0}}
robots:
{robots}""")
        mission = Mission(load_scenario(scenario))
        mission.run()
        return mission.backend.figures(mission)

    tree = DATA.parents[2] / "trees" / "gbplanner_explorer.yaml"
    pair = figures(f"  - {{name: a, platform: legged, tree: {tree}}}\n  - {{name: b, platform: legged, tree: {tree}}}\n")
    assert 0.5 < pair["overlap_fraction"] <= 1.0
    assert "overlap_fraction" not in figures(f"  - {{name: a, platform: legged, tree: {tree}}}\n")
