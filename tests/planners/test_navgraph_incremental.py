import numpy as np
import pytest

from delve.planners.navgraph import NavGraph, aerial_graph, legged_graph
from delve.planners.navgraph_incremental import AerialGraphUpdater, LeggedGraphUpdater

from .recorded_mapping import grid_of, mine, sweeps, walk

LEGGED = dict(body_height_m=0.5, radius_m=0.4, max_step_m=0.3, max_inclination_deg=35.0)
#: Each graph: its updater and its full build.
KINDS = {"legged": (lambda: LeggedGraphUpdater(**LEGGED), lambda g: legged_graph(g, **LEGGED)),
         "aerial": (lambda: AerialGraphUpdater(radius_m=0.5), lambda g: aerial_graph(g, radius_m=0.5))}


def assert_same_graph(a: NavGraph, b: NavGraph) -> None:
    assert np.array_equal(a.positions, b.positions)
    assert a.adjacency.shape == b.adjacency.shape
    for part in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(a.adjacency, part), getattr(b.adjacency, part)), part


@pytest.mark.parametrize("kind", KINDS)
def test_updates_equal_the_full_build_after_every_sweep_of_a_recorded_run(kind):
    make, full = KINDS[kind]
    updater = make()
    sizes = []
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine()))):
        graph = updater.update(grid_of(m), None if i == 0 else changed)
        assert_same_graph(graph, full(grid_of(m)))
        sizes.append(len(graph))
    assert sizes[-1] > {"legged": 10, "aerial": 5}[kind] * sizes[0] > 0          # the graph grew along the run


@pytest.mark.parametrize("kind", KINDS)
def test_changes_gathered_over_several_sweeps_and_a_cleared_sphere_give_the_full_build(kind):
    make, full = KINDS[kind]
    updater = make()
    pending = []
    graph = None
    for i, (m, changed) in enumerate(sweeps(mine(), walk(mine())[:40])):
        pending.append(changed)
        if i == 25:   # a local map reset, as after a fault: the ball around the robot is unknown again
            centre = m.origin + (np.array(np.unravel_index(m.free_voxels()[-1], m.shape)) + 0.5) * m.voxel_size_m
            log = m.change_log()
            m.set_sphere(centre, 3.0, -1)
            pending.append(log.take())
        if i % 7 == 6 or i == 25:
            graph = updater.update(grid_of(m), np.unique(np.concatenate(pending)) if graph is not None else None)
            pending = []
            assert_same_graph(graph, full(grid_of(m)))


def test_an_update_without_changes_keeps_the_graph_and_its_edges():
    updater = LeggedGraphUpdater(**LEGGED)
    run = sweeps(mine(), walk(mine())[:12])
    for m, _ in run:
        pass
    first = updater.update(grid_of(m))
    edges = updater._edges[0].copy()
    graph = updater.update(grid_of(m), np.zeros(0, np.int64))
    assert_same_graph(graph, first)
    assert np.array_equal(updater._edges[0], edges)
