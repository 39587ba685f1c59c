"""Scan points of the inspection payload (CERBERUS paper, section 3.5, "Autonomous
scanning"): the smallest set of the payload's joint configurations that covers the
unseen part of its reachable workspace, and whether it calls for a full scan.

The paper's algorithm, as implemented here:

1. The candidate scan points are a grid of the payload's joint space (yaw x pitch,
   3°: 1170 candidates); a visibility matrix says which unseen point each candidate
   sees (within 5 m, in the camera's view, not behind rock).
2. The scan points are a minimum **set cover** of the unseen points that some
   candidate can see: ``min sum_j x_j`` subject to ``sum_{j sees i} x_j >= 1`` for
   every such point ``i``, ``x_j`` binary. The instance is first reduced (identical
   points and candidates merged, points whose constraint another implies dropped,
   candidates that see a subset of another's dropped), which keeps the optimum.
   Small instances are solved exactly with CBC (pulp, quiet, one thread, a limit
   on branch-and-bound nodes so that the result does not depend on the machine's
   speed, a wall-clock safety stop, started from the greedy cover); larger ones, or when CBC returns nothing better, with
   the greedy cover (most newly covered points first, then redundant scans removed).
3. **Autonomous Full Scan** when the unseen part exceeds ``full_scan_fraction``
   (50 %) of the reachable workspace: the robot pauses, stops and scans every
   scan point. Otherwise **Autonomous Point Scan**: the scan points are scanned
   while walking.

Pure numpy and pulp; the visibility comes in as a matrix or a function, so this
module knows nothing of worlds or cameras.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from collections.abc import Callable

import numpy as np
import pulp

#: The paper's threshold: a full scan when the unseen part exceeds this fraction of
#: the reachable workspace.
FULL_SCAN_FRACTION = 0.5
#: Reduced instances with at most this many (points x candidates) cells go to CBC.
EXACT_MAX_SIZE = 200_000
#: CBC's work limit: branch-and-bound nodes (a result that the machine's load
#: cannot change, unlike a time limit).
NODE_LIMIT = 2000
#: Wall-clock safety stop for CBC (seconds); only a pathological instance reaches it.
TIME_LIMIT_S = 30.0
#: Above this many rows (or columns) the quadratic dominance reductions are skipped.
_DOMINANCE_MAX = 3000

AUTONOMOUS_FULL_SCAN = "autonomous_full_scan"
AUTONOMOUS_POINT_SCAN = "autonomous_point_scan"

#: A visibility function: (points (N, 3), body_pose, candidates (K, 2)) -> (N, K) bool.
VisibilityFn = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
Visibility = np.ndarray | VisibilityFn


@dataclass(frozen=True)
class ScanPointSelection:
    """The chosen scan points and the scan mode.

    Fields:
        scan_points: (S, 2) joint configurations (yaw, pitch) in degrees, in scanning
            order (by yaw, then pitch: one sweep of the pan joint).
        candidate_indices: (S,) their rows in the candidates.
        covered: (N,) bool, which unseen points the scan points see.
        covered_fraction: covered unseen points / unseen points (1.0 when none is unseen).
        coverable_fraction: unseen points that some candidate sees / unseen points.
        unseen_fraction: unseen points in the reachable workspace / its size.
        full_scan: True for an Autonomous Full Scan (stop and scan every point).
        mode: ``AUTONOMOUS_FULL_SCAN`` or ``AUTONOMOUS_POINT_SCAN`` ("" when nothing to scan).
        solver: "cbc", "greedy" or "none" (nothing to cover).
        optimal: whether the set is proven to be a smallest cover.
    """

    scan_points: np.ndarray
    candidate_indices: np.ndarray
    covered: np.ndarray
    covered_fraction: float
    coverable_fraction: float
    unseen_fraction: float
    full_scan: bool
    mode: str
    solver: str
    optimal: bool

    @property
    def n_scan_points(self) -> int:
        return len(self.candidate_indices)


def visibility_of(unseen_points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                  visibility: Visibility) -> np.ndarray:
    """The (N, K) bool visibility matrix, from a matrix or by calling the function."""
    pts = np.asarray(unseen_points, dtype=float).reshape(-1, 3)
    cand = np.asarray(candidates, dtype=float).reshape(-1, 2)
    vis = visibility(pts, body_pose, cand) if callable(visibility) else visibility
    vis = np.asarray(vis, dtype=bool)
    if vis.shape != (len(pts), len(cand)):
        raise ValueError(f"visibility must be (points, candidates) = {(len(pts), len(cand))}, got {vis.shape}")
    return vis


def reachable_workspace(points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                        visibility: Visibility) -> np.ndarray:
    """(N,) bool: which points some candidate scan point sees (the reachable workspace)."""
    return visibility_of(points, body_pose, candidates, visibility).any(axis=1)


def select_scan_points(unseen_points: np.ndarray, body_pose: np.ndarray, candidates: np.ndarray,
                       visibility: Visibility, reachable_workspace_size: int, *,
                       full_scan_fraction: float = FULL_SCAN_FRACTION,
                       exact_max_size: int = EXACT_MAX_SIZE, node_limit: int = NODE_LIMIT,
                       time_limit_s: float = TIME_LIMIT_S) -> ScanPointSelection:
    """Choose the smallest set of scan points that covers the unseen part of the workspace.

    Args:
        unseen_points: (N, 3) points of the reachable workspace not yet seen.
        body_pose: the robot's body pose, passed to ``visibility`` when it is a function.
        candidates: (K, 2) joint configurations (yaw, pitch) in degrees.
        visibility: (N, K) bool matrix, or a function (points, body_pose, candidates) -> it.
        reachable_workspace_size: number of points in the reachable workspace, seen or not.
        full_scan_fraction: Autonomous Full Scan above this unseen fraction (the paper's 0.5).
        exact_max_size: largest reduced instance (points x candidates) solved with CBC.
        node_limit: CBC's limit of branch-and-bound nodes; the greedy cover is kept if
            CBC finds nothing better.
        time_limit_s: CBC's wall-clock safety stop.
    """
    if not 0.0 <= full_scan_fraction <= 1.0:
        raise ValueError(f"full_scan_fraction must lie in [0, 1], got {full_scan_fraction}")
    if not (math.isfinite(time_limit_s) and time_limit_s > 0):
        raise ValueError(f"time_limit_s must be > 0, got {time_limit_s}")
    if node_limit < 1:
        raise ValueError(f"node_limit must be >= 1, got {node_limit}")
    cand = np.asarray(candidates, dtype=float).reshape(-1, 2)
    vis = visibility_of(unseen_points, body_pose, cand, visibility)
    n = len(vis)
    coverable = vis.any(axis=1)
    n_cov = int(coverable.sum())
    if int(reachable_workspace_size) < n_cov:
        raise ValueError(f"reachable_workspace_size {reachable_workspace_size} is smaller than the "
                         f"{n_cov} unseen points the candidates see")
    unseen_fraction = n_cov / int(reachable_workspace_size) if reachable_workspace_size else 0.0
    full_scan = n_cov > 0 and unseen_fraction > full_scan_fraction
    mode = "" if n_cov == 0 else (AUTONOMOUS_FULL_SCAN if full_scan else AUTONOMOUS_POINT_SCAN)

    if n_cov == 0:
        chosen, solver, optimal = np.zeros(0, dtype=int), "none", True
    else:
        chosen, solver, optimal = minimum_set_cover(vis[coverable], exact_max_size=exact_max_size,
                                                    node_limit=node_limit, time_limit_s=time_limit_s)
    order = np.lexsort((cand[chosen, 1], cand[chosen, 0])) if len(chosen) else np.zeros(0, dtype=int)
    chosen = chosen[order]
    covered = vis[:, chosen].any(axis=1) if len(chosen) else np.zeros(n, dtype=bool)
    return ScanPointSelection(
        scan_points=cand[chosen].copy(),
        candidate_indices=chosen,
        covered=covered,
        covered_fraction=float(covered.mean()) if n else 1.0,
        coverable_fraction=n_cov / n if n else 1.0,
        unseen_fraction=float(unseen_fraction),
        full_scan=bool(full_scan),
        mode=mode,
        solver=solver,
        optimal=bool(optimal),
    )


# ---- set cover -------------------------------------------------------------------
def minimum_set_cover(covers: np.ndarray, *, exact_max_size: int = EXACT_MAX_SIZE, node_limit: int = NODE_LIMIT,
                      time_limit_s: float = TIME_LIMIT_S) -> tuple[np.ndarray, str, bool]:
    """A smallest set of columns of ``covers`` ((N, K) bool) whose union covers every row.

    Every row must be covered by some column. Returns (column indices sorted,
    solver name, proven optimal).
    """
    a = np.asarray(covers, dtype=bool)
    if not a.any(axis=1).all():
        raise ValueError("every row of a set cover instance needs a column that covers it")
    if a.shape[0] == 0:
        return np.zeros(0, dtype=int), "none", True
    reduced, cols = _reduce(a)
    start = _greedy_cover(reduced)
    greedy = _greedy_cover(a)                 # most unseen points first, on the full instance
    if len(start) < len(greedy):
        greedy = cols[start]
    if reduced.size <= exact_max_size:
        exact, proven = _cbc_cover(reduced, start, node_limit, time_limit_s)
        if exact is not None and (proven or len(exact) < len(greedy)):
            return np.sort(cols[exact]), "cbc", proven
    return np.sort(greedy), "greedy", len(greedy) <= 1


def _reduce(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reduce a set cover instance without changing its optimum.

    Merges identical rows and identical columns, drops rows implied by another
    (a superset of another row's columns) and columns dominated by another (a subset
    of another column's rows), until nothing changes. Returns the reduced matrix and
    the original index of each kept column.
    """
    cols = np.arange(a.shape[1])
    keep = a.any(axis=0)
    a, cols = a[:, keep], cols[keep]
    while True:
        shape = a.shape
        a = a[_unique_rows(a)]
        if a.shape[0] <= _DOMINANCE_MAX:
            f = a.astype(np.float32)
            overlap = f @ f.T                                  # shared columns of rows i, k
            size = f.sum(axis=1)
            implied = overlap >= size[None, :] - 0.5           # row k's columns all in row i
            np.fill_diagonal(implied, False)
            a = a[~implied.any(axis=1)]
        first = _unique_rows(a.T)
        a, cols = a[:, first], cols[first]
        if a.shape[1] <= _DOMINANCE_MAX:
            f = a.astype(np.float32)
            overlap = f.T @ f                                  # shared rows of columns j, l
            size = f.sum(axis=0)
            dominated = overlap >= size[:, None] - 0.5         # column j's rows all in column l
            np.fill_diagonal(dominated, False)
            drop = dominated.any(axis=1)
            a, cols = a[:, ~drop], cols[~drop]
        if a.shape == shape:
            return a, cols


def _unique_rows(a: np.ndarray) -> np.ndarray:
    """Sorted indices of the first occurrence of each distinct row of a bool matrix."""
    if a.shape[0] == 0 or a.shape[1] == 0:
        return np.arange(min(a.shape[0], 1))
    packed = np.ascontiguousarray(np.packbits(a, axis=1))
    keys = packed.view(np.dtype((np.void, packed.shape[1]))).ravel()
    _, first = np.unique(keys, return_index=True)
    return np.sort(first)


def _greedy_cover(a: np.ndarray) -> np.ndarray:
    """Greedy set cover: take the column covering most uncovered rows (lowest index on
    ties) until all are covered, then drop chosen columns that others make redundant."""
    uncovered = np.ones(a.shape[0], dtype=bool)
    counts = a.sum(axis=0).astype(np.int64)
    chosen: list[int] = []
    while uncovered.any():
        j = int(np.argmax(counts))
        chosen.append(j)
        newly = uncovered & a[:, j]
        uncovered &= ~newly
        counts -= a[newly].sum(axis=0)
    times = a[:, chosen].sum(axis=1)
    for j in reversed(list(chosen)):
        if np.all(times[a[:, j]] >= 2):
            times -= a[:, j]
            chosen.remove(j)
    return np.array(sorted(chosen), dtype=int)


def _cbc_cover(a: np.ndarray, start: np.ndarray, node_limit: int,
               time_limit_s: float) -> tuple[np.ndarray | None, bool]:
    """Exact set cover with CBC, warm-started from ``start``. Returns (columns or None, proven)."""
    prob = pulp.LpProblem("scan_points", pulp.LpMinimize)
    x = [prob.add_variable(f"x{j}", cat=pulp.LpBinary) for j in range(a.shape[1])]
    prob += pulp.lpSum(x)
    for i, row in enumerate(a):
        prob += pulp.lpSum(x[j] for j in np.flatnonzero(row)) >= 1, f"cover{i}"
    in_start = set(start.tolist())
    for j, v in enumerate(x):
        v.setInitialValue(1 if j in in_start else 0)
    with warnings.catch_warnings():      # pulp 3.3+ prefers an external CBC; the bundled one is fine
        warnings.simplefilter("ignore", DeprecationWarning)
        solver = pulp.PULP_CBC_CMD(msg=False, timeLimit=float(time_limit_s), maxNodes=int(node_limit),
                                    warmStart=True, threads=1)
    try:
        prob.solve(solver)
    except pulp.PulpSolverError:
        return None, False
    if prob.sol_status not in (pulp.LpSolutionOptimal, pulp.LpSolutionIntegerFeasible):
        return None, False
    chosen = np.array([j for j, v in enumerate(x) if (v.value() or 0.0) > 0.5], dtype=int)
    if len(chosen) == 0 or not a[:, chosen].any(axis=1).all():
        return None, False
    return chosen, prob.sol_status == pulp.LpSolutionOptimal
