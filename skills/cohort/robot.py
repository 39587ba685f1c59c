"""COHORT on the robot (Kulkarni et al. 2022, section IV-B): send submaps to the hub,
call the hub every T_C seconds of exploration, and follow its re-positioning path.

Radio messages (``docs/cohort.md``): ``cohort_submap`` and ``cohort_request`` go to the
base station, ``cohort_assignment`` comes back. The parameters come from the team
strategy as service ``cohort_params`` (:class:`~delve.planners.cohort.CohortParams`;
the paper's defaults when a tree runs without it, e.g. in a unit test).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from py_trees.common import Status
from py_trees.ports import PortInformation

from ...planners.cohort import CohortParams
from ...planners.geometry import xyz
from ..base import AgentContext, Param, Skill, mailbox
from ..gbplanner import SERVICE as GBPLANNER_SERVICE, onboard_grid
from ..motion import GoTo
from ..robot import Robot
from .hub import ASSIGNMENT, PARAMS_SERVICE, REQUEST, SUBMAP

#: Who the hub is on the radio.
HUB = "base"
#: ``ctx.services`` key of the agent's count of requests to the hub.
REQUEST_COUNT = "cohort_requests"


def cohort_params(ctx: AgentContext) -> CohortParams:
    """The team's COHORT parameters (the paper's when no strategy gave them)."""
    return ctx.services.get(PARAMS_SERVICE) or CohortParams()


def record_transit(ctx: AgentContext, robot: Robot, spacing_m: float) -> None:
    """Add the robot's position to the agent's GBPlanner2 global graph as a visited
    vertex joined to the last one and to its neighbours on the onboard map, when it lies
    ``spacing_m`` or more from the last one (nothing when the agent has no GBPlanner2).
    A COHORT transit (the hub's path, the way back to a link point) runs outside the
    explorer, and the global graph only records where the explorer planned: without
    these vertices the next plan would join the end of the transit to its start by one
    straight edge, through rock, which is cut when checked and leaves the frontiers and
    home on the far side unreachable in the robot's own graph."""
    svc = ctx.services.get(GBPLANNER_SERVICE)
    if svc is None:
        return
    gp = svc.planner.global_planner
    position = np.asarray(robot.position, float)
    if np.linalg.norm(position - gp.position_of(gp.robot_vertex)) >= spacing_m:
        gp.record_position(position, onboard_grid(ctx, robot))


def linked(radio: Any, attempts: int, other: str = HUB) -> bool:
    """Whether one of ``attempts`` pings reaches ``other`` (a single ping can be lost
    on a working link)."""
    return any(radio.ping(other) for _ in range(attempts))


class SendSubmaps(Skill):
    """Cut the onboard map's changes into submaps and send each to the hub
    (``cohort_submap``): a submap ends when ``submap_window_s`` has passed or the robot
    has moved ``submap_displacement_m`` since it began (``cohort_params``). A submap
    carries the changed voxels (flat indices and values of the onboard map, which shares
    the world's grid), their bounding box and the robot's trajectory while it was made.
    Messages wait in the radio's outbox while no route exists; the rest is sent when the
    behaviour stops. Replaces ``ShareMap`` in a COHORT tree (both take the changes).

    Logs ``cohort_submap_sent`` per submap. Returns RUNNING (a background task).
    """

    PARAMS = {"trajectory_spacing_m": Param(float, 1.0, "the submap's trajectory keeps a point this far apart",
                                            exclusive_minimum=0)}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.index = 0
        self.start_s: float | None = None
        self.trajectory: list[np.ndarray] = []

    def update(self) -> Status:
        pos, now, cp = self.robot.position, self.ctx.clock.now_s, cohort_params(self.ctx)
        if self.start_s is None:
            self._begin(now, pos)
        if np.linalg.norm(pos - self.trajectory[-1]) >= self.p["trajectory_spacing_m"]:
            self.trajectory.append(pos)
        if (now - self.start_s >= cp.submap_window_s
                or np.linalg.norm(pos - self.trajectory[0]) >= cp.submap_displacement_m):
            self._send()
            self._begin(now, pos)
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if self.ctx.robot is not None and new_status != Status.RUNNING and self.start_s is not None:
            self.trajectory.append(self.robot.position)
            self._send()
            self.start_s = None

    def _begin(self, now: float, pos: np.ndarray) -> None:
        self.start_s, self.trajectory = now, [pos]

    def _send(self) -> None:
        m = self.robot.onboard_map
        flat, values = m.take_changes()
        if not len(flat):
            return
        idx = np.stack(np.unravel_index(np.asarray(flat, np.int64), m.occupancy.shape), axis=1)
        lo = m.origin + idx.min(axis=0) * m.voxel_size_m
        hi = m.origin + (idx.max(axis=0) + 1) * m.voxel_size_m
        self.robot.radio.send(HUB, SUBMAP, {
            "robot": self.ctx.name, "index": self.index, "t_s": self.ctx.clock.now_s, "flat": flat,
            "values": values, "bbox_min": xyz(lo), "bbox_max": xyz(hi), "trajectory": np.asarray(self.trajectory)})
        self.event("cohort_submap_sent", index=self.index, voxels=int(len(flat)))
        self.index += 1


class CallHub(Skill):
    """Call the COHORT hub: ping it; if it answers, send a ``cohort_request`` and wait
    for the matching ``cohort_assignment``.

    At a successful ping the robot's position is appended to ``cohort_link_points``
    (the points that offered a link, oldest first; it replaces the last one within
    ``link_point_spacing_m``). With a frontier, the assignment gives ``cohort_target``
    (the frontier), ``cohort_goal`` (where the hub's path ends, else the frontier),
    ``cohort_path`` (the path along the hub's global graph G_C) and
    ``exploration_bbox`` (the box D around the frontier); without one (the hub has
    nothing to give) those are null and the box is lifted, so that GBPlanner2 explores
    on its own. ``cohort_explored`` says whether the hub answered that its common map
    has no frontier left (reason ``explored``): the team's exploration is over. A
    frontier within ``repeat_radius_m`` of the last target, when the robot found that
    box explored (``exploration_complete``), counts as none (reason ``repeated``): the
    hub's frontier is one the robot's sensors cannot clear. A call
    that fails sets ``cohort_goal`` to null (nothing to follow) and keeps the box.

    Logs ``cohort_call`` (reached or not) and ``cohort_assignment_received``.
    Returns RUNNING while waiting for the answer; SUCCESS when it came; FAILURE when
    no ping got through (the lost-link rule follows) or no answer came within
    ``answer_timeout_s`` of sim time.
    """

    PARAMS = {
        "ping_attempts": Param(int, 3, "pings tried before the hub counts as out of reach", minimum=1),
        "answer_timeout_s": Param(float, 10.0, "sim time to wait for the hub's answer", exclusive_minimum=0),
        "link_point_spacing_m": Param(float, 2.0, "a link point this close to the last one replaces it", minimum=0),
        "repeat_radius_m": Param(float, 4.0, "a target this close to the last one, whose box the robot found "
                                 "explored, counts as no frontier", minimum=0),
    }
    INPUT_PORTS = {
        "cohort_link_points": PortInformation(list, required=False, default_value=[], description="[x, y, z] "
                                              "points that offered a link to the hub, oldest first"),
        "cohort_target": PortInformation(list | None, required=False, description="the last frontier assigned"),
        "exploration_complete": PortInformation(bool, required=False, description="GBPlanner2 found the box "
                                                "explored"),
    }
    OUTPUT_PORTS = {
        "cohort_link_points": PortInformation(list, description="[x, y, z] points that offered a link to the hub, "
                                              "oldest first"),
        "cohort_target": PortInformation(list | None, description="[x, y, z] the frontier assigned; null: none"),
        "cohort_goal": PortInformation(list | None, description="[x, y, z] where the re-positioning path ends; null: "
                                       "no frontier, or the last call failed"),
        "cohort_path": PortInformation(list | None, description="[[x, y, z], ...] the hub's path along G_C"),
        "exploration_bbox": PortInformation(dict | None, description="{min, max}: the box D around the frontier; "
                                            "null: no box"),
        "cohort_explored": PortInformation(bool, description="the hub's last answer: its common map has no "
                                           "frontier left"),
    }

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, **params)
        self.request_id = 0
        self.asked_s: float | None = None
        if ctx.robot is not None:  # not when a tree is only checked
            mailbox(ctx, ctx.robot.radio).claim(ASSIGNMENT)

    def initialise(self) -> None:
        self.asked_s = None

    def update(self) -> Status:
        r, now = self.robot, self.ctx.clock.now_s
        box = mailbox(self.ctx, r.radio)
        if self.asked_s is None:
            box.take(ASSIGNMENT)  # answers to calls given up on
            if not linked(r.radio, self.p["ping_attempts"]):
                self.feedback_message = "hub out of reach"
                self.event("cohort_call", reached=False, position=xyz(r.position, 2))
                self.write("cohort_goal", None)
                return Status.FAILURE
            self._remember_link_point(r.position)
            # One count per agent: a tree may call the hub from several places.
            self.request_id = self.ctx.services[REQUEST_COUNT] = self.ctx.services.get(REQUEST_COUNT, 0) + 1
            r.radio.send(HUB, REQUEST, {"robot": self.ctx.name, "request_id": self.request_id,
                                        "position": xyz(r.position, 3), "t_s": now})
            self.asked_s = now
            self.event("cohort_call", reached=True, request_id=self.request_id, position=xyz(r.position, 2))
        answer = next((m.data for m in box.take(ASSIGNMENT) if m.data.get("request_id") == self.request_id), None)
        if answer is not None:
            self._apply(answer)
            return Status.SUCCESS
        if now - self.asked_s >= self.p["answer_timeout_s"]:
            self.feedback_message = f"no answer to request {self.request_id}"
            self.event("cohort_call_unanswered", request_id=self.request_id)
            self.write("cohort_goal", None)
            return Status.FAILURE
        self.feedback_message = f"waiting for the hub (request {self.request_id})"
        return Status.RUNNING

    def _remember_link_point(self, here: np.ndarray) -> None:
        points = list(self.read("cohort_link_points") or [])
        if points and np.linalg.norm(np.asarray(points[-1]) - here) <= self.p["link_point_spacing_m"]:
            points.pop()
        self.write("cohort_link_points", [*points, xyz(here, 2)])

    def _repeated(self, frontier: Any) -> bool:
        """Whether the hub sends the robot back to the frontier it was sent to last,
        whose box it has since found explored (a frontier its sensors cannot clear)."""
        last = self.read("cohort_target")
        return (frontier is not None and last is not None and bool(self.read("exploration_complete"))
                and float(np.linalg.norm(np.asarray(frontier, float) - np.asarray(last, float)))
                <= self.p["repeat_radius_m"])

    def _apply(self, answer: dict[str, Any]) -> None:
        frontier, path = answer.get("frontier"), answer.get("path")
        if self._repeated(frontier):
            answer = {**answer, "reason": "repeated"}
            frontier = None
        self.write("cohort_target", None if frontier is None else xyz(frontier, 2))
        if frontier is None:
            goal = box = path = None
        else:
            path = None if path is None or not len(path) else np.asarray(path, float).reshape(-1, 3).tolist()
            goal = path[-1] if path else xyz(frontier, 3)
            box = None if answer.get("box_min") is None else {"min": xyz(answer["box_min"], 2),
                                                              "max": xyz(answer["box_max"], 2)}
        self.write("cohort_goal", goal)
        self.write("cohort_path", path)
        self.write("exploration_bbox", box)
        self.write("cohort_explored", answer.get("reason") == "explored")
        self.feedback_message = f"assigned {answer.get('reason', '')}".strip()
        self.event("cohort_assignment_received", request_id=self.request_id,
                   frontier=None if frontier is None else xyz(frontier, 2), box=box,
                   path_points=0 if path is None else len(path), reason=answer.get("reason", ""))


