"""Scenario files: reading, checking (JSON Schema, then meaning) and building the world.

Every mistake becomes a one-line :class:`DelveError` with the file and line.
"""
from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Iterable

import jsonschema

from .artifacts import ArtifactSetup, check_sensors
from .errors import DelveDeprecation, DelveError, DelveWarning, did_you_mean, display_path
from .document_kind import scenario_keys
from .faults import Fault, FaultContext, load_faults
from .supervisor import Command, load_supervisor
from .teams import DEFAULT_STRATEGY, TEAM_STRATEGIES, TeamStrategy, implied_strategy
from .worlds import WorldBackend, backend_for, generator_names
from ..skills.base import short_repr, yaml_number_hint
from .yamlio import YamlDict, YamlList, file_problem, load_yaml, plain

SCHEMA_PATH = Path(__file__).parent / "schema" / "scenario.schema.json"
DEFAULTS = {"seed": 0, "duration_s": 3600.0, "dt_s": 0.1, "coverage_period_s": 5.0}
#: Most simulation steps a run may take (duration_s / dt_s). The shipped scenarios
#: take at most 40 000 (cops_tunnel: 40 000 s at 1 s; demo: 2400 s at 0.1 s); a voxel
#: world runs a few hundred to a few thousand steps a second, so 2 000 000 steps is
#: hours of wall time: more is a typo (dt_s: 1e-6) that would never end.
MAX_SIM_STEPS = 2_000_000


def steps_problem(duration_s: float, dt_s: float) -> str | None:
    """Why a run of ``duration_s`` in steps of ``dt_s`` cannot be run, or None."""
    if not math.isfinite(duration_s) or not duration_s > 0:
        return f"must be a finite number of seconds > 0, got {duration_s}"
    steps = duration_s / dt_s
    if steps > MAX_SIM_STEPS:
        return (f"{duration_s:g} s in steps of dt_s {dt_s:g} s is {steps:.3g} steps, more than the limit of "
                f"{MAX_SIM_STEPS:,}")
    return None


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
    #: The artifact sensors' parameters that differ from the platform's.
    sensors: dict[str, Any] = field(default_factory=dict)
    #: Sim time its tree starts ticking (until then it stands at its start).
    deploy_at_s: float = 0.0
    line: int | None = None
    start_line: int | None = None


@dataclass(frozen=True)
class TeamSpec:
    """The scenario's team strategy and its checked parameters."""

    strategy: type[TeamStrategy]
    params: dict[str, Any]


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
    world_backend: type[WorldBackend]
    team: TeamSpec
    supervisor: list[Command] = field(default_factory=list)
    faults: list[Fault] = field(default_factory=list)
    #: The artifacts the world hides and the referee's rules (``artifacts:``), or None.
    artifacts: ArtifactSetup | None = None
    #: Folders the trees' includes may resolve into besides their own and the shipped trees.
    include_path: tuple[Path, ...] = ()

    def team_strategy(self) -> TeamStrategy:
        """A fresh instance of the scenario's team strategy."""
        return self.team.strategy(**self.team.params)

    def build_world(self, seed: int | None = None) -> Any:
        """Generate or load the world (a DelveError when its parameters are wrong).

        A generator without its own ``seed`` takes ``seed``, else the scenario's."""
        return self.world_backend.build_world(self, self.seed if seed is None else seed)

    def check_starts(self, world: Any) -> None:
        """Each robot's start pose must be inside the world and in free space, and so
        must each listed artifact; the team strategy's parameters must fit the world."""
        for r in self.robots:
            if r.start is None:
                continue
            problem = world.start_problem(r.start)
            if problem:
                raise DelveError(f"robot {short_repr(r.name)}: start pose {r.start} is {problem}", self.path,
                                 r.start_line)
        if self.base_position is not None:
            problem = world.start_problem(self.base_position)
            if problem:
                raise DelveError(f"base station position is {problem}", self.path,
                                 self.doc["base_station"].key_line("position"))
        if self.artifacts is not None:
            self.artifacts.listed(world)
        self.team.strategy.check_world(self, world)


