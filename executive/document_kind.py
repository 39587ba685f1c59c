"""Whether a YAML file's top level is a scenario or a tree, told by its keys, so that
a scenario given where a tree is expected (or the other way round) is named as such."""
from __future__ import annotations

from typing import Any

from .errors import did_you_mean


#: Top-level keys that only a scenario has (a tree node may have a name too).
_SCENARIO_ONLY_KEYS = ("world", "robots", "base_station", "radio", "team", "supervisor", "faults", "artifacts")


def scenario_keys(mapping: Any) -> list[str]:
    """The keys that make ``mapping`` (a file's top level) a scenario rather than a
    tree: keys only a scenario has, or near misses of them (``wrold``), in file order.
    [] for a tree node (it has, or nearly has, 'type' or 'include')."""
    if not isinstance(mapping, dict):
        return []
    keys = [k for k in mapping if isinstance(k, str)]
    if any(k in ("type", "include") or did_you_mean(k, ("type", "include")) for k in keys):
        return []
    return [k for k in keys if k in _SCENARIO_ONLY_KEYS or did_you_mean(k, _SCENARIO_ONLY_KEYS)]
