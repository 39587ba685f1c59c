"""Tick-rate overhead of trees built from YAML against the same tree built by hand.

Builds one 40-node tree twice -- from YAML with delve's loader, and by hand in plain
py_trees -- ticks each N times per repetition (repetitions interleaved, the order
alternating) and prints the median ticks per second of each and the ratio of the
time per tick, yaml / hand (median over the back-to-back pairs; goal <= 1.05). Only py_trees built-ins and delve's
sim-clock Timer/Timeout are used, so it runs without the simulator.

    python bench/bt_overhead.py [--ticks N] [--reps R]
"""
from __future__ import annotations

import argparse
import gc
import operator
import shlex
import statistics
import sys
import tempfile
import time
from importlib.metadata import version
from pathlib import Path

import py_trees
from delve.executive.tree_loader import load_tree
from delve.skills.base import AgentContext
from delve.skills.timing import Timeout, Timer
from py_trees import behaviours, common, composites, decorators

FOREVER_S = 1.0e9

TREE_YAML = f"""\
type: Parallel
name: Mission
policy: success_on_all
synchronise: false
children:
  - type: Sequence
    name: Checks
    memory: false
    children:
      - {{type: SetBlackboardVariable, name: Set battery, variable_name: battery_pct, variable_value: 80}}
      - {{type: CheckBlackboardVariableValue, name: Battery ok, variable_name: battery_pct, value: 20, operator: ">"}}
      - {{type: CheckBlackboardVariableExists, name: Have battery, variable_name: battery_pct}}
      - type: Inverter
        name: Not failed
        child: {{type: Failure, name: Failed}}
      - {{type: SuccessEveryN, name: Every tick, n: 1}}
  - type: Sequence
    name: Blackboard
    memory: false
    children:
      - {{type: SetBlackboardVariable, name: Set mode, variable_name: mode, variable_value: explore}}
      - {{type: CompareBlackboardVariables, name: Same battery, var1_key: battery_pct, var2_key: battery_pct, operator: ">="}}
      - type: StatusToBlackboard
        name: Remember status
        variable_name: last_status
        child: {{type: Success, name: Status source}}
      - {{type: BlackboardToStatus, name: Recall status, variable_name: last_status}}
  - type: Selector
    name: Choose
    memory: false
    children:
      - type: Sequence
        name: Return?
        memory: false
        children:
          - {{type: CheckBlackboardVariableValue, name: Mode return, variable_name: mode, value: return}}
          - {{type: Running, name: Returning}}
      - type: Sequence
        name: Explore?
        memory: false
        children:
          - {{type: CheckBlackboardVariableValue, name: Mode explore, variable_name: mode, value: explore}}
          - {{type: Timer, name: Dwell, duration_s: {FOREVER_S}}}
      - {{type: Running, name: Idle}}
  - type: Sequence
    name: Counters
    memory: false
    children:
      - type: FailureIsSuccess
        name: Periodic ok
        child: {{type: Periodic, name: Periodic, n: 3}}
      - type: RunningIsSuccess
        name: Counting ok
        child: {{type: TickCounter, name: Counter, duration_ticks: 5}}
      - type: PassThrough
        name: Pass
        child: {{type: Success, name: Passed}}
      - type: Count
        name: Count
        child: {{type: Success, name: Counted}}
  - type: Timeout
    name: Watchdog
    duration_s: {FOREVER_S}
    child:
      type: Selector
      name: Fallback
      memory: false
      children:
        - {{type: Failure, name: First try}}
        - {{type: Running, name: Second try}}
  - type: Sequence
    name: Flags
    memory: false
    children:
      - {{type: CheckBlackboardVariableValue, name: Battery not full, variable_name: battery_pct, value: 100, operator: "<"}}
      - type: FailureIsSuccess
        name: Charging optional
        child: {{type: CheckBlackboardVariableValue, name: Charging, variable_name: charging, value: true}}
      - {{type: Success, name: Done}}
"""

N_NODES = 40


