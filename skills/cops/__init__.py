"""The COPS mission executive (Figure 4 of the COPS paper) as behaviours.

Every agent (robots and the base station) keeps one :class:`CopsState` on its
blackboard (key ``cops``): what it knows (the topology it gathered or received,
the freshness of each robot's information, robots declared lost), the cycle plan it
executes (the information m), which part of the cycle it is in (``pre``,
``explore``, ``post``, ``done``) and the plan step t.

Behaviours, in the paper's words, by module:

* :mod:`.communication`: ``InformationStorage`` (background; receives,
  acknowledges and stores every message, merges what the robot's own sensing
  reveals) and ``CommunicationAction`` (PreIntCom, ExtCom, PostIntCom; re-sent
  until acknowledged).
* :mod:`.leader`: ``Leader?`` (``IsLeader``), ``COPS`` (``SolveCOPS``),
  ``WaitToReceivePlan``, ``ReturnWithoutPlan`` and ``MissionComplete?``.
* :mod:`.motion`: ``TransitionAction`` and ``ActionTimer``, ``ExplorationAction``
  (Algorithm 1), ``ExplorationTimer``, ``TransitToReturnNode``.
* :mod:`.conditions`: ``Explore?`` (``IsExploring``), ``FinishedPlan?`` and
  ``TransitionFailed?``.
* :mod:`.endurance`: ``LeavePlan``, ``TransitToBase`` and ``GreetBase``, a
  robot's way home when its endurance barely covers it (the onboard
  ``EnduranceLow``) or a move of the plan failed.

:mod:`.state` holds the state and the message ids, :mod:`.base` the behaviours'
common base, :mod:`.voxel_view` the network a robot's voxel map reveals.
"""
from __future__ import annotations

from .base import STATE_KEY, CopsSkill, network_view
from .communication import CommunicationAction, InformationStorage
from .conditions import FinishedPlan, IsExploring, TransitionFailed
from .endurance import GreetBase, LeavePlan, TransitToBase
from .leader import IsLeader, MissionComplete, ReturnWithoutPlan, SolveCOPS, WaitToReceivePlan
from .motion import (ActionTimer, ExplorationAction, ExplorationTimer, TransitionAction, TransitToReturnNode,
                     ordered_choices)
from .state import KIND, PARTS, CopsState, Knowledge, collect_own_map, final_plan_id, message_id

__all__ = [
    "KIND", "PARTS", "STATE_KEY", "ActionTimer", "CommunicationAction", "CopsSkill", "CopsState",
    "ExplorationAction", "ExplorationTimer", "FinishedPlan", "GreetBase", "InformationStorage", "IsExploring",
    "IsLeader", "Knowledge", "LeavePlan", "MissionComplete", "ReturnWithoutPlan", "SolveCOPS", "TransitToBase",
    "TransitToReturnNode", "TransitionAction", "TransitionFailed", "WaitToReceivePlan", "collect_own_map", "final_plan_id",
    "message_id", "network_view", "ordered_choices",
]
