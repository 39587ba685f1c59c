"""delve.executive.colours: one colour per robot, the same in every picture."""
import matplotlib.pyplot as plt
from delve.executive.colours import robot_colour


def test_robots_take_the_colour_cycle_in_order_and_wrap_around():
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    assert [robot_colour(i) for i in range(3)] == cycle[:3]
    assert robot_colour(len(cycle)) == cycle[0]
