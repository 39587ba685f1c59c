"""What every skill test shares: a blackboard cleared before and after each test
(py_trees' blackboard storage is global)."""
import py_trees
import pytest


@pytest.fixture(autouse=True)
def clean_blackboard():
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()
