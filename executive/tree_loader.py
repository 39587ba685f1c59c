"""YAML tree files -> py_trees behaviour trees.

A tree file's top-level mapping is the root node. A node is either a typed node::

    type: Sequence            # a name from the registry (delve.executive.registry)
    name: Explore then home   # optional, default: the type
    memory: true              # parameters as sibling keys (units in names: timeout_s)
    children:                 # composites and many-child idioms
      - type: ExploreGBPlanner2
      - type: Timeout         # decorators take `child:` (or `children:` with one node)
        duration_s: 600
        child: {type: Home}

or an include of another file, its root renamed and blackboard keys remapped::

    include: subtrees/return_home.yaml    # relative to this file
    remap: {goal: home_pose}              # key in the subtree -> key here
    name: Go home                         # optional

Includes nest, remaps compose, and include cycles are reported with their chain.
An include resolves (symbolic links followed) only inside the folder of the tree being
loaded and its sub-folders, the shipped trees, and the folders the user names
(``include_path``, the command line's ``--include-path``); anything else is refused
before the file is opened. A tree nests at most :data:`MAX_TREE_DEPTH` nodes deep.
Every mistake raises :class:`~delve.executive.errors.DelveError` with the file, line
and node; it quotes at most a few dozen characters of a value.
"""
from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from typing import Any

from py_trees.behaviour import Behaviour

from .. import TREES_DIR
from ..skills.base import KEY_PATTERN, KEY_RULE, AgentContext, Skill, short_repr
from .document_kind import scenario_keys
from .errors import DelveError, clip_message, did_you_mean, display_path
from .registry import Build, NodeType, Registry, Site, coerce_param, default_registry
from .yamlio import YamlDict, YamlList, file_problem, line_of, line_of_key_named, load_yaml

__all__ = ["MAX_TREE_DEPTH", "allowed_include_roots", "build_tree", "check_context", "check_tree", "compose_remap",
           "load_tree", "path_inside"]

_INCLUDE_KEYS = ("include", "remap", "name")
#: Deepest a tree may nest, nodes within nodes, includes counted (the shipped trees
#: nest 9 deep); deeper trees are a mistake (a runaway generator) and would exhaust
#: Python's stack when built, ticked or drawn.
MAX_TREE_DEPTH = 100
#: How much of a builder's own explanation an error repeats.
_BUILD_ERROR_CHARS = 160


def compose_remap(inner: Mapping[str, str] | None, outer: Mapping[str, str] | None) -> dict[str, str]:
    """The remap of a subtree included with ``inner`` into a tree that is itself
    remapped with ``outer``: a subtree key goes through ``inner``, then ``outer``."""
    composed = dict(outer or {})
    for key, value in (inner or {}).items():
        composed[key] = (outer or {}).get(value, value)
    return composed


def _kind(value: Any) -> str:
    if isinstance(value, list):
        return "a list"
    return "a string" if isinstance(value, str) else f"a value of type {type(value).__name__}"


def _describe(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, str):
        return f"the string {short_repr(value)}"
    return f"{type(value).__name__} {short_repr(value)}"


def allowed_include_roots(tree_file: str | os.PathLike[str] | None,
                          include_path: Iterable[str | os.PathLike[str]] = ()) -> tuple[str, ...]:
    """The folders an include of the tree ``tree_file`` may resolve into, symbolic links
    resolved: the tree's own folder, the shipped trees and ``include_path``."""
    own = os.path.dirname(os.path.realpath(tree_file)) if tree_file is not None else os.getcwd()
    roots = [own, os.path.realpath(TREES_DIR), *(os.path.realpath(p) for p in include_path)]
    return tuple(dict.fromkeys(roots))


def path_inside(path: str, root: str) -> bool:
    """Whether the real path ``path`` lies in the folder ``root`` (also real)."""
    try:
        return os.path.commonpath([path, root]) == root
    except ValueError:  # another drive on Windows
        return False