def _where(path: Any) -> str:
    return "/".join(short_repr(p)[1:-1] if isinstance(p, str) else str(p) for p in path) or "scenario"


def _schema_rank(err: jsonschema.ValidationError) -> tuple:
    """Which error to report first: the shallowest, then an unknown key (a typo
    explains the rest), then in file order."""
    return (len(err.absolute_path), err.validator != "additionalProperties", list(map(str, err.absolute_path)))


def _schema_error(err: jsonschema.ValidationError, doc: Any, path: Path) -> DelveError:
    """Turn a JSON Schema error into one line at the offending key; it quotes at most
    a few dozen characters of the offending value."""
    node, line = doc, getattr(doc, "line", None)
    for part in err.absolute_path:
        if isinstance(node, YamlDict):
            line = node.key_line(part) or line
        elif isinstance(node, YamlList):
            line = node.item_line(part) or line
        node = node[part]
    where = _where(err.absolute_path)
    if err.validator == "additionalProperties":
        allowed = err.schema.get("properties", {})
        extra = [k for k in node if k not in allowed]
        key = extra[0] if extra else "?"
        if isinstance(node, YamlDict):
            line = node.key_line(key) or line
        return DelveError(f"{where}: unknown key {short_repr(key)}{did_you_mean(str(key), allowed)}", path, line)
    if err.validator == "required":
        return DelveError(f"{where}: {err.message.replace(' is a required property', '')} is missing", path, line)
    if err.validator == "oneOf" and where == "world":
        return DelveError("world: give one of 'generator', 'mesh' or 'network'", path, line)
    if err.validator == "enum":
        choices = ", ".join(map(repr, err.validator_value))
        hint = did_you_mean(err.instance, map(str, err.validator_value)) \
            if isinstance(err.instance, str) else ""
        return DelveError(f"{where}: {short_repr(err.instance)} is not one of {choices}{hint}", path, line)
    message = err.message
    shown = repr(err.instance)
    if len(shown) > len(short_repr(err.instance)):
        message = message.replace(shown, short_repr(err.instance))
    if len(message) > 160:
        message = message[:160] + "..."
    if err.validator == "type" and {"number", "integer"} & set(_as_list(err.validator_value)):
        message += yaml_number_hint(err.instance, integer="number" not in _as_list(err.validator_value))
    return DelveError(f"{where}: {message}", path, line)


def _as_list(value: Any) -> list:
    return value if isinstance(value, list) else [value]


def _nan(doc: Any, path: Path, where: tuple = ()) -> None:
    """Reject NaN and infinite numbers, and integers too large for a number, anywhere
    in the file; the error names the value's path (``robots/0/start/0``)."""
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for k, v in items:
        bad = isinstance(v, float) and not math.isfinite(v)
        huge = isinstance(v, int) and not isinstance(v, bool) and abs(v) > 2.0 ** 1023
        if bad or huge:
            line = doc.key_line(k) if isinstance(doc, YamlDict) else doc.item_line(k)
            what = f"not {v}" if bad else f"not an integer of {len(str(abs(v)))} digits"
            raise DelveError(f"{_where((*where, k))}: must be a finite number, {what}", path, line)
        _nan(v, path, (*where, k))


def _check_steps(doc: YamlDict, path: Path, duration_s: float, dt_s: float) -> None:
    """A run over :data:`MAX_SIM_STEPS` steps is an error at ``dt_s`` (when the
    duration would fit at the default step) or else at ``duration_s``."""
    problem = steps_problem(duration_s, dt_s)
    if problem is None:
        return
    at_dt = "dt_s" in doc and (duration_s / DEFAULTS["dt_s"] <= MAX_SIM_STEPS or "duration_s" not in doc)
    key = "dt_s" if at_dt else "duration_s"
    raise DelveError(f"{key}: {problem}", path, doc.key_line(key) or doc.line)


