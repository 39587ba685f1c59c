"""Scenario files: reading, checking (JSON Schema, then meaning) and building the world.

Every mistake becomes a one-line :class:`DelveError` with the file and line.
"""
from __future__ import annotations

import inspect
import json
import math
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import jsonschema

from ..sim import worldgen
from ..sim.graph_world import GraphWorld
from . import graph_worlds
from ..sim.world import World
from .errors import DelveError, did_you_mean
from .supervisor import Command, load_supervisor

from .yamlio import YamlDict, YamlList, load_yaml, plain

SCHEMA_PATH = Path(__file__).parent / "schema" / "scenario.schema.json"
GENERATORS = ("tunnel_network", "cave") + graph_worlds.GRAPH_GENERATORS
#: Radio settings that mean something on a graph world (communication edges decide links).
GRAPH_RADIO_KEYS = ("loss", "update_period_s")
MESH_OPTIONS = ("mesh", "scale", "up_axis", "voxel_size_m", "start", "seed")
DEFAULTS = {"seed": 0, "duration_s": 3600.0, "dt_s": 0.1, "coverage_period_s": 5.0}


@lru_cache(maxsize=1)
def scenario_schema() -> dict:
    return json.loads(SCHEMA_PATH.read_text())


@dataclass
class RobotSpec:
    """One robot of a scenario, with its tree file resolved."""

    name: str
    platform: str
    tree: Path
    start: list[float] | None = None
    endurance_s: float | None = None
    tick_hz: float = 5.0
    overrides: dict[str, float] = field(default_factory=dict)
    lidar: dict[str, float] = field(default_factory=dict)
    breadcrumbs: int = 0
    line: int | None = None
    start_line: int | None = None


@dataclass(frozen=True)
class Fault:
    """A fault injected at ``at_s``: ``stuck`` (the robot cannot move for
    ``duration_s``), ``map_artifact`` (rock appears in its onboard map around it,
    as odometry drift leaves in a real map) or ``lost`` (the robot dies: it stops
    and its radio falls silent for good)."""

    at_s: float
    robot: str
    kind: str
    duration_s: float = 0.0


@dataclass
class Scenario:
    """A checked scenario: plain values, resolved paths and where each came from."""

    path: Path
    name: str
    seed: int
    duration_s: float
    dt_s: float
    coverage_period_s: float
    world: dict[str, Any]
    robots: list[RobotSpec]
    base_tree: Path | None
    base_position: list[float] | None
    base_tick_hz: float
    radio: dict[str, float]
    doc: YamlDict
    supervisor: list[Command] = field(default_factory=list)
    faults: list[Fault] = field(default_factory=list)

    @property
    def is_graph(self) -> bool:
        """Whether the world is a graph world (a network file or a graph generator)."""
        return "network" in self.world or self.world.get("generator") in graph_worlds.GRAPH_GENERATORS

    def build_world(self, seed: int | None = None) -> World | GraphWorld:
        """Generate or load the world (a DelveError when its parameters are wrong).

        A generator without its own ``seed`` takes ``seed``, else the scenario's."""
        spec = dict(self.world)
        line = self.doc["world"].line
        try:
            if "network" in spec:
                return graph_worlds.load_network_world(self.path.parent / spec["network"])
            if spec.get("generator") in graph_worlds.GRAPH_GENERATORS:
                gen = getattr(graph_worlds, spec.pop("generator"))
                spec.setdefault("seed", self.seed if seed is None else seed)
                return gen(**spec)
            if "mesh" in spec:
                mesh = (self.path.parent / spec.pop("mesh")).resolve()
                if not mesh.exists():
                    raise DelveError(f"mesh file not found: {mesh}", self.path, self.doc["world"].key_line("mesh"))
                spec.pop("seed", None)
                return worldgen.from_mesh(mesh, **spec)
            gen = getattr(worldgen, spec.pop("generator"))
            spec.setdefault("seed", self.seed if seed is None else seed)
            return gen(**spec)
        except ValueError as err:
            raise DelveError(f"world: {err}", self.path, line) from None

    def check_starts(self, world: World) -> None:
        """Each robot's start pose must be inside the world and in free space."""
        for r in self.robots:
            if r.start is None:
                continue
            problem = world.start_problem(r.start)
            if problem:
                raise DelveError(f"robot {r.name!r}: start pose {r.start} is {problem}", self.path, r.start_line)
        if self.base_position is not None:
            problem = world.start_problem(self.base_position)
            if problem:
                raise DelveError(f"base station position is {problem}", self.path, self.doc["base_station"].line)


