"""delve.executive.agent: an agent's tree, ticked on its period, stopped with its statuses kept."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest
from delve.executive.agent import Agent
from delve.executive.tree_loader import load_tree
from delve.skills.base import AgentContext
from py_trees.common import Status

TREES = Path(__file__).resolve().parent.parent / "data" / "trees"


@pytest.mark.usefixtures("clean_blackboard")
def test_a_stopped_tree_keeps_the_statuses_it_had_and_its_final_status():
    ctx = AgentContext(name="r1", namespace="/r1", clock=SimpleNamespace(now_s=0.0), log=lambda *a, **k: None)
    agent = Agent("r1", load_tree(TREES / "timed.yaml", ctx), 1.0, ctx)
    assert agent.tick_if_due(0.0) and not agent.tick_if_due(0.5)   # one tick a period
    assert agent.final_status == Status.RUNNING and agent.stopped_statuses is None
    agent.stop()
    agent.stop()   # a second stop (a lost robot's, at the end of the run) keeps the first statuses
    assert agent.root.status == Status.INVALID and agent.final_status == Status.RUNNING
    assert agent.stopped_statuses[agent.root.id] == Status.RUNNING
    assert list(agent.stopped_statuses.values()).count(Status.INVALID) == 1   # the note, never ticked