def warn_late_events(doc: YamlDict, path: Path, duration_s: float, until_s: float = math.inf,
                     where: str = "duration_s") -> None:
    """A :class:`DelveWarning` for each supervisor command and fault of ``doc``
    timed after ``duration_s`` (and at most ``until_s``): it never happens."""
    for section, what in (("supervisor", "supervisor command"), ("faults", "fault")):
        items = doc.get(section)
        if not isinstance(items, YamlList):
            continue
        for item in items:
            at = item.get("at_s") if isinstance(item, YamlDict) else None
            if isinstance(at, bool) or not isinstance(at, (int, float)) or not duration_s < at <= until_s:
                continue
            name = item.get("command") or item.get("kind")
            label = f" {short_repr(name)}" if isinstance(name, str) else ""
            warnings.warn(DelveWarning(
                f"{display_path(path)}:{item.key_line('at_s')}: {what}{label} at_s {at:g} comes after the end of "
                f"the run ({where} {duration_s:g} s): it never happens"), stacklevel=2)


def _tree_file(path: Path, given: str, include_path: tuple[Path, ...], what: str, line: int | None) -> Path:
    """The tree file ``given`` names (relative to the scenario ``path``), resolved: it
    must lie, symbolic links followed, in the scenario's folder, the shipped trees or
    an ``include_path`` folder (the rule of includes), and be a readable file."""
    from .tree_loader import allowed_include_roots, path_inside

    where = path.parent / given
    if "\0" not in given:
        roots = allowed_include_roots(path, include_path)
        if not any(path_inside(os.path.realpath(where), root) for root in roots):
            folders = ", ".join([f"the scenario's folder {os.path.join(display_path(roots[0]), '')}",
                                 "the shipped trees", *(display_path(r) for r in roots[2:])])
            raise DelveError(f"{what} {short_repr(given)} is outside the allowed folders ({folders}; "
                             "add --include-path)", path, line)
    problem = file_problem(where)
    if problem:
        raise DelveError(f"{what} file {problem}: {short_repr(given)[1:-1]}", path, line)
    return where.resolve()


def _world_backend(doc: YamlDict, path: Path) -> type[WorldBackend]:
    """The backend that claims the scenario's ``world:``; a DelveError if none does."""
    world = doc["world"]
    backend = backend_for(world)
    if backend is None:
        names = generator_names()
        name = world.get("generator")
        raise DelveError(f"world/generator: {short_repr(name)} is not one of {', '.join(map(repr, names))}"
                         f"{did_you_mean(str(name), names)}", path, world.key_line("generator") or world.line)
    return backend


def _team(doc: YamlDict, path: Path, tree_types: set[type]) -> TeamSpec:
    """The scenario's team strategy with its checked parameters. Without ``team:``,
    the strategy whose behaviours the trees use (with a deprecation warning that names
    the key to add), else the default. Trees whose nodes need another strategy than
    the one named are a mistake."""
    team = doc.get("team")
    if team is None:
        name = implied_strategy(tree_types)
        if name is None:
            return TeamSpec(TEAM_STRATEGIES[DEFAULT_STRATEGY], {})
        warnings.warn(DelveDeprecation(
            f"{path}: no 'team:' key; the trees use behaviours of strategy {name!r}. "
            f"It runs as a {name!r} team with the default parameters; add 'team: {{strategy: {name}}}' (a later "
            "version will run a scenario without 'team:' as an independent team)"), stacklevel=2)
        return TeamSpec(TEAM_STRATEGIES[name], {})
    name = team["strategy"]
    if name not in TEAM_STRATEGIES:
        raise DelveError(f"team: unknown strategy {short_repr(name)}{did_you_mean(name, TEAM_STRATEGIES)} "
                         f"(one of {', '.join(map(repr, TEAM_STRATEGIES))})", path, team.key_line("strategy"))
    strategy = TEAM_STRATEGIES[name]
    needed = implied_strategy(tree_types)
    if needed is not None and needed != name:
        raise DelveError(f"team: the trees use behaviours of strategy {needed!r}, not {name!r} "
                         f"(use 'strategy: {needed}')", path, team.key_line("strategy"))
    params = {}
    for key, value in team.items():
        if key == "strategy":
            continue
        spec = strategy.PARAMS.get(key)
        if spec is None:
            raise DelveError(f"team: unknown parameter {short_repr(key)} of strategy {name!r}"
                             f"{did_you_mean(key, strategy.PARAMS)}", path, team.key_line(key))
        problem = spec.problem(value)
        if problem:
            raise DelveError(f"team: {key} {problem}", path, team.key_line(key))
        params[key] = float(value) if spec.type is float else value
    return TeamSpec(strategy, params)