def build_by_hand(ctx: AgentContext) -> py_trees.behaviour.Behaviour:
    """The tree of TREE_YAML written out in plain py_trees."""
    ns = ctx.namespace

    def check(name: str, key: str, value: object, op=operator.eq) -> behaviours.CheckBlackboardVariableValue:
        return behaviours.CheckBlackboardVariableValue(
            name=name, check=common.ComparisonExpression(variable=f"{ns}/{key}", value=value, operator=op)
        )

    blackboard = composites.Sequence(name="Blackboard", memory=False, children=[
        behaviours.SetBlackboardVariable(name="Set mode", variable_name=f"{ns}/mode", variable_value="explore",
                                         overwrite=True),
        behaviours.CompareBlackboardVariables(name="Same battery", var1_key=f"{ns}/battery_pct",
                                              var2_key=f"{ns}/battery_pct", operator=operator.ge),
        decorators.StatusToBlackboard(name="Remember status", child=behaviours.Success(name="Status source"),
                                      variable_name=f"{ns}/last_status"),
        behaviours.BlackboardToStatus(name="Recall status", variable_name=f"{ns}/last_status"),
    ])
    checks = composites.Sequence(name="Checks", memory=False, children=[
        behaviours.SetBlackboardVariable(name="Set battery", variable_name=f"{ns}/battery_pct", variable_value=80,
                                         overwrite=True),
        check("Battery ok", "battery_pct", 20, operator.gt),
        behaviours.CheckBlackboardVariableExists(name="Have battery", variable_name=f"{ns}/battery_pct"),
        decorators.Inverter(name="Not failed", child=behaviours.Failure(name="Failed")),
        behaviours.SuccessEveryN(name="Every tick", n=1),
    ])
    choose = composites.Selector(name="Choose", memory=False, children=[
        composites.Sequence(name="Return?", memory=False, children=[
            check("Mode return", "mode", "return"), behaviours.Running(name="Returning"),
        ]),
        composites.Sequence(name="Explore?", memory=False, children=[
            check("Mode explore", "mode", "explore"), Timer(name="Dwell", ctx=ctx, duration_s=FOREVER_S),
        ]),
        behaviours.Running(name="Idle"),
    ])
    counters = composites.Sequence(name="Counters", memory=False, children=[
        decorators.FailureIsSuccess(name="Periodic ok", child=behaviours.Periodic(name="Periodic", n=3)),
        decorators.RunningIsSuccess(name="Counting ok", child=behaviours.TickCounter(
            name="Counter", duration=5, completion_status=common.Status.SUCCESS)),
        decorators.PassThrough(name="Pass", child=behaviours.Success(name="Passed")),
        decorators.Count(name="Count", child=behaviours.Success(name="Counted")),
    ])
    watchdog = Timeout(name="Watchdog", ctx=ctx, duration_s=FOREVER_S, child=composites.Selector(
        name="Fallback", memory=False, children=[behaviours.Failure(name="First try"), behaviours.Running(name="Second try")],
    ))
    flags = composites.Sequence(name="Flags", memory=False, children=[
        check("Battery not full", "battery_pct", 100, operator.lt),
        decorators.FailureIsSuccess(name="Charging optional", child=check("Charging", "charging", True)),
        behaviours.Success(name="Done"),
    ])
    return composites.Parallel(
        name="Mission",
        policy=common.ParallelPolicy.SuccessOnAll(synchronise=False),
        children=[checks, blackboard, choose, counters, watchdog, flags],
    )


class _Clock:
    now_s = 0.0


def _context(namespace: str) -> AgentContext:
    return AgentContext(name=namespace.strip("/"), namespace=namespace, clock=_Clock(), log=lambda *a, **k: None)


def _ticks_per_s(root: py_trees.behaviour.Behaviour, ticks: int) -> float:
    tick = root.tick_once
    gc.collect()
    start = time.perf_counter()
    for _ in range(ticks):
        tick()
    return ticks / (time.perf_counter() - start)


def _shape(root: py_trees.behaviour.Behaviour) -> list[tuple[str, str]]:
    return [(type(node).__name__, node.name) for node in root.iterate()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--ticks", type=int, default=500, help="ticks per repetition (default 500)")
    parser.add_argument("--reps", type=int, default=31, help="repetitions, at least 5 (default 31)")
    args = parser.parse_args(argv)
    reps = max(5, args.reps)

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bt_overhead.yaml"
        path.write_text(TREE_YAML)
        start = time.perf_counter()
        load_tree(path, _context("/cold"))  # the first load also imports every skill module
        cold_ms = (time.perf_counter() - start) * 1e3
        start = time.perf_counter()
        from_yaml = load_tree(path, _context("/yaml"))
        load_ms = (time.perf_counter() - start) * 1e3
    start = time.perf_counter()
    by_hand = build_by_hand(_context("/hand"))
    hand_ms = (time.perf_counter() - start) * 1e3

    shape = _shape(from_yaml)
    if len(shape) != N_NODES or shape != _shape(by_hand):
        print(f"the two trees differ ({len(shape)} vs {len(_shape(by_hand))} nodes)", file=sys.stderr)
        return 1

    rates: dict[str, list[float]] = {"yaml": [], "hand": []}
    trees = {"yaml": from_yaml, "hand": by_hand}
    for name, root in trees.items():  # warm up
        _ticks_per_s(root, min(200, args.ticks))
    for rep in range(reps):
        order = ("yaml", "hand") if rep % 2 == 0 else ("hand", "yaml")
        for name in order:
            rates[name].append(_ticks_per_s(trees[name], args.ticks))
    yaml_rate = statistics.median(rates["yaml"])
    hand_rate = statistics.median(rates["hand"])
    # pairs measured back to back share the machine's load: their ratio is steadier
    ratio = statistics.median(h / y for y, h in zip(rates["yaml"], rates["hand"]))

    command = shlex.join([Path(sys.executable).name, *sys.argv]) if argv is None else shlex.join(["bt_overhead.py", *argv])
    print(f"$ {command}")
    print(f"{N_NODES}-node tree, {args.ticks} ticks x {reps} repetitions (interleaved), median; "
          f"py_trees {version('py_trees')}, Python {sys.version.split()[0]}")
    print()
    print(f"{'tree':<8}{'ticks/s':>12}{'us/tick':>10}{'build ms':>10}")
    print(f"{'yaml':<8}{yaml_rate:>12,.0f}{1e6 / yaml_rate:>10.1f}{load_ms:>10.2f}")
    print(f"{'hand':<8}{hand_rate:>12,.0f}{1e6 / hand_rate:>10.1f}{hand_ms:>10.2f}")
    print(f"(build ms: yaml parse + check + build; the first load in a process took {cold_ms:.0f} ms, "
          f"importing the skill modules)")
    print()
    verdict = "ok" if ratio <= 1.05 else "ABOVE GOAL"
    print(f"time per tick, yaml / hand: {ratio:.3f}  (median of the {reps} paired repetitions; goal <= 1.05: {verdict})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
