import json

from delve.planners.cops import Communication, CyclePlan, ExplorationTask, Plan, Requirement


def sample():
    return Plan(horizon=2,
                trajectories={"r2": ["s1", "s1", "s1"], "base": ["s0", "s0", "s0"], "r1": ["s0", "s1", "s2"]},
                communications=[Communication(0, "base", "r1", "m"), Communication(1, "r1", "r2", "m"),
                                Communication(1, "r2", "r1", "r2")],
                masters=["base"], requirements=[Requirement(("r2",), ("base",))],
                explore={"r1": "s2"}, phase="pre", meta={"solver": "highs", "cost": 2.0})


def test_json_round_trip_is_deterministic():
    p = sample()
    text = p.to_json()
    assert Plan.from_json(text).to_json() == text
    d = json.loads(text)
    assert list(d) == sorted(d)
    assert d["communications"][0] == [0, "base", "r1", "m"]
    assert list(d["trajectories"]) == ["base", "r1", "r2"]


def test_steps_phases_and_frontier_indices():
    p = sample()
    steps = p.steps("r1")
    assert [s.action for s in steps] == ["move", "move", "explore"]
    assert steps[1].sends == (Communication(1, "r1", "r2", "m"),)
    assert p.frontier_assignment() == {"s2": ["r1"]} and p.exploration_index("r1") == 0
    assert p.moves("r1") == 2 and p.master_receivers() == {"base", "r1", "r2"}
    ph = p.communication_phases(1, "r1")
    assert len(ph["PreIntCom"]) + len(ph["PostIntCom"]) == 2 and ph["ExtCom"] == []
    ph0 = p.communication_phases(0, "r1")
    assert ph0["PreIntCom"] == [Communication(0, "base", "r1", "m")] or ph0["PostIntCom"]


def test_cycle_plan_round_trip():
    c = CyclePlan(sample(), sample(), {"r1": ExplorationTask("s2", 0, 2, 5, 0)}, meta={"clustered": False})
    assert CyclePlan.from_json(c.to_json()).to_json() == c.to_json()
