"""Graph worlds for COPS scenarios: a generated tunnel-like network, or a network file.

Both become a :class:`delve.sim.graph_world.GraphWorld` (the simulator knows nothing
of the planner; the graph backend converts). A malformed network file is rejected when
the scenario is loaded, with its file and line.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from ...planners.cops.network import MCNetwork, network_from_dict, tunnel_network_graph
from ...sim.graph_world import GraphWorld
from ..errors import DelveError, clip_message
from ..yamlio import YamlDict, YamlList, load_yaml, plain


def tunnel_graph(n_locations: int = 100, spacing_m: float = 50.0, seed: int = 0, fork_probability: float = 0.2,
                 max_depth_m: float = 1000.0, comm_range_m: float = 100.0) -> GraphWorld:
    """The paper's experiment world: ``n_locations`` locations about ``spacing_m``
    apart in tunnels that fork, at most ``max_depth_m`` deep, with communication
    edges in line of sight within ``comm_range_m``."""
    net = tunnel_network_graph(n_locations, spacing_m, seed, fork_probability=fork_probability,
                               max_depth_m=max_depth_m, comm_range_m=comm_range_m, base_station=None)
    return world_of(net)


def world_of(net: MCNetwork) -> GraphWorld:
    """The graph world of a network whose locations all have positions."""
    pos = {}
    for s in net.locations:
        p = net.position(s)
        if p is None:
            raise ValueError(f"location '{s}' needs a position ('pos') in a graph world")
        pos[s] = tuple(p) + (0.0,) * (3 - len(p))
    tunnels = sorted({tuple(sorted(e)) for e in net.mobility.edges})
    comm = sorted({tuple(sorted(e)) for e in net.communication.edges})
    if net.base is None:
        raise ValueError("the network needs a 'base' location")
    return GraphWorld(pos, tunnels, comm, net.base)


def load_network_world(path: Path) -> GraphWorld:
    """Read a network file (the format of ``network_from_dict``) as a graph world.
    Any mistake is a :class:`DelveError` at the offending line."""
    doc = load_yaml(path)
    if not isinstance(doc, YamlDict):
        raise DelveError("a network file must be a mapping", path, getattr(doc, "line", 1))
    _finite_numbers(doc, path)
    try:
        return world_of(network_from_dict(plain(doc)))
    except (ValueError, TypeError) as err:
        raise DelveError(f"network: {clip_message(err, 100)}", path, _line_of(doc, str(err))) from None


def _finite_numbers(value: Any, path: Path) -> None:
    """A DelveError at the first NaN, infinity or integer beyond a float's range."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        bad = isinstance(item, float) and not math.isfinite(item)
        huge = isinstance(item, int) and not isinstance(item, bool) and abs(item) > 2.0 ** 1023
        if bad or huge:
            line = value.key_line(key) if isinstance(value, YamlDict) else value.item_line(key)
            raise DelveError("network: numbers must be finite and within +-1.8e308", path, line)
        _finite_numbers(item, path)


def _line_of(doc: YamlDict, message: str) -> int | None:
    """The line a network error is about: the first entry of the section the message
    names that mentions the names the message quotes."""
    names = re.findall(r"'([^']+)'", message) + [x for pair in re.findall(r"(\S+)->(\S+?)[:\s]", message)
                                                 for x in pair]
    section = next((k for k in ("mobility", "communication", "robots", "locations", "frontiers")
                    if k.rstrip("s") in message or k in message), None)
    order = [section] if section in doc else []
    order += [k for k in doc if k not in order]
    best, line = 0, None
    for key in order:
        value = doc[key]
        found = ([(_mentions(item, names), value.item_line(i)) for i, item in enumerate(value)]
                 if isinstance(value, YamlList) else [(_mentions(value, names), doc.key_line(key))])
        for score, where in found:
            if score > best:
                best, line = score, where
    if line is not None:
        return line
    return doc.key_line(section) if section in doc else doc.line


def _mentions(item: Any, names: list[str]) -> int:
    """How many of ``names`` an entry names."""
    values = item.values() if isinstance(item, dict) else item if isinstance(item, list) else [item]
    return len({str(v) for v in values if not isinstance(v, (dict, list))} & set(names))