def _schema_error(err: jsonschema.ValidationError, doc: Any, path: Path) -> DelveError:
    """Turn a JSON Schema error into one line at the offending key."""
    node, line = doc, getattr(doc, "line", None)
    for part in err.absolute_path:
        if isinstance(node, YamlDict):
            line = node.key_line(part) or line
        elif isinstance(node, YamlList):
            line = node.item_line(part) or line
        node = node[part]
    where = "/".join(str(p) for p in err.absolute_path) or "scenario"
    if err.validator == "additionalProperties":
        allowed = err.schema.get("properties", {})
        extra = sorted(set(node) - set(allowed))
        key = extra[0] if extra else "?"
        if isinstance(node, YamlDict):
            line = node.key_line(key) or line
        return DelveError(f"{where}: unknown key {key!r}{did_you_mean(key, allowed)}", path, line)
    if err.validator == "required":
        return DelveError(f"{where}: {err.message.replace(' is a required property', '')} is missing", path, line)
    if err.validator == "oneOf" and where == "world":
        return DelveError("world: give one of 'generator', 'mesh' or 'network'", path, line)
    if err.validator == "enum":
        choices = ", ".join(map(repr, err.validator_value))
        return DelveError(f"{where}: {err.instance!r} is not one of {choices}", path, line)
    return DelveError(f"{where}: {err.message}", path, line)


def _nan(doc: Any, path: Path) -> None:
    """Reject NaN and infinite numbers anywhere in the file."""
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for k, v in items:
        if isinstance(v, float) and not math.isfinite(v):
            line = doc.key_line(k) if isinstance(doc, YamlDict) else doc.item_line(k)
            raise DelveError(f"{k}: must be a finite number, not {v}", path, line)
        _nan(v, path)


def _world_params(world: YamlDict, path: Path) -> None:
    if "mesh" in world:
        allowed = MESH_OPTIONS
    elif "network" in world:
        allowed = ("network",)
    else:
        module = graph_worlds if world["generator"] in graph_worlds.GRAPH_GENERATORS else worldgen
        allowed = ("generator",) + tuple(inspect.signature(getattr(module, world["generator"])).parameters)
    for key in world:
        if key not in allowed:
            raise DelveError(f"world: unknown parameter {key!r}{did_you_mean(key, allowed)}", path,
                             world.key_line(key))


def _graph_checks(doc: YamlDict, path: Path, base_tree: Path | None, faults: list[Fault]) -> None:
    """What a graph world needs and refuses: a base station tree, a readable network
    file, no voxel-world radio settings or faults."""
    world = doc["world"]
    if "network" in world:
        net_path = path.parent / world["network"]
        if not net_path.exists():
            raise DelveError(f"network file not found: {world['network']}", path, world.key_line("network"))
        graph_worlds.load_network_world(net_path)
    if base_tree is None:
        raise DelveError("a graph world needs a base station tree (base_station: tree: ...), the COPS leader",
                         path, doc.key_line("base_station") or doc.key_line("world"))
    for key in doc.get("radio", {}):
        if key not in GRAPH_RADIO_KEYS:
            raise DelveError(f"radio: {key!r} does not apply to a graph world (communication edges decide links; "
                             f"use {', '.join(GRAPH_RADIO_KEYS)})", path, doc["radio"].key_line(key))
    for i, f in enumerate(faults):
        if f.kind == "map_artifact":
            raise DelveError("a 'map_artifact' fault needs a voxel map; a graph world has none", path,
                             doc["faults"].item_line(i))


