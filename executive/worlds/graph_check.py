"""A graph world looked at before a run (``delve world``): its locations, tunnels and
radio edges, whether they hang together, and the location each robot starts at."""
from __future__ import annotations

from typing import TYPE_CHECKING

import networkx as nx
import numpy as np

from ...sim.graph_world import GraphWorld
from ...skills.base import short_repr
from ..errors import DelveError
from .base import WorldDescription

if TYPE_CHECKING:
    from ..scenario import Scenario


def describe_graph_world(scenario: "Scenario", world: GraphWorld) -> WorldDescription:
    """Locations, tunnels (their total length), radio edges, the extent, each robot's
    start location; a warning when the tunnels fall apart into several parts."""
    g = world.graph
    xyz = np.array([world.pos(n) for n in g.nodes])
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    parts = sorted(nx.connected_components(g), key=len, reverse=True)
    length = sum(d["length_m"] for _, _, d in g.edges(data=True))
    out = WorldDescription(lines=[
        f"world {scenario.name}: a graph of {len(world)} locations, {g.number_of_edges()} tunnels "
        f"({length:.0f} m), {len(world.communication)} radio edges; base location {world.base!r}",
        f"  {'extent':<9} x {lo[0]:.1f} … {hi[0]:.1f}, y {lo[1]:.1f} … {hi[1]:.1f}, z {lo[2]:.1f} … {hi[2]:.1f} m",
        f"  {'parts':<9} {len(parts)} (the largest holds {len(parts[0])} of {len(world)} locations)"])
    where = scenario.doc["world"]
    if len(parts) > 1:
        out.warnings.append(str(DelveError(f"the tunnels fall apart into {len(parts)} parts (the largest "
                                           f"{len(parts[0])} of {len(world)} locations): robots reach only the "
                                           f"part they start in", scenario.path, where.line)))
    for i, spec in enumerate(scenario.robots):
        start = spec.start if spec.start is not None else world.start
        problem = world.start_problem(start)
        label = "start" if i == 0 else ""
        if problem:
            out.lines.append(f"  {label:<9} {spec.name} ({spec.platform}): {list(start)} is {problem}")
            out.errors.append(DelveError(f"robot {short_repr(spec.name)}: start pose {spec.start} is {problem}",
                                         scenario.path, spec.start_line))
            continue
        out.lines.append(f"  {label:<9} {spec.name} ({spec.platform}): at location "
                         f"{world.location_at(start)!r}")
        out.starts[spec.name] = [round(float(c), 3) for c in start]
    return out