class _ZeroClock:
    """The clock of :func:`check_tree`'s dummy agent: time stands still at 0."""

    now_s = 0.0


def check_context() -> AgentContext:
    """A dummy agent context to build trees with for checking (no robot, no log)."""
    return AgentContext(name="check", namespace="/__check__", clock=_ZeroClock(), log=lambda *args, **fields: None)


class _RemapFrame:
    """An include being built: its remap, and the keys its subtree's nodes name (in
    the naming of the including file's include, before the remap applies)."""

    def __init__(self, remap: dict[str, str]):
        self.remap = remap
        self.named: set[str] = set()


class _TreeBuilder:
    def __init__(self, ctx: AgentContext, registry: Registry, root_file: str | None,
                 include_path: Iterable[str | os.PathLike[str]] = ()):
        self.ctx = ctx
        self.registry = registry
        self.root_dir = os.path.dirname(os.path.realpath(root_file)) if root_file else os.getcwd()
        self.roots = allowed_include_roots(root_file, include_path)
        #: Where a relative include not found beside its file is looked for next, in order.
        self.search = tuple(dict.fromkeys([*(os.path.realpath(p) for p in include_path),
                                           os.path.realpath(TREES_DIR)]))
        self.depth = 0
        self.frames: list[_RemapFrame] = []

    # ---------------------------------------------------------------- files
    def _find(self, base: str, target: str) -> str:
        """The file an include names: ``target`` beside the including file, or, when it is
        not there and is relative, in the first of :attr:`search` that holds it (so a
        shipped tree copied elsewhere still finds the shipped subtrees)."""
        path = os.path.normpath(os.path.join(base, target))
        if os.path.isabs(target) or os.path.exists(path):
            return path
        for root in self.search:
            found = os.path.normpath(os.path.join(root, target))
            if path_inside(os.path.realpath(found), root) and os.path.isfile(found):
                return found
        return path


    def chain_name(self, real: str) -> str:
        rel = os.path.relpath(real, self.root_dir)
        return real if rel.startswith(os.pardir) else rel

    def file(self, path: str, remap: dict[str, str], chain: tuple[str, ...], site: Site | None = None) -> Behaviour:
        data = load_yaml(path)
        if data is None:
            raise DelveError("empty tree file: its top-level mapping must be the root node", path, 1)
        if not isinstance(data, Mapping):  # said without quoting it: this may be any text file
            raise DelveError(f"a tree file's top level must be a mapping (the root node), not {_kind(data)}: "
                             "is it a tree file?", path, line_of(data, 1))
        self.not_a_scenario(data, path, site)
        return self.node(data, path, 1, remap, chain)

    @staticmethod
    def not_a_scenario(data: Any, path: str, site: Site | None) -> None:
        """A DelveError when the tree file ``path`` holds a scenario (at the include
        that names it, if any)."""
        if not isinstance(data, Mapping) or "type" in data or "include" in data:
            return
        keys = scenario_keys(data)
        if not keys:
            return
        what = f"{os.path.basename(path)} is a scenario, not a tree (it has {', '.join(map(repr, keys[:3]))})"
        if site is not None:
            site.fail(f"include {short_repr(site.node['include'])}: {what}", "include")
        line = data.key_line(keys[0]) if isinstance(data, YamlDict) else 1
        raise DelveError(f"{what}: name a tree file, or validate or run the scenario", path, line)

    # ---------------------------------------------------------------- nodes

    def node(self, data: Any, file: str | None, line: int | None, remap: dict[str, str], chain: tuple[str, ...]) -> Behaviour:
        if not isinstance(data, Mapping):
            raise DelveError(
                f"a tree node must be a mapping with 'type' (or 'include'), not {_describe(data)}",
                file,
                line_of(data, line),
            )
        line = line_of(data, line)
        self.depth += 1
        try:
            if self.depth > MAX_TREE_DEPTH:
                name = data.get("name")
                raise DelveError(f"the tree nests more than {MAX_TREE_DEPTH} nodes deep (includes counted)", file, line,
                                 name if isinstance(name, str) else None)
            if "include" in data:
                return self.include(data, file, line, remap, chain)
            return self.typed(data, file, line, remap, chain)
        finally:
            self.depth -= 1

    def include(self, data: Mapping[str, Any], file: str | None, line: int | None, remap: dict[str, str], chain: tuple[str, ...]) -> Behaviour:
        site = Site(file, data, None, line)
        name = data.get("name")
        if name is not None and (not isinstance(name, str) or not name):
            site.fail(f"'name' must be a non-empty string, not {_describe(name)}", "name")
        site.node_name = name
        for key in data:
            if key not in _INCLUDE_KEYS:
                hint = did_you_mean(str(key), _INCLUDE_KEYS)
                if key == "type":
                    hint = " (a node is either an include or a typed node, not both)"
                site.fail(f"unknown key {short_repr(key)} in an include{hint}", key)
        target = data["include"]
        if not isinstance(target, str) or not target or "\0" in target:
            site.fail(f"'include' must be a path (a string without NUL bytes), not {_describe(target)}", "include")
        inner = data.get("remap") or {}
        if not isinstance(inner, Mapping):
            site.fail(f"'remap' must be a mapping of subtree key -> key, not {_describe(inner)}", "remap")
        for key, value in inner.items():
            line_hint = inner.key_line(key) if isinstance(inner, YamlDict) else None
            if not isinstance(key, str) or not key or not isinstance(value, str) or not value:
                raise DelveError(
                    f"remap entries must map a key name to a key name, not {short_repr(key)}: {short_repr(value)}",
                    file,
                    line_hint or site.line_of("remap"),
                    name,
                )
            for what, text in (("key", key), ("value", value)):
                if not KEY_PATTERN.fullmatch(text):
                    raise DelveError(f"remap {what} {short_repr(text)} is not a blackboard key ({KEY_RULE})", file,
                                     line_hint or site.line_of("remap"), name)
        base = os.path.dirname(file) if file else ""
        path = self._find(base, target)
        real = os.path.realpath(path)
        if not any(path_inside(real, root) for root in self.roots):
            folders = ", ".join([f"the tree's folder {os.path.join(display_path(self.roots[0]), '')}",
                                 "the shipped trees", *(display_path(r) for r in self.roots[2:])])
            site.fail(f"include {short_repr(target)} is outside the allowed folders ({folders}; add --include-path)",
                      "include")
        if real in chain:
            names = [self.chain_name(p) for p in chain[chain.index(real):]] + [self.chain_name(real)]
            site.fail(f"include cycle: {' -> '.join(names)}", "include")
        problem = file_problem(path)
        if problem:
            site.fail(f"included file {problem}: {short_repr(target)} (relative to {display_path(base or '.')}, "
                      "the --include-path folders and the shipped trees)", "include")
        frame = _RemapFrame(dict(inner))
        self.frames.append(frame)
        try:
            root = self.file(path, compose_remap(inner, remap), (*chain, real), site)
        finally:
            self.frames.pop()
        for key in inner:
            if key not in frame.named:
                line_hint = inner.key_line(key) if isinstance(inner, YamlDict) else None
                raise DelveError(f"remap {short_repr(key)}: no node of {short_repr(target)} names that key"
                                 f"{did_you_mean(key, sorted(frame.named))}", file,
                                 line_hint or site.line_of("remap"), name)
        if name is not None:
            root.name = name
        return root

    def note_keys(self, node_type: NodeType, params: Mapping[str, Any], built: Behaviour) -> None:
        """Record the blackboard keys a node names (in its own file) with every
        include it lies in, each in the naming of that include's file."""
        if not self.frames:
            return
        keys = {value for pname, value in params.items()
                if node_type.params[pname].key and isinstance(value, str)}
        if isinstance(built, Skill):
            ports = {**built.INPUT_PORTS, **built.OUTPUT_PORTS}
            keys |= {k for k in (built.port_key(p) for p in ports) if k}
        for frame in reversed(self.frames):
            named = keys | {k.split(".", 1)[0] for k in keys}
            frame.named |= named
            keys = {frame.remap.get(k) or (frame.remap[k.split(".", 1)[0]] + "." + k.split(".", 1)[1]
                                           if "." in k and k.split(".", 1)[0] in frame.remap else k)
                    for k in keys}

    def typed(self, data: Mapping[str, Any], file: str | None, line: int | None, remap: dict[str, str], chain: tuple[str, ...]) -> Behaviour:
        site = Site(file, data, None, line)
        explicit_name = data.get("name")
        if isinstance(explicit_name, str) and explicit_name:
            site.node_name = explicit_name
        if "type" not in data:
            close = [k for k in data if isinstance(k, str) and did_you_mean(k, ("type", "include"))]
            hint = f" ({short_repr(close[0])} is not 'type' or 'include')" if close else ""
            site.fail(f"node has no 'type' (or 'include'){hint}")
        type_name = data["type"]
        if not isinstance(type_name, str):
            site.fail(f"'type' must be a string, not {_describe(type_name)}", "type")
        node_type = self.registry.get(type_name)
        if node_type is None:
            site.fail(f"unknown behaviour type {short_repr(type_name)}{self.registry.suggest(type_name)}", "type")
        if explicit_name is not None and (not isinstance(explicit_name, str) or not explicit_name):
            site.fail(f"'name' must be a non-empty string, not {_describe(explicit_name)}", "name")
        name = explicit_name or type_name
        site.node_name = name

        params, given = self.params(node_type, data, site)
        children = self.children(node_type, data, site, remap, chain)
        subtrees = {}
        for slot in node_type.subtrees:
            if slot not in data:
                site.fail(f"{node_type.kind} {type_name!r} needs a '{slot}' subtree")
            subtrees[slot] = self.node(data[slot], file, site.line_of(slot), remap, chain)

        build = Build(
            name=name,
            params=params,
            children=children,
            ctx=self.ctx,
            remap=dict(remap),
            subtrees=subtrees,
            given=frozenset(given),
            site=site,
        )
        try:
            built = node_type.build(build)
            self.note_keys(node_type, params, built)
            return built
        except DelveError:
            raise
        except (ValueError, TypeError) as err:  # the builder refused the checked parameters
            raise DelveError(f"cannot build {type_name!r}: {clip_message(err, _BUILD_ERROR_CHARS)}", file,
                             line_of_key_named(data, str(err)) or site.line, site.node_name) from None

    def params(self, node_type: NodeType, data: Mapping[str, Any], site: Site) -> tuple[dict[str, Any], list[str]]:
        structural = {"type", "name", *node_type.subtrees}
        if node_type.arity != "none":
            structural |= {"children", "child"}
        else:
            for key in ("children", "child"):
                if key in data:
                    site.fail(f"{node_type.kind} {node_type.name!r} takes no children", key)
        given = [k for k in data if k not in structural]
        for key in given:
            if key not in node_type.params:
                known = [*node_type.params, *sorted(structural - {"type"})]
                site.fail(f"unknown parameter {short_repr(key)} for {node_type.name!r}{did_you_mean(str(key), known)}",
                          key)
        values: dict[str, Any] = {}
        missing = []
        for pname, spec in node_type.params.items():
            if pname in data:
                value = data[pname]
                problem = spec.problem(value)
                if problem is None and spec.key and value is not None and not value.strip():
                    problem = "must be a blackboard key name, not an empty string"
                if problem is not None:
                    site.fail(f"parameter {pname!r} {problem}", pname)
                values[pname] = coerce_param(spec, value)
            elif spec.required:
                missing.append(pname)
            else:
                values[pname] = coerce_param(spec, spec.default)
        if missing:
            names = ", ".join(repr(m) for m in missing)
            plural = "s" if len(missing) > 1 else ""
            site.fail(f"missing required parameter{plural} {names} for {node_type.name!r}")
        return values, given

    def children(self, node_type: NodeType, data: Mapping[str, Any], site: Site, remap: dict[str, str], chain: tuple[str, ...]) -> list[Behaviour]:
        what = f"{node_type.kind} {node_type.name!r}"
        if node_type.arity == "none":
            return []
        has_child, has_children = "child" in data, "children" in data
        if has_child and has_children:
            site.fail(f"{what} takes 'child' or 'children', not both", "child")
        if has_child:
            if node_type.arity == "many":
                site.fail(f"{what} takes 'children' (a list of nodes), not 'child'", "child")
            return [self.node(data["child"], site.file, site.line_of("child"), remap, chain)]
        if not has_children:
            need = "exactly one child ('child')" if node_type.arity == "one" else "at least one child ('children')"
            site.fail(f"{what} needs {need}")
        items = data["children"]
        if not isinstance(items, list):
            site.fail(f"'children' must be a list of nodes, not {_describe(items)}", "children")
        if node_type.arity == "one" and len(items) != 1:
            site.fail(f"{what} needs exactly one child, got {len(items)}", "children")
        if not items:
            site.fail(f"{what} needs at least one child, got none", "children")
        out = []
        for index, item in enumerate(items):
            item_line = items.item_line(index) if isinstance(items, YamlList) else site.line_of("children")
            out.append(self.node(item, site.file, item_line, remap, chain))
        return out


