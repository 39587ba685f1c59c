"""Each robot's colour in every picture of a run (map.png, coverage.png, ...): the
matplotlib colour cycle's, in the scenario's order of robots."""
from __future__ import annotations

import matplotlib.pyplot as plt


def robot_colour(i: int) -> str:
    """The colour of the scenario's ``i``-th robot (from 0)."""
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    return colours[i % len(colours)]
