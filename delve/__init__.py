"""delve: a behaviour-tree mission executive for subterranean robot teams."""
from pathlib import Path

__version__ = "0.1.0"

#: Repository root, which holds the shipped ``trees/`` and ``scenarios/``.
ROOT = Path(__file__).resolve().parent.parent
TREES_DIR = ROOT / "trees"
SCENARIOS_DIR = ROOT / "scenarios"