def build_tree(
    data: Mapping[str, Any],
    ctx: AgentContext,
    *,
    file: str | os.PathLike[str] | None = None,
    remap: Mapping[str, str] | None = None,
    registry: Registry | None = None,
    include_path: Iterable[str | os.PathLike[str]] = (),
) -> Behaviour:
    """Build the tree whose root node is ``data`` (already parsed, e.g. a tree written
    inline in a scenario); includes resolve relative to ``file``'s directory, and
    inside it, the shipped trees or ``include_path``."""
    file_text = os.fspath(file) if file is not None else None
    builder = _TreeBuilder(ctx, registry or default_registry(), file_text, include_path)
    chain = (os.path.realpath(file_text),) if file_text else ()
    return builder.node(data, file_text, line_of(data, 1), dict(remap or {}), chain)


def load_tree(
    path: str | os.PathLike[str],
    ctx: AgentContext,
    *,
    remap: Mapping[str, str] | None = None,
    registry: Registry | None = None,
    include_path: Iterable[str | os.PathLike[str]] = (),
) -> Behaviour:
    """Build the py_trees tree of the YAML file at ``path`` for the agent ``ctx``.

    ``remap`` renames blackboard keys of the whole tree (as an include's remap does).
    Includes may resolve inside the tree's folder, the shipped trees and the folders
    of ``include_path``.

    Raises:
        DelveError: any mistake in the file or the files it includes.
    """
    file_text = os.fspath(path)
    builder = _TreeBuilder(ctx, registry or default_registry(), file_text, include_path)
    return builder.file(file_text, dict(remap or {}), (os.path.realpath(file_text),))


def _release_blackboard(root: Behaviour) -> None:
    """Unregister the blackboard clients of a tree built only to be checked."""
    stack = [root]
    while stack:
        node = stack.pop()
        stack.extend(node.children)
        condition = getattr(node, "condition_subtree", None)
        if isinstance(condition, Behaviour):
            stack.append(condition)
        for client in node.blackboards:
            try:
                client.unregister(clear=False)
            except KeyError:
                pass


def check_tree(path: str | os.PathLike[str], *, registry: Registry | None = None,
               include_path: Iterable[str | os.PathLike[str]] = ()) -> set[type]:
    """Check the YAML tree at ``path`` by building it for a dummy agent; return the
    classes of its nodes.

    Raises:
        DelveError: the first mistake found, with its file, line and node.
    """
    root = load_tree(path, check_context(), registry=registry, include_path=include_path)
    _release_blackboard(root)
    return {type(node) for node in root.iterate()}
