"""A small graph world and a robot on it, for the graph world's tests."""
import numpy as np

from delve.sim.graph_radio import GraphRadioNetwork, GraphRadioSpec
from delve.sim.graph_robot import GraphRobot
from delve.sim.graph_world import GraphWorld
from delve.sim.platforms import LEGGED


def world() -> GraphWorld:
    """a - b - c with d off b; the radio reaches only between a and b."""
    pos = {"a": (0, 0, 0), "b": (50, 0, 0), "c": (100, 0, 0), "d": (50, 50, 0)}
    return GraphWorld(pos, [("a", "b"), ("b", "c"), ("b", "d")], [("a", "b")], "a")


def robot(w: GraphWorld, name: str = "r", loss: float = 0.0, seed: int = 0, endurance_s: float | None = None):
    """A legged robot at the world's start, its radio network and the network's clock."""
    clock = {"t": 0.0}
    net = GraphRadioNetwork(GraphRadioSpec(loss=loss), w, np.random.default_rng(seed), lambda: clock["t"])
    holder = {}
    r = GraphRobot(name, LEGGED, w, w.start, net.add(name, lambda: holder["r"].position), endurance_s)
    holder["r"] = r
    return r, net, clock
