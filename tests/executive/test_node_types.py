"""delve.executive.node_types: what a node type is."""
from __future__ import annotations

import pytest
from delve.executive.node_types import NodeType
from delve.skills.base import Param


def test_node_type_rejects_reserved_names_and_unknown_kinds():
    with pytest.raises(ValueError, match="reserved"):
        NodeType("Y", "behaviour", lambda b: None, {"children": Param(int, 1)})
    with pytest.raises(ValueError, match="kind"):
        NodeType("Z", "gadget", lambda b: None)
