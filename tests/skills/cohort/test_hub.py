"""delve.skills.cohort.hub: MergeSubmaps, UpdateGlobalFrontiers and
AnswerRepositionRequests on the base station's fake radio and a simulator voxel map."""
from __future__ import annotations

import json

import numpy as np
from delve.planners.cohort import CohortParams
from delve.planners.gbplanner2 import synthetic as syn
from delve.planners.occupancy import UNKNOWN
from delve.sim.voxel_map import VoxelMap
from delve.skills.base import AgentContext, mailbox
from delve.skills.cohort import ASSIGNMENT, REQUEST, SUBMAP, cohort_hub
from py_trees.common import Status

from ..fakes import Clock, FakeRadio, build, events

Z = 1.5


def fork():
    T = syn.Tunnel
    return syn.carve((60, 40, 6), 0.2, [T((2, 20, 1), (30, 20, 1)), T((30, 20, 1), (50, 5, 1)),
                                         T((30, 20, 1), (50, 35, 1))])


#: Small f_min (a drift's end face is ~80 points at 0.4 m) and a box D within the world.
PARAMS = CohortParams(f_min=20, box_m=(10.0, 10.0, 4.0))


def base_station(truth, **services) -> AgentContext:
    """The base station's agent with its radio, an empty map of the truth's world and
    the team's COHORT parameters."""
    log: list = []
    ctx = AgentContext(name="base", namespace="/base", clock=Clock(),
                       log=lambda event, **fields: log.append((event, fields)),
                       services={"radio": FakeRadio("base"), "cohort_params": PARAMS,
                                 "map": VoxelMap(truth.shape, truth.origin, truth.voxel_size_m), **services})
    ctx.events = log  # type: ignore[attr-defined]
    return ctx


def submap(truth, robot, index, x_lo, x_hi, trajectory) -> dict:
    """A ``cohort_submap`` message's data: the truth's known voxels in [x_lo, x_hi)."""
    occ = truth.occupancy.reshape(-1)
    known = np.flatnonzero(occ != UNKNOWN)
    x = truth.to_world(np.stack(np.unravel_index(known, truth.shape), axis=1))[:, 0]
    flat = known[(x >= x_lo) & (x < x_hi)]
    traj = np.array(trajectory, float)
    return {"robot": robot, "index": index, "t_s": 0.0, "flat": flat, "values": occ[flat].astype(np.uint8),
            "bbox_min": traj.min(axis=0), "bbox_max": traj.max(axis=0), "trajectory": traj}


HUB_TREE = """
type: Parallel
policy: success_on_all
children:
  - type: MergeSubmaps
  - type: UpdateGlobalFrontiers
  - type: AnswerRepositionRequests
"""


def tick(tree, ctx, n: int = 1) -> None:
    for _ in range(n):
        tree.tick_once()
        ctx.clock.now_s += 1.0


def request(ctx, robot: str, request_id: int, position) -> None:
    ctx.services["radio"].deliver(robot, REQUEST, {"robot": robot, "request_id": request_id,
                                                   "position": list(position), "t_s": ctx.clock.now_s})


def test_a_submap_is_merged_into_the_base_map_and_the_hub():
    truth = fork()
    ctx = base_station(truth)
    tree = build(HUB_TREE, ctx)
    data = submap(truth, "r1", 0, 0, 20, [[3, 20, Z], [18, 20, Z]])
    ctx.services["radio"].deliver("r1", SUBMAP, data)
    tick(tree, ctx)
    assert tree.status == Status.RUNNING
    base = ctx.services["map"].occupancy.reshape(-1)
    assert np.array_equal(base[data["flat"]], truth.occupancy.reshape(-1)[data["flat"]])
    hub = cohort_hub(ctx)
    assert ("r1", 0) in hub.submaps and len(hub.clusters) == 1 and not hub.stale
    (merged,), (found,) = events(ctx, "cohort_submap"), events(ctx, "cohort_frontiers")
    assert merged["robot"] == "r1" and merged["voxels"] == len(data["flat"]) and merged["vertices"] > 200
    assert found["clusters"][0]["size"] == hub.clusters[0].size
    json.dumps(merged), json.dumps(found)                            # log.jsonl takes them as they are
    tick(tree, ctx, 3)
    assert len(events(ctx, "cohort_frontiers")) == 1                 # nothing new: nothing recomputed


def test_a_request_gets_the_matching_assignment():
    truth = fork()
    ctx = base_station(truth)
    tree = build(HUB_TREE, ctx)
    radio = ctx.services["radio"]
    radio.deliver("r1", SUBMAP, submap(truth, "r1", 0, 0, 20, [[3, 20, Z], [18, 20, Z]]))
    radio.deliver("r2", SUBMAP, submap(truth, "r2", 0, 15, 40, [[18, 20, Z], [30, 20, Z]]))
    request(ctx, "r1", 4, [30, 20, Z])
    request(ctx, "r2", 9, [30, 20, Z])
    tick(tree, ctx)
    sent = [m for m in radio.sent if m.kind == ASSIGNMENT]
    assert [(m.recipient, m.data["request_id"]) for m in sent] == [("r1", 4), ("r2", 9)]
    a, b = (m.data for m in sent)
    assert a["reason"] == b["reason"] == "ok" and a["cluster_size"] >= 20
    assert (a["frontier"][1] - 20) * (b["frontier"][1] - 20) < 0      # one robot per branch
    assert np.allclose(np.add(a["box_min"], a["box_max"]) / 2, a["frontier"], atol=1e-3)
    assert np.allclose(np.subtract(a["box_max"], a["box_min"]), PARAMS.box_m, atol=1e-3)
    assert np.asarray(a["path"]).shape[1] == 3
    logged = events(ctx, "cohort_assignment")
    assert [(e["robot"], e["request_id"], e["reason"]) for e in logged] == [("r1", 4, "ok"), ("r2", 9, "ok")]
    json.dumps(logged)


def test_with_no_frontier_the_answer_says_so():
    truth = fork()
    ctx = base_station(truth, cohort_home=np.array([3, 20, Z]))
    tree = build(HUB_TREE, ctx)
    request(ctx, "r1", 1, [3, 20, Z])
    tick(tree, ctx)
    (msg,) = ctx.services["radio"].sent
    assert msg.recipient == "r1" and msg.kind == ASSIGNMENT
    assert msg.data == {"request_id": 1, "frontier": None, "path": None, "box_min": None, "box_max": None,
                        "cluster_size": 0, "reason": "no_frontier"}
    assert events(ctx, "cohort_assignment")[0]["reason"] == "no_frontier"


def test_the_hub_takes_only_its_own_messages_and_exists_once_needed():
    truth = fork()
    ctx = base_station(truth)
    tree = build(HUB_TREE, ctx)
    ctx.services["radio"].deliver("r1", "artifact_report", {"x": 1})
    tick(tree, ctx)
    assert [m.kind for m in mailbox(ctx, ctx.services["radio"]).take_unclaimed()] == ["artifact_report"]
    assert "cohort_hub" not in ctx.services                          # created on first use only