def _check_agent_kind(types: set[type], kind: str, what: str, path: Path, line: int | None) -> None:
    """A behaviour that belongs in the other kind of agent's tree (``AGENT`` of a
    skill: "robot" or "base") in the tree of a ``kind`` agent: a mistake at its
    ``tree:`` line (built, it would fail at its first tick)."""
    wrong = sorted(getattr(c, "TYPE_NAME", c.__name__) for c in types
                   if getattr(c, "AGENT", None) not in (None, kind))
    if wrong:
        why = "which needs a robot (the base station has none)" if kind == "base" else \
            "a behaviour of the base station (it belongs in base_station: tree:)"
        raise DelveError(f"{what} uses {wrong[0]}, {why}", path, line)


def _check_hub_needed(doc: YamlDict, path: Path, robots: list[RobotSpec], robot_types: dict[str, set[type]]) -> None:
    """A robot tree whose behaviours belong to a strategy that needs a base station
    tree, in a scenario with neither: a mistake at that robot's ``tree:`` line."""
    for i, r in enumerate(robots):
        name = implied_strategy(robot_types[r.name])
        if name is not None and TEAM_STRATEGIES[name].NEEDS_BASE_TREE:
            raise DelveError(f"robot {short_repr(r.name)}: its tree uses behaviours of team strategy {name!r}, which "
                             f"needs a base station tree (base_station: tree: ...) and 'team: {{strategy: {name}}}'",
                             path, doc["robots"][i].key_line("tree"))


def _artifacts(doc: YamlDict, path: Path, backend: type[WorldBackend], tree_types: set[type]) -> ArtifactSetup | None:
    """The scenario's ``artifacts:`` section: only on worlds that hide artifacts; a
    warning when no tree submits reports (nothing could score)."""
    setup = ArtifactSetup.from_scenario(doc, path)
    if setup is None:
        return None
    if not backend.ARTIFACTS:
        raise DelveError(f"artifacts: this world ({backend.__name__}) cannot hide artifacts (a voxel world can)",
                         path, doc.key_line("artifacts"))
    if not any(t.__name__ == "SubmitArtifacts" for t in tree_types):
        warnings.warn(DelveWarning(f"{display_path(path)}:{doc.key_line('artifacts')}: artifacts: no tree submits "
                                   "reports (SubmitArtifacts in the base station's tree): nothing can score"),
                      stacklevel=2)
    return setup


