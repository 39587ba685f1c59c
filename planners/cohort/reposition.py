"""COHORT's re-positioning (Kulkarni et al. 2022, section IV-B): where a robot that
calls the hub should explore next.

Dijkstra on G_C from every robot and from home; the frontier clusters (re-clustered
in the global frame) are sorted by size and the best n_C % kept; of those, the one
closest to the calling robot along G_C is its target, with the path to it along G_C
and a fixed-size box D around it as GBPlanner2's new exploration volume.

Choices where the paper is silent:

* A cluster is reached through the G_C vertices linked to it; its distance from a
  source is the least, over those vertices, of the path length to the vertex plus the
  straight line from it to the cluster's centroid. Clusters the calling robot cannot
  reach on G_C are left out before the best n_C % are taken.
* What the distances from every robot are for (the paper computes them, then names
  only the caller's): a cluster another robot was sent to (``holders``: the hub passes,
  per cluster, the other robots whose latest assignment still holds it) is left out,
  so two robots asking from the same place are not sent to one frontier. The unheld
  clusters are shared between the caller and the other robots that hold none
  (``free``), as a minimum-distance assignment (scipy ``linear_sum_assignment``) of
  those robots to the best n_C % of them by size (at least one each while there are
  enough clusters); the caller gets the cluster the assignment gives it, which is the
  closest of the best n_C % when no other robot is free. A caller the assignment
  leaves without one, because free robots nearer to every cluster take them all, gets
  a held cluster only where it is nearer than every robot holding it; else no
  frontier (reason ``taken``): it explores on with its own GBPlanner2 rather than
  fly across the world to a frontier a teammate reaches first. The distances from
  every robot and home to the chosen cluster come with the answer (``distances_m``)
  and are logged.
* The box is centred on the centroid and clipped to the world (a box of 360 m in a
  smaller world is the world).
"""
from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.sparse.csgraph import dijkstra

from ..frontier import FrontierCluster
from .global_graph import GlobalGraph


@dataclass(frozen=True)
class Reposition:
    """The hub's answer: the chosen cluster (index into the clusters, None when there is
    none), its centroid ``frontier``, the ``path`` along G_C (from the calling robot's
    entry vertex to the cluster's linked vertex), the box, the cluster's size, the
    path ``distance_m`` and ``reason`` ("ok", "no_frontier", "no_graph",
    "unreachable", "taken"; the hub answers "explored" itself, see
    :attr:`CohortHub.explored`). ``distances_m``: from each source (robot names, "home") to the
    chosen cluster."""

    cluster: int | None
    frontier: np.ndarray | None = None
    path: np.ndarray | None = None
    box_min: np.ndarray | None = None
    box_max: np.ndarray | None = None
    cluster_size: int = 0
    distance_m: float = math.inf
    reason: str = "ok"
    distances_m: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.cluster is not None


