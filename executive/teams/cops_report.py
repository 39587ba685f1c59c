"""Report figures of a COPS mission (graph or voxel world), read from its events."""
from __future__ import annotations

import statistics
from typing import Any

#: Per plan, the fields of its ``cops_plan`` event that the report keeps.
PLAN_FIELDS = ("cycle", "final", "robots", "locations", "frontiers", "explorers", "T_pre", "T_post", "ext_com",
               "int_com", "transitions", "relayed", "clustered", "work")


def cops_figures(events: list[dict[str, Any]]) -> dict[str, Any]:
    """Cycles, plans that passed the validator, why planning failed, the moves robots
    could not make, each plan (with its work: simplex iterations), and the safety
    stops (wall clock) that fired while planning: with one, the run may not be
    reproducible (``reproducible`` is false)."""
    plans = [e for e in events if e["event"] == "cops_plan"]
    stops = sum(e["count"] for e in events if e["event"] == "cops_safety_stop")
    return {
        "cycles": len(plans),
        "plans_valid": sum(1 for e in plans if e.get("valid")),
        "no_plan": [e["reason"] for e in events if e["event"] in ("cops_no_plan", "cops_invalid_plan")],
        "transitions_failed": transition_failures(events),
        "safety_stops": stops,
        "reproducible": stops == 0,
        "plans": [{k: e.get(k) for k in PLAN_FIELDS} for e in plans],
    }


def transition_failures(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every move a robot could not make (``cops_transition_failed``): robot, time,
    from, to, reason."""
    return [{"robot": e["robot"], "t": e["t"], "from": e["from"], "to": e["to"], "reason": e["reason"]}
            for e in events if e["event"] == "cops_transition_failed"]


def gone_home(events: list[dict[str, Any]]) -> dict[str, list[str]]:
    """Robots that left the plan for home: ``by_endurance`` (their endurance barely
    covered the way), ``after_failed_move`` (a move of the plan failed)."""
    left = [e for e in events if e["event"] == "cops_left_plan"]
    return {"by_endurance": sorted({e["agent"] for e in left if e["reason"] == "endurance"}),
            "after_failed_move": sorted({e["agent"] for e in left if e["reason"] != "endurance"})}


def declared_lost(events: list[dict[str, Any]]) -> list[str]:
    """Robots some agent declared lost."""
    return sorted({e["robot"] for e in events if e["event"] == "robot_declared_lost"})


def solve_time_figures(events: list[dict[str, Any]]) -> dict[str, Any]:
    """Median, longest and total solve time of the plans (wall clock)."""
    times = [e["solve_time_s"] for e in events if e["event"] == "cops_plan" and e.get("solve_time_s") is not None]
    if not times:
        return {}
    return {"cops_solve_time_s": {"median": round(statistics.median(times), 3),
                                  "max": round(max(times), 3), "total": round(sum(times), 3)}}