def load_scenario(path: str | Path) -> Scenario:
    """Read and check a scenario file (not its world: see :meth:`Scenario.build_world`)."""
    path = Path(path)
    doc = load_yaml(path)
    if not isinstance(doc, YamlDict):
        raise DelveError("a scenario file must be a mapping", path, getattr(doc, "line", 1))
    _nan(doc, path)
    errors = sorted(jsonschema.Draft202012Validator(scenario_schema()).iter_errors(doc),
                    key=lambda e: (len(e.absolute_path), list(map(str, e.absolute_path))))
    if errors:
        raise _schema_error(jsonschema.exceptions.best_match(errors), doc, path)
    _world_params(doc["world"], path)
    from .tree_loader import check_tree

    robots, names = [], set()  # names: the robots seen so far
    for i, r in enumerate(doc["robots"]):
        line = doc["robots"].item_line(i)
        if r["name"] in names or r["name"] == "base":
            why = "is used twice" if r["name"] in names else "is reserved for the base station"
            raise DelveError(f"robot name {r['name']!r} {why}", path, line)
        names.add(r["name"])
        tree = (path.parent / r["tree"]).resolve()
        if not tree.exists():
            raise DelveError(f"robot {r['name']!r}: tree file not found: {r['tree']}", path, r.key_line("tree"))
        check_tree(tree)
        extra = {k: float(r[k]) for k in ("speed_mps", "max_inclination_deg", "max_step_m") if k in r}
        robots.append(RobotSpec(name=r["name"], platform=r["platform"], tree=tree, start=r.get("start"),
                                endurance_s=r.get("endurance_s"), tick_hz=float(r.get("tick_hz", 5.0)),
                                overrides=extra, lidar=plain(r.get("lidar", {})), breadcrumbs=r.get("breadcrumbs", 0),
                                line=line, start_line=r.key_line("start")))

    base = doc.get("base_station", {})
    base_tree = None
    if "tree" in base:
        base_tree = (path.parent / base["tree"]).resolve()
        if not base_tree.exists():
            raise DelveError(f"base station tree file not found: {base['tree']}", path, base.key_line("tree"))
        check_tree(base_tree)
    supervisor = load_supervisor(doc.get("supervisor"), path, {r.name: r.breadcrumbs for r in robots})
    faults = []
    for i, f in enumerate(doc.get("faults", [])):
        if f["robot"] not in names:
            raise DelveError(f"fault for unknown robot {f['robot']!r}{did_you_mean(f['robot'], names)}", path,
                             doc["faults"].item_line(i))
        if f["kind"] == "stuck" and "duration_s" not in f:
            raise DelveError("a 'stuck' fault needs duration_s", path, doc["faults"].item_line(i))
        faults.append(Fault(float(f["at_s"]), f["robot"], f["kind"], float(f.get("duration_s", 0.0))))
    values = {k: doc.get(k, v) for k, v in DEFAULTS.items()}
    if "network" in doc["world"] or doc["world"].get("generator") in graph_worlds.GRAPH_GENERATORS:
        _graph_checks(doc, path, base_tree, faults)
    return Scenario(path=path, name=doc["name"], seed=int(values["seed"]), duration_s=float(values["duration_s"]),
                    dt_s=float(values["dt_s"]), coverage_period_s=float(values["coverage_period_s"]),
                    world=plain(doc["world"]), robots=robots, base_tree=base_tree,
                    base_position=base.get("position"), base_tick_hz=float(base.get("tick_hz", 1.0)),
                    radio=plain(doc.get("radio", {})), doc=doc, supervisor=supervisor,
                    faults=sorted(faults, key=lambda f: f.at_s))