class FollowHubPath(GoTo):
    """Re-position to the frontier the hub assigned: follow ``cohort_path`` (the hub's
    path along G_C, which crosses space the other robots mapped) to ``cohort_goal``;
    a blocked path or an arrival short of the goal is re-planned as ``GoTo`` plans
    (navigation graph of the onboard map, or GBPlanner2's global graph).

    The way flown is added to GBPlanner2's global graph every ``graph_spacing_m``
    (:func:`record_transit`). Reads ``cohort_goal`` and ``cohort_path``; writes
    ``goto_failure`` as ``GoTo``. Returns SUCCESS at once when the hub gave no goal (nothing to follow) and within
    ``tolerance_m`` of the goal; RUNNING on the way; FAILURE as ``GoTo``.
    """

    PARAMS = {**{k: v for k, v in GoTo.PARAMS.items() if k != "goal"},
              "goal_key": Param(str, "cohort_goal", "blackboard key holding the goal [x, y, z]", key=True),
              "tolerance_m": Param(float, 2.0, "distance to the goal that counts as arrived", exclusive_minimum=0),
              "graph_spacing_m": Param(float, 2.0, "the way flown joins GBPlanner2's global graph a vertex this "
                                       "far apart", exclusive_minimum=0)}
    INPUT_PORTS = {**GoTo.INPUT_PORTS,
                   "cohort_path": PortInformation(list, required=False, description="[[x, y, z], ...] the hub's path")}

    def __init__(self, name: str, ctx: Any, remap: dict[str, str] | None = None, **params: Any):
        super().__init__(name, ctx, remap, goal=None, **params)

    def update(self) -> Status:
        if self.goal is None and self.read("goal") is None:
            self.feedback_message = "no frontier assigned"
            return Status.SUCCESS
        status = super().update()
        record_transit(self.ctx, self.robot, self.p["graph_spacing_m"])
        return status

    def _path(self, grid: Any) -> tuple[np.ndarray | None, str, str, str]:
        hub_path = self.read("cohort_path")
        if self.replans == 0 and hub_path:
            return np.asarray(hub_path, float).reshape(-1, 3), "cohort", "", ""
        return super()._path(grid)


__all__ = ["HUB", "REQUEST_COUNT", "CallHub", "FollowHubPath", "SendSubmaps", "cohort_params", "linked",
           "record_transit"]
