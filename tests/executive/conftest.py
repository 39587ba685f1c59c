"""Fixtures shared by the executive's tests."""
import py_trees
import pytest


@pytest.fixture()
def clean_blackboard():
    """py_trees' blackboard empty before the test and after it, whatever the test did."""
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()
