"""delve.planners.cohort.hub: submaps in, global frontiers, answers, on the fork."""
import numpy as np
from delve.planners.cohort import CohortHub, CohortParams

from .worlds import Z, base_map, cut, fork

#: A tunnel's end face is about 80 points at 0.4 m: small f_min for the hand-made fork.
PARAMS = CohortParams(f_min=20)


def hub_after(*submaps):
    """A hub fed ``(robot, index, x_lo, x_hi, trajectory)`` submaps of the fork."""
    truth = fork()
    m, fine = base_map(truth)
    hub = CohortHub(PARAMS, fine)
    for robot, index, lo, hi, traj in submaps:
        flat, values = cut(truth, lo, hi)
        m.merge(flat, values)
        hub.add_submap(fine, robot, index, 0.0, flat, values, np.array(traj, float))
    return hub, fine


TRUNK = ("a", 0, 0, 20, [[3, 20, Z], [18, 20, Z]])
JUNCTION = ("b", 0, 15, 40, [[18, 20, Z], [30, 20, Z]])


def test_a_submap_updates_the_map_graph_and_frontiers():
    hub, _ = hub_after(TRUNK)
    info = hub.submaps[("a", 0)]
    assert hub.stale and info.frontier_points > 50 and info.vertices == len(hub.graph) > 200
    assert np.allclose(hub.home, [3, 20, Z]) and np.allclose(hub.robot_positions["a"], [18, 20, Z])
    assert info.bbox_max[0] <= 20.0 + 1e-9
    hub.update_frontiers()
    assert not hub.stale and len(hub.clusters) == 1 and len(hub.links[0])
    assert np.allclose(hub.frontier_centroids[:, :2], [[20.2, 20]], atol=0.3)


def test_two_robots_at_the_fork_are_sent_to_different_branches():
    hub, fine = hub_after(TRUNK, JUNCTION)
    ra = hub.reposition(fine, "a", np.array([30, 20, Z]), 10.0, request_id=1)
    rb = hub.reposition(fine, "b", np.array([30, 20, Z]), 10.0, request_id=7)
    assert ra.ok and rb.ok and ra.frontier[0] > 39 and rb.frontier[0] > 39
    assert (ra.frontier[1] - 20) * (rb.frontier[1] - 20) < 0
    assert np.linalg.norm(ra.path[-1] - ra.frontier) <= PARAMS.edge_radius_m + 1e-9
    assert [(a.robot, a.request_id) for a in hub.assignments] == [("a", 1), ("b", 7)]
    assert hub.last_assignment["b"].result is rb


def test_an_assignment_holds_its_cluster_for_t_c_plus_t_c_e():
    hub, fine = hub_after(TRUNK, JUNCTION)
    at = np.array([30, 20, Z])
    ra = hub.reposition(fine, "a", at, 10.0)
    held = 10.0 + PARAMS.period_s + PARAMS.extra_explore_s
    assert hub.reposition(fine, "b", at, held).cluster != ra.cluster
    assert hub.reposition(fine, "b", at, held + 1.0).cluster == ra.cluster


def test_no_frontier_before_any_submap():
    truth = fork()
    _, fine = base_map(truth)
    r = CohortHub(PARAMS, fine, home=np.array([3, 20, Z])).reposition(fine, "a", np.array([3, 20, Z]), 0.0)
    assert r.reason == "no_frontier" and r.frontier is None


def test_a_closed_common_map_is_explored_and_one_with_small_frontiers_is_not():
    whole = ("a", 0, 0, 60, [[3, 20, Z], [30, 20, Z], [38, 30, Z], [38, 10, Z]])   # every dead end seen
    hub, fine = hub_after(whole)
    r = hub.reposition(fine, "a", np.array([30, 20, Z]), 10.0)
    assert hub.explored and r.reason == "explored" and r.frontier is None
    hub, fine = hub_after(TRUNK)
    hub.frontiers.points.clear()   # a frontier lost to the hub's filters: the map itself is still open
    assert not hub.explored and hub.reposition(fine, "a", np.array([18, 20, Z]), 10.0).reason == "no_frontier"
    big = CohortParams(f_min=10_000)   # the trunk's end face stays open, under f_min
    hub, fine = hub_after(TRUNK)
    hub.params = big
    r = hub.reposition(fine, "a", np.array([18, 20, Z]), 10.0)
    assert not hub.explored and r.reason == "no_frontier"


def test_the_same_submaps_give_the_same_answers():
    answers = []
    for _ in range(2):
        hub, fine = hub_after(TRUNK, JUNCTION)
        r = hub.reposition(fine, "a", np.array([25, 20, Z]), 10.0)
        answers.append((r.frontier.tolist(), r.path.tolist(), hub.graph.positions.tolist()))
    assert answers[0] == answers[1]


def test_clusters_held_by_others_and_free_robots_heard_from_lately_reach_the_choice(monkeypatch):
    """The hub passes choose_frontier, per cluster, the other robots whose latest
    assignment holds it, and as free the others it heard from within T_C + T_C^e."""
    import delve.planners.cohort.hub as hub_module

    hub, fine = hub_after(TRUNK, JUNCTION)   # "a" and "b" heard from at t = 0
    at = np.array([30, 20, Z])
    ra = hub.reposition(fine, "a", at, 10.0)
    seen = {}
    real = hub_module.choose_frontier

    def spy(*args, **kw):
        seen.update(kw)
        return real(*args, **kw)

    monkeypatch.setattr(hub_module, "choose_frontier", spy)
    hub.reposition(fine, "c", at, 20.0)
    assert seen["holders"] == {ra.cluster: {"a"}} and seen["free"] == ["b"]
    hold = PARAMS.period_s + PARAMS.extra_explore_s
    hub.reposition(fine, "c", at, hold + 1.0)   # "b" silent since t = 0; "a" still holds
    assert seen["holders"] == {ra.cluster: {"a"}} and seen["free"] == []


def test_a_robot_just_answered_without_a_frontier_is_not_waiting_for_one(monkeypatch):
    """Two robots call in turn for the trunk's one frontier, each nearer to it than the
    other where the hub last placed it: the first is told none (the second, placed by
    its submap, is nearer); the second, calling from farther back, then gets it rather
    than leaving it to the first, which explores on its own until its next call, T_C
    later (from then on it counts as free again)."""
    import delve.planners.cohort.hub as hub_module

    hub, fine = hub_after(TRUNK, ("b", 0, 0, 10, [[3, 20, Z], [19, 20, Z]]))
    hub.update_frontiers()
    assert len(hub.clusters) == 1
    ra = hub.reposition(fine, "a", np.array([10, 20, Z]), 10.0)
    rb = hub.reposition(fine, "b", np.array([4, 20, Z]), 11.0)
    assert ra.reason == "taken" and rb.ok
    seen = {}
    real = hub_module.choose_frontier
    monkeypatch.setattr(hub_module, "choose_frontier", lambda *a, **kw: seen.update(kw) or real(*a, **kw))
    hub.reposition(fine, "c", np.array([4, 20, Z]), 10.0 + PARAMS.period_s - 1.0)
    assert seen["free"] == []
    hub.reposition(fine, "c", np.array([4, 20, Z]), 10.0 + PARAMS.period_s + 1.0)
    assert seen["free"] == ["a"]
