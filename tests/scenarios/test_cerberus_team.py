"""A legged and an aerial robot with the CERBERUS trees on two levels joined by a
ramp beyond the legged limit and a vertical shaft."""
import numpy as np
from delve import SCENARIOS_DIR

from .conftest import run_scenario
from .test_cerberus import ends_well


def test_legged_robot_refuses_the_steep_ramp_while_the_aerial_robot_flies_the_shaft():
    # The ANYmal is at the ramp's foot at about 100 s, the aerial robot above the upper
    # floor at about 130 s: short endurances keep the test short.
    mission, _ = run_scenario(SCENARIOS_DIR / "cerberus_slopes_shaft.yaml",
                              endurance_s={"anymal": 300, "obelix": 260})
    g = mission.world.centreline
    upper_floor = min(float(g.nodes[n]["pos"][2]) for n in g.nodes if g.nodes[n].get("level") == 1)
    (ramp,) = [(u, v) for u, v, d in g.edges(data=True) if d.get("kind") == "ramp"]
    foot = min((np.asarray(g.nodes[n]["pos"], float) for n in ramp), key=lambda p: p[2])
    legged = np.asarray(mission.robots["anymal"].traversed_path, float)
    assert np.linalg.norm(legged - foot, axis=1).min() < 3.0   # it came to the ramp ...
    legged_top = legged[:, 2].max()                            # ... and did not climb it
    aerial_top = max(p[2] for p in mission.robots["obelix"].traversed_path)
    assert legged_top < upper_floor - 2.0
    assert aerial_top > upper_floor
    ends_well(mission)
