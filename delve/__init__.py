"""delve: a behaviour-tree mission executive for subterranean robot teams."""
from importlib.resources import files
from pathlib import Path

__version__ = "0.1.0"

#: The shipped trees (``trees/`` in the repository, ``delve/trees`` when installed).
TREES_DIR = Path(str(files("delve.trees")))
#: The shipped scenarios and their worlds (``scenarios/``, ``delve/scenarios``).
SCENARIOS_DIR = Path(str(files("delve.scenarios")))
