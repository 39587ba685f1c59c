"""delve.planners.cohort.reposition: the closest of the best n_C % clusters, its path
along G_C and the box D around it, on a hand-made G_C."""
import numpy as np
import pytest
from delve.planners.cohort import GlobalGraph, choose_frontier, exploration_box
from delve.planners.frontier import FrontierCluster

WORLD = (np.full(3, -50.0), np.full(3, 50.0))
BOX = (4.0, 4.0, 2.0)


def line_graph(n: int = 11) -> GlobalGraph:
    """Vertices 0..n-1 at x = 0..n-1 on a line, joined in order, and one lone vertex n."""
    g = GlobalGraph()
    g.positions = np.column_stack([np.arange(n + 1.0), np.zeros(n + 1), np.zeros(n + 1)])
    g.edge_u, g.edge_v = np.arange(n - 1), np.arange(1, n)
    g.edge_w = np.ones(n - 1)
    return g


def cluster(size: int, x: float) -> FrontierCluster:
    """A cluster of ``size`` points with its centroid 1 m off the line at ``x``."""
    return FrontierCluster(voxels=np.arange(size) + 1000 * int(x), centroid=np.array([x, 1.0, 0.0]))


#: sizes 100, 90, 80, 10 at x = 10, 5, 3, 1, each linked to the vertex beside it
CLUSTERS = [cluster(100, 10), cluster(90, 5), cluster(80, 3), cluster(10, 1)]
LINKS = [np.array([10]), np.array([5]), np.array([3]), np.array([1])]


def choose(share: float = 50.0, clusters=CLUSTERS, links=LINKS, other: int | None = None, **kw):
    """Choose for robot "r" at vertex 0 (home at vertex 10; robot "o" at vertex ``other``)."""
    entries = {"r": 0, "home": 10, **({} if other is None else {"o": other})}
    return choose_frontier(line_graph(), clusters, links, entries, "r", best_share_pct=share,
                           box_m=BOX, world_min=WORLD[0], world_max=WORLD[1], **kw)


@pytest.mark.parametrize("share, chosen", [(50.0, 1), (25.0, 0), (75.0, 2), (100.0, 3)])
def test_the_closest_of_the_best_share_by_size_is_chosen(share, chosen):
    r = choose(share)
    assert r.reason == "ok" and r.cluster == chosen
    assert r.cluster_size == CLUSTERS[chosen].size
    assert np.allclose(r.frontier, CLUSTERS[chosen].centroid)


def test_the_path_runs_along_the_graph_and_the_box_is_centred_on_the_frontier():
    r = choose(50.0)
    assert np.allclose(r.path, [[x, 0, 0] for x in range(6)])
    assert np.isclose(r.distance_m, 6.0)
    assert np.allclose((r.box_min + r.box_max) / 2, r.frontier)
    assert np.allclose(r.box_max - r.box_min, BOX)
    assert r.distances_m == pytest.approx({"r": 6.0, "home": 6.0})


def test_the_box_is_clipped_to_the_world():
    lo, hi = exploration_box(np.array([1.0, 0, 0]), (360, 360, 20), np.zeros(3), np.array([30.0, 20, 5]))
    assert np.allclose(lo, 0) and np.allclose(hi, [30, 20, 5])


def test_a_cluster_another_robot_holds_is_left_out_while_others_remain():
    assert choose(50.0, other=9, holders={1: {"o"}}).cluster == 2
    assert choose(50.0, other=9).cluster == 1


@pytest.mark.parametrize("other, chosen", [(9, 2), (2, None)])
def test_when_every_cluster_is_held_the_caller_gets_one_only_where_it_is_nearer_than_its_holder(other, chosen):
    """"o" at vertex 9 is nearer to the clusters at x = 10 and 5; at vertex 2, to all
    (a tie at x = 1 leaves the cluster to its holder)."""
    r = choose(50.0, other=other, holders={i: {"o"} for i in range(4)})
    assert r.cluster == chosen
    assert r.ok or (r.reason == "taken" and r.frontier is None and r.box_min is None)


def test_a_holder_the_hub_cannot_place_keeps_its_cluster():
    assert choose(100.0, holders={i: {"ghost"} for i in range(4)}).reason == "taken"


@pytest.mark.parametrize("other, free, chosen", [(9, {"o"}, 1), (9, set(), 0), (None, {"o"}, 0)])
def test_unheld_clusters_are_shared_with_the_free_robots_at_the_least_total_distance(other, free, chosen):
    """Alone, "r" gets the largest (x = 10, 11 m away). "o" free at x = 9 is 2 m from it:
    the two largest are shared, "o" takes x = 10 and "r" x = 5 (8 m in all against 16);
    "o" busy, or unplaced, changes nothing."""
    assert choose(25.0, other=other, free=free).cluster == chosen


@pytest.mark.parametrize("other, chosen", [(9, None), (None, 0)])
def test_a_caller_the_free_robots_leave_without_a_cluster_gets_none(other, chosen):
    r = choose(50.0, clusters=CLUSTERS[:1], links=LINKS[:1], other=other, free={"o"})
    assert r.cluster == chosen and r.reason == ("taken" if chosen is None else "ok")


def test_clusters_the_robot_cannot_reach_are_left_out():
    links = [np.array([11]), LINKS[1], LINKS[2], LINKS[3]]           # the biggest hangs off the lone vertex
    assert choose(25.0, links=links).cluster == 1
    r = choose(50.0, links=[np.array([11])] * 4)
    assert not r.ok and r.reason == "unreachable" and r.frontier is None


def test_nothing_to_give():
    assert choose(clusters=[], links=[]).reason == "no_frontier"
    r = choose_frontier(line_graph(), CLUSTERS, LINKS, {"r": None}, "r", best_share_pct=50.0, box_m=BOX,
                        world_min=WORLD[0], world_max=WORLD[1])
    assert r.reason == "no_graph" and r.path is None and r.box_min is None
