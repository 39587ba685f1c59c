"""Supervisor commands: what the Human Supervisor can ask of a robot, and the skill
that turns commands arriving over the radio into blackboard state for the tree.

The commands are the CERBERUS paper's operator calls and its four modes of
operation: explore within radio range (backing off when the link drops), explore
with a time budget out of range, relocate to a frontier then explore, and go to a
waypoint; plus setting the exploration bounding box, homing, cancelling, scanning
the area or a point, dropping a breadcrumb, and letting the robot ask for scans
where its map shows unseen wall (the paper's autonomous scanning, which the Human
Supervisor enabled).
"""
from __future__ import annotations

from typing import Any

from py_trees.common import Status
from py_trees.ports import PortInformation

from .base import Param, Skill, mailbox

COMMAND = "command"
GOAL_UNREACHABLE = "goal_unreachable"

#: Each command's arguments. The executive checks supervisor scripts against these.
COMMANDS: dict[str, dict[str, Param]] = {
    "explore": {"budget_s": Param(float, None, "time budget for exploring out of radio range; none: stay in range",
                                  minimum=0, nullable=True)},
    "set_bbox": {"min": Param(list, doc="lower corner [x, y, z] of the exploration bounding box (m)"),
                 "max": Param(list, doc="upper corner [x, y, z] (m)")},
    "home": {},
    "cancel": {},
    "relocate": {},
    "scan": {"point": Param(list, None, "point [x, y, z] to inspect; none: scan the area", nullable=True)},
    "goto": {"goal": Param(list, doc="waypoint [x, y, z] (m)")},
    "drop_breadcrumb": {},
    "autonomous_scans": {"enabled": Param(bool, True, "whether the robot asks for inspections where its map shows "
                                                      "unseen wall")},
}

#: Blackboard values of ``mode``.
MODES = ("idle", "explore", "relocate", "goto", "home")
#: Commands that give the robot a new task: each replaces the running one and its
#: time budget (``explore`` sets its own).
TASKS = ("explore", "relocate", "goto", "home", "cancel")


class ProcessOperatorCommands(Skill):
    """Process Operator Calls: apply every supervisor command that has arrived.

    Takes the radio messages of kind ``command`` from the agent's mailbox (they wait
    in the base station's outbox while the link is down; other kinds stay for other
    behaviours). Writes ``mode`` (idle, explore, relocate, goto, home),
    ``time_budget_s`` and ``budget_start_s`` (explore with a budget), ``goal`` and
    ``goal_source`` (goto), ``exploration_bbox``, ``inspection_request`` (scan),
    ``breadcrumb_request``, ``autonomous_scans`` (False until the supervisor enables
    them), ``end_at_home`` and ``last_command``; ``explore`` also
    clears ``link_loss_points`` (WiFi safety's memory of the radio edge: a new
    exploring task starts afresh).

    Commands take priority over onboard requests: a task (explore, relocate, goto,
    home, cancel) replaces the running one and clears its time budget (explore sets
    its own). ``end_at_home`` says whether homing ends the mission (True) or only a
    sortie, after which the robot waits at home for its next command (False): it
    starts as ``end_at_home`` (an unsupervised robot's mission ends at home), the
    ``home`` command sets it, and the other tasks clear it (the supervisor will send
    the robot out again, or call it home). Returns RUNNING (it is a background task).
    """

    PARAMS = {
        "initial_mode": Param(str, "idle", "mode before the first command", choices=MODES),
        "end_at_home": Param(bool, True, "whether homing ends the mission until a task command other than "
                                         "home arrives (then homing ends a sortie)"),
    }
    #: Set up with ``initial_mode``, ``end_at_home``, ``False`` for ``breadcrumb_request``
    #: and null for the rest.
    OUTPUT_PORTS = {
        "mode": PortInformation(str, description="the mode of operation: " + ", ".join(MODES)),
        "time_budget_s": PortInformation(float | None, description="explore's time budget (s); null: none"),
        "budget_start_s": PortInformation(float | None, description="sim time the budget started at (s)"),
        "goal": PortInformation(list | None, description="goto's waypoint [x, y, z] (m)"),
        "goal_source": PortInformation(str | None, description="who set goal (``supervisor``)"),
        "exploration_bbox": PortInformation(list | None, description="[min, max] corners of the exploration "
                                            "bounding box (m)"),
        "inspection_request": PortInformation(dict | None, description="scan's request: {point, requested_s}"),
        "breadcrumb_request": PortInformation(bool, description="True when a breadcrumb is to be dropped"),
        "end_at_home": PortInformation(bool, description="True: homing ends the mission; False: it ends a sortie "
                                       "and the robot waits at home for commands"),
        "link_loss_points": PortInformation(list, description="where the radio link was lost: cleared by explore"),
        "autonomous_scans": PortInformation(bool, description="True when the robot may ask for inspections itself"),
        "last_command": PortInformation(str | None, description="the last command applied"),
    }

    def setup(self, **kwargs: Any) -> None:
        self.write("mode", self.p["initial_mode"])
        for k in ("time_budget_s", "budget_start_s", "goal", "goal_source", "exploration_bbox", "inspection_request"):
            self.write(k, None)
        self.write("breadcrumb_request", False)
        self.write("end_at_home", self.p["end_at_home"])
        self.write("link_loss_points", [])
        self.write("autonomous_scans", False)
        self.write("last_command", None)

    def update(self) -> Status:
        for msg in mailbox(self.ctx, self.robot.radio).take(COMMAND):
            self._apply(msg.data["command"], msg.data.get("args", {}))
        return Status.RUNNING

    def _apply(self, command: str, args: dict[str, Any]) -> None:
        now, set_ = self.ctx.clock.now_s, self.write
        if command in TASKS:
            budget = args.get("budget_s") if command == "explore" else None
            set_("time_budget_s", budget)
            set_("budget_start_s", now if budget is not None else None)
            set_("end_at_home", command == "home")
        if command == "explore":
            set_("mode", "explore")
            set_("link_loss_points", [])
        elif command == "set_bbox":
            set_("exploration_bbox", [list(args["min"]), list(args["max"])])
        elif command in ("home", "relocate"):
            set_("mode", command)
        elif command == "cancel":
            set_("mode", "idle")
            self.robot.stop()
        elif command == "goto":
            set_("mode", "goto")
            set_("goal", list(args["goal"]))
            set_("goal_source", "supervisor")
        elif command == "scan":
            set_("inspection_request", {"point": args.get("point"), "requested_s": now})
        elif command == "drop_breadcrumb":
            set_("breadcrumb_request", True)
        elif command == "autonomous_scans":
            set_("autonomous_scans", bool(args.get("enabled", True)))
        set_("last_command", command)
        self.event("operator_command", trigger=True, command=command, **{k: v for k, v in args.items()})
