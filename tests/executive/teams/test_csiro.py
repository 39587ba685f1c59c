"""delve.executive.teams.csiro: what map.png shows of a CSIRO run (the frontiers current at the end,
a mean off free space at its observer, the failed goals, the topometric map's trajectory edges)."""
from __future__ import annotations

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from delve.executive.teams.csiro import Csiro, failed_goals  # noqa: E402
from delve.planners.csiro.frontier_types import Frontier  # noqa: E402
from delve.planners.csiro.observer import Observer  # noqa: E402
from delve.planners.csiro.sharing import summarise  # noqa: E402
from delve.skills.csiro import STATE_SERVICE, csiro_state  # noqa: E402


def frontier(fid: int, mean) -> Frontier:
    mean = np.asarray(mean, float)
    return Frontier(id=fid, points=mean[None], normals=np.array([[1.0, 0, 0]]), areas=np.ones(1), mean=mean,
                    cov=np.eye(3))


def robot_state(name: str, frontiers: list[Frontier], observers: dict[int, list[float]]):
    st = csiro_state(SimpleNamespace(services={}))
    st.frontiers._frontiers = {f.id: f for f in frontiers}
    for f in frontiers:
        if f.id in observers:
            observer = Observer(np.array(observers[f.id], float), 1.0, 0)
            st.summaries[(name, f.id)] = summarise(f, name, observer, 0.0)
    for k in range(4):                                                 # a trajectory along x ...
        st.topometric.add_pose(name, float(k), [3.0 * k, 0.0, 0.5])
    st.topometric.connect((name, 0), (name, 3))                        # ... and one observer-planning edge
    return st


def drawn(states: dict, aerial: dict, events: list) -> dict[str, np.ndarray]:
    """The map's lines by label: their points (N, 2)."""
    free = lambda p: np.abs(np.asarray(p)[:, 1]) < 2.0                 # a drift along x, 4 m wide
    robots = {n: SimpleNamespace(mobility=SimpleNamespace(aerial=aerial[n])) for n in states}
    mission = SimpleNamespace(robots=robots,
                              agents={n: SimpleNamespace(ctx=SimpleNamespace(services={STATE_SERVICE: st}))
                                      for n, st in states.items()},
                              state=SimpleNamespace(events=events), world=SimpleNamespace(is_free=free))
    fig, ax = plt.subplots()
    Csiro().draw(ax, mission)
    out = {line.get_label(): np.column_stack([line.get_xdata(), line.get_ydata()]) for line in ax.get_lines()}
    plt.close(fig)
    return out


def test_the_map_draws_the_frontiers_at_the_end_and_a_mean_off_free_space_at_its_observer():
    ugv = robot_state("ugv", [frontier(0, [8.0, 0.5, 1.0]), frontier(1, [4.0, 5.0, 2.5])],
                      {0: [6.0, 0.0, 0.0], 1: [4.0, 1.0, 0.0]})
    uav = robot_state("uav", [frontier(0, [2.0, -1.0, 1.0]), frontier(1, [2.0, -6.0, 1.0])], {})
    lines = drawn({"ugv": ugv, "uav": uav}, {"ugv": False, "uav": True}, [])
    means = lines["frontiers at the end, at their means (2)"]
    assert sorted(means.tolist()) == [[2.0, -1.0], [8.0, 0.5]]
    off = [v for k, v in lines.items() if k.startswith("frontiers at the end, mean off free space")]
    assert len(off) == 1 and off[0].tolist() == [[4.0, 1.0]]                 # the ugv's, at its observer
    (label,) = [k for k in lines if k.startswith("frontiers at the end, mean off")]
    assert label.endswith("(1; 1 without one not drawn)")
    edges = lines["topometric map (2 observer-planning edges not drawn)"]
    assert np.isnan(edges[:, 0]).sum() == 6                                 # 3 edges along each trajectory


def test_failed_goals_are_drawn_where_the_goal_was():
    events = [{"event": "csiro_goal_selected", "agent": "ugv", "goal": [5.0, 1.0, 0.5]},
              {"event": "csiro_goal_done", "agent": "ugv"},
              {"event": "csiro_goal_selected", "agent": "ugv", "goal": [9.0, 1.0, 0.5]},
              {"event": "csiro_goal_failed", "agent": "ugv"}]
    assert failed_goals(events) == [[9.0, 1.0, 0.5]]
    lines = drawn({"ugv": robot_state("ugv", [], {})}, {"ugv": False}, events)
    assert lines["frontier goals that failed (1)"].tolist() == [[9.0, 1.0]]