def exploration_box(centre: np.ndarray, box_m: tuple[float, float, float], world_min: np.ndarray,
                    world_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The box D of size ``box_m`` centred on ``centre``, clipped to the world's corners."""
    half = 0.5 * np.asarray(box_m, float)
    centre = np.asarray(centre, float)
    return np.maximum(centre - half, world_min), np.minimum(centre + half, world_max)


def cluster_distances(graph: GlobalGraph, clusters: list[FrontierCluster], links: list[np.ndarray],
                      dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each cluster: the least distance from a source (``dist``: distances of every
    vertex from it) through its linked vertices plus the straight offset to its centroid
    (inf when unreachable), and the vertex that gives it (-1 when none)."""
    best = np.full(len(clusters), math.inf)
    via = np.full(len(clusters), -1, dtype=np.int64)
    for i, (c, vs) in enumerate(zip(clusters, links)):
        if len(vs) == 0:
            continue
        cost = dist[vs] + np.linalg.norm(graph.positions[vs] - c.centroid, axis=1)
        k = int(np.argmin(cost))
        if np.isfinite(cost[k]):
            best[i], via[i] = cost[k], vs[k]
    return best, via


def best_share(sizes: np.ndarray, candidates: np.ndarray, share_pct: float) -> np.ndarray:
    """The best ``share_pct`` % of ``candidates`` (indices) by size, at least one,
    largest first (ties: lower index first)."""
    order = candidates[np.lexsort((candidates, -sizes[candidates]))]
    return order[: max(1, math.ceil(len(order) * share_pct / 100.0))]


def graph_path(pred: np.ndarray, positions: np.ndarray, target: int) -> np.ndarray:
    """(N, 3) positions from the source of the predecessor row ``pred`` to ``target``."""
    nodes = [target]
    while pred[nodes[-1]] >= 0:
        nodes.append(int(pred[nodes[-1]]))
    return positions[nodes[::-1]]


def assign_unheld(cost: np.ndarray, rival_costs: list[np.ndarray], unheld: np.ndarray, sizes: np.ndarray,
                  share_pct: float) -> int | None:
    """The unheld cluster the caller gets when the best ``share_pct`` % of ``unheld`` by
    size (at least one per robot while there are enough) are shared among it and its
    free rivals at the least total distance (``cost``: the caller's per cluster;
    ``rival_costs``: each free rival's). None when the caller gets none."""
    if len(unheld) == 0:
        return None
    top = best_share(sizes, unheld, share_pct)
    if len(top) <= len(rival_costs):
        top = best_share(sizes, unheld, 100.0)[: len(rival_costs) + 1]
    table = np.array([cost[top], *(c[top] for c in rival_costs)])
    finite = np.isfinite(table)
    big = 1.0 + 2.0 * (np.abs(table[finite]).sum() if finite.any() else 0.0)
    rows, cols = linear_sum_assignment(np.where(finite, table, big))
    mine = cols[rows == 0]
    if len(mine) == 0 or not np.isfinite(table[0, mine[0]]):
        return None
    return int(top[mine[0]])


def held_by_farther(cost: np.ndarray, reachable: np.ndarray, holder_costs: Mapping[int, list[np.ndarray]]
                    ) -> np.ndarray:
    """The held clusters of ``reachable`` the caller is nearer to than every robot
    holding them (``holder_costs``: per held cluster, each holder's cost per cluster;
    an empty array stands for a holder the hub cannot place, which keeps its cluster)."""
    return np.array([i for i in reachable if int(i) in holder_costs
                     and all(len(c) and cost[i] < c[i] for c in holder_costs[int(i)])], dtype=np.int64)


def choose_frontier(graph: GlobalGraph, clusters: list[FrontierCluster], links: list[np.ndarray],
                    entries: dict[str, int | None], robot: str, *, best_share_pct: float,
                    box_m: tuple[float, float, float], world_min: np.ndarray, world_max: np.ndarray,
                    holders: Mapping[int, Collection[str]] | None = None,
                    free: Collection[str] = ()) -> Reposition:
    """Re-position ``robot``: the unheld cluster it gets in the assignment of
    :func:`assign_unheld`, else the closest of the best ``best_share_pct`` % of the held
    clusters it is nearer to than their holders (:func:`held_by_farther`), else none.

    ``entries``: the G_C vertex of every source (robot names and "home"; None when it
    has none), ``robot`` among them; ``links``: each cluster's linked vertices
    (:meth:`GlobalGraph.link_frontiers`); ``holders``: per cluster, the other robots
    whose latest assignment still holds it; ``free``: the other robots holding none.
    """
    if not clusters:
        return Reposition(None, reason="no_frontier")
    if entries.get(robot) is None:
        return Reposition(None, reason="no_graph")
    names = sorted((n for n, v in entries.items() if v is not None), key=lambda n: (n != robot, n))
    dist, pred = dijkstra(graph.adjacency(), directed=False, indices=[entries[n] for n in names],
                          return_predecessors=True)
    cost, via = cluster_distances(graph, clusters, links, dist[0])
    reachable = np.flatnonzero(np.isfinite(cost))
    if len(reachable) == 0:
        return Reposition(None, reason="unreachable")
    costs = {n: cluster_distances(graph, clusters, links, dist[i])[0] for i, n in enumerate(names)}
    none = np.zeros(0)
    holder_costs = {int(i): [costs.get(h, none) for h in sorted(hs)]
                    for i, hs in (holders or {}).items() if hs}
    rivals = [costs[n] for n in sorted(free) if n in costs and n != robot]
    sizes = np.array([c.size for c in clusters])
    unheld = reachable[[int(i) not in holder_costs for i in reachable]]
    chosen = assign_unheld(cost, rivals, unheld, sizes, best_share_pct)
    if chosen is None:
        mine = held_by_farther(cost, reachable, holder_costs)
        if len(mine) == 0:
            return Reposition(None, reason="taken")
        top = best_share(sizes, mine, best_share_pct)
        chosen = int(top[np.argmin(cost[top])])
    cluster = clusters[chosen]
    box_min, box_max = exploration_box(cluster.centroid, box_m, world_min, world_max)
    others = {n: float(costs[n][chosen]) for n in names}
    return Reposition(chosen, frontier=cluster.centroid.copy(), path=graph_path(pred[0], graph.positions,
                      int(via[chosen])), box_min=box_min, box_max=box_max, cluster_size=cluster.size,
                      distance_m=float(cost[chosen]), distances_m=others)