def load_scenario(path: str | Path, include_path: Iterable[str | Path] = (),
                  doc: YamlDict | None = None) -> Scenario:
    """Read and check a scenario file (not its world: see :meth:`Scenario.build_world`).
    ``include_path``: folders its trees' includes may also resolve into. ``doc``: the
    file's content as already read and changed (a sweep's overrides); paths in it
    still resolve from ``path``."""
    include_path = tuple(Path(p) for p in include_path)
    path = Path(path)
    doc = load_yaml(path) if doc is None else doc
    if not isinstance(doc, YamlDict):
        raise DelveError("a scenario file must be a mapping", path, getattr(doc, "line", 1))
    if ("type" in doc or "include" in doc) and not scenario_keys({k: v for k, v in doc.items()
                                                                  if k not in ("type", "include")}):
        key = "type" if "type" in doc else "include"
        raise DelveError(f"{path.name} is a tree, not a scenario: a scenario names its trees "
                         "(robots: - tree: ...)", path, doc.key_line(key))
    known = tuple(scenario_schema()["properties"])
    if doc and not any(isinstance(k, str) and (k in known or did_you_mean(k, known)) for k in doc):
        # Not a word of it: a file that is no scenario (named by mistake) is not quoted.
        raise DelveError(f"{path.name} is no scenario: none of its keys is a scenario's ({', '.join(known[:6])}, ...)",
                         path, doc.line)
    _nan(doc, path)
    errors = sorted(jsonschema.Draft202012Validator(scenario_schema()).iter_errors(doc), key=_schema_rank)
    if errors:
        first = errors[0]
        raise _schema_error(jsonschema.exceptions.best_match([first]) if first.context else first, doc, path)
    backend = _world_backend(doc, path)
    from .tree_loader import check_tree

    robots, names, tree_types = [], set(), set()  # names: the robots seen so far
    robot_types: dict[str, set[type]] = {}
    for i, r in enumerate(doc["robots"]):
        line = doc["robots"].item_line(i)
        if r["name"] in names or r["name"] == "base":
            why = "is used twice" if r["name"] in names else "is reserved for the base station"
            raise DelveError(f"robot name {short_repr(r['name'])} {why}", path, line)
        names.add(r["name"])
        tree = _tree_file(path, r["tree"], include_path, f"robot {short_repr(r['name'])}: tree", r.key_line("tree"))
        robot_types[r["name"]] = check_tree(tree, include_path=include_path)
        _check_agent_kind(robot_types[r["name"]], "robot", f"robot {short_repr(r['name'])}: its tree", path,
                          r.key_line("tree"))
        tree_types |= robot_types[r["name"]]
        extra = {k: float(r[k]) for k in ("speed_mps", "max_inclination_deg", "max_step_m") if k in r}
        robots.append(RobotSpec(name=r["name"], platform=r["platform"], tree=tree, start=r.get("start"),
                                endurance_s=r.get("endurance_s"), tick_hz=float(r.get("tick_hz", 5.0)),
                                overrides=extra, lidar=plain(r.get("lidar", {})), breadcrumbs=r.get("breadcrumbs", 0),
                                sensors=check_sensors(r, i, r["platform"], path),
                                deploy_at_s=float(r.get("deploy_at_s", 0.0)), line=line,
                                start_line=r.key_line("start")))

    base = doc.get("base_station", {})
    base_tree, base_types = None, set()
    if "tree" in base:
        base_tree = _tree_file(path, base["tree"], include_path, "base station tree", base.key_line("tree"))
        base_types = check_tree(base_tree, include_path=include_path)
        _check_agent_kind(base_types, "base", "base station tree", path, base.key_line("tree"))
        tree_types |= base_types
    supervisor = load_supervisor(doc.get("supervisor"), path, {r.name: r.breadcrumbs for r in robots})
    faults = load_faults(doc.get("faults"), FaultContext(path, {r.name: r for r in robots}, robot_types, backend,
                                                         base_tree is not None))
    values = {k: doc.get(k, v) for k, v in DEFAULTS.items()}
    _check_steps(doc, path, float(values["duration_s"]), float(values["dt_s"]))
    warn_late_events(doc, path, float(values["duration_s"]))
    backend.check(doc, path, base_tree is not None)
    if base_tree is None and "team" not in doc:
        _check_hub_needed(doc, path, robots, robot_types)
    team = _team(doc, path, tree_types)
    artifacts = _artifacts(doc, path, backend, tree_types)
    if team.strategy.NEEDS_BASE_TREE and base_tree is None:
        name = next(n for n, s in TEAM_STRATEGIES.items() if s is team.strategy)
        raise DelveError(f"team strategy {name!r} needs a base station tree (base_station: tree: ...)", path,
                         doc.key_line("team"))
    problem = team.strategy.base_tree_problem(base_types) if base_tree is not None else None
    if problem:
        raise DelveError(problem, path, base.key_line("tree"))
    return Scenario(path=path, name=doc["name"], seed=int(values["seed"]), duration_s=float(values["duration_s"]),
                    dt_s=float(values["dt_s"]), coverage_period_s=float(values["coverage_period_s"]),
                    world=plain(doc["world"]), robots=robots, base_tree=base_tree,
                    base_position=base.get("position"), base_tick_hz=float(base.get("tick_hz", 1.0)),
                    radio=plain(doc.get("radio", {})), doc=doc, world_backend=backend, team=team, supervisor=supervisor,
                    faults=faults, include_path=include_path, artifacts=artifacts)
