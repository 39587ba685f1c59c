"""A physical lower limit on exploration time: the shortest walk over a world's
centreline graph that brings a sensor within range of every passage.

A robot that explores a network of passages must pass along every passage, except
that it sees the last ``sensor_range_m`` of a dead end from where it stands: dead
ends are trimmed by the range (a branch shorter than the range is seen whole from
its junction). The shortest walk from the start that covers every remaining edge
is the open Chinese postman walk: the edges once, plus the cheapest set of
repeated paths that pairs up the odd-degree junctions (a minimum-weight perfect
matching on their shortest-path distances); the walk may end anywhere, which a
zero-cost partner of every junction models. A ``closed`` walk also returns to the
start (the mission's homing).

This is the limit issue 17 defines (a tour over the graph's edges and dead ends,
shortened by the sensor range): it ignores that a sensor also sees some way along
a passage and around a junction, and it assumes the top speed throughout, so it
is a bound the planners cannot beat by much and should approach.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Hashable

import networkx as nx
import numpy as np

#: The zero-cost partner in the matching that lets the walk end at any junction.
_END = ("__walk_end__",)


@dataclass(frozen=True)
class ExplorationBound:
    """The shortest covering walk: its length, the passages it covers once (after
    trimming dead ends by the sensor range), and the length it walks twice."""

    walk_m: float
    covered_m: float
    repeated_m: float
    closed: bool

    def time_s(self, speed_mps: float) -> float:
        """The walk's duration at a constant ``speed_mps``."""
        if not speed_mps > 0:
            raise ValueError(f"speed_mps must be > 0, got {speed_mps}")
        return self.walk_m / speed_mps


def edge_length(graph: nx.Graph, u: Hashable, v: Hashable, data: dict[str, Any]) -> float:
    """An edge's ``length_m``, else the distance between its nodes' ``pos``."""
    if "length_m" in data:
        return float(data["length_m"])
    return float(np.linalg.norm(np.asarray(graph.nodes[u]["pos"]) - np.asarray(graph.nodes[v]["pos"])))


def trimmed_graph(graph: nx.Graph, start: Hashable, sensor_range_m: float,
                  walkable: Callable[[dict[str, Any]], bool] = lambda data: True) -> nx.Graph:
    """The walkable part of ``graph`` connected to ``start``, with weights
    ``length_m``, and each dead end trimmed by ``sensor_range_m`` along its branch
    (edges seen whole are removed, and the trim goes on past a junction that
    becomes a dead end by it)."""
    if sensor_range_m < 0:
        raise ValueError(f"sensor_range_m must be >= 0, got {sensor_range_m}")
    g = nx.Graph()
    g.add_node(start)
    for u, v, data in graph.edges(data=True):
        if walkable(data) and u != v:
            g.add_edge(u, v, length_m=edge_length(graph, u, v, data))
    g = g.subgraph(nx.node_connected_component(g, start)).copy()
    # Dead ends in a fixed order (the nodes' order in the graph), for reproducibility.
    budget = {n: sensor_range_m for n in g.nodes if n != start and g.degree(n) == 1}
    while budget:
        leaf = next(iter(budget))
        left = budget.pop(leaf)
        if g.degree(leaf) != 1:
            continue
        (parent,) = g.neighbors(leaf)
        length = g.edges[leaf, parent]["length_m"]
        if length > left:
            g.edges[leaf, parent]["length_m"] = length - left
            continue
        g.remove_node(leaf)
        if parent != start and g.degree(parent) == 1:
            budget[parent] = max(budget.get(parent, 0.0), left - length)
    return g


def exploration_bound(graph: nx.Graph, start: Hashable, sensor_range_m: float, *, closed: bool = False,
                      walkable: Callable[[dict[str, Any]], bool] = lambda data: True) -> ExplorationBound:
    """The shortest walk from ``start`` over ``graph`` (nodes with ``pos``, edges
    with ``length_m``) that covers every walkable passage reachable from it, dead
    ends trimmed by ``sensor_range_m``; ``closed``: it ends back at ``start``."""
    g = trimmed_graph(graph, start, sensor_range_m, walkable)
    covered = sum(d["length_m"] for _, _, d in g.edges(data=True))
    odd = {n for n in g.nodes if g.degree(n) % 2 == 1}
    if not closed:
        odd ^= {start}  # the walk starts at ``start``: it may keep an odd degree ...
    pairs = nx.Graph()
    nodes = sorted(odd, key=list(g.nodes).index)
    for i, a in enumerate(nodes):
        dist = nx.single_source_dijkstra_path_length(g, a, weight="length_m")
        for b in nodes[i + 1:]:
            pairs.add_edge(a, b, weight=dist[b])
        if not closed:
            pairs.add_edge(a, _END, weight=0.0)  # ... and so may the end, anywhere.
    matching = nx.min_weight_matching(pairs, weight="weight")
    repeated = sum(pairs.edges[a, b]["weight"] for a, b in matching)
    return ExplorationBound(walk_m=covered + repeated, covered_m=covered, repeated_m=repeated, closed=closed)
