"""World backends: one per kind of world, behind :class:`WorldBackend`.

A scenario's ``world:`` mapping picks the backend that claims it. A new kind of
world is a module here (or anywhere) that subclasses :class:`WorldBackend` and calls
:func:`register_world`; the runner needs no change (see docs/extending.md).
"""
from __future__ import annotations

from typing import Any, Mapping

from .base import BASE, Coverage, TeamNetwork, WorldBackend
from .graph import GraphBackend
from .voxel import VoxelBackend

#: The registered backends by name, in the order they are asked to claim a world.
WORLD_BACKENDS: dict[str, type[WorldBackend]] = {}


def register_world(name: str, backend: type[WorldBackend]) -> None:
    """Make ``backend`` available to scenarios (a later name replaces an earlier one)."""
    WORLD_BACKENDS[name] = backend


def backend_for(world: Mapping[str, Any]) -> type[WorldBackend] | None:
    """The backend that claims a scenario's ``world:`` mapping, or None."""
    return next((b for b in WORLD_BACKENDS.values() if b.claims(world)), None)


def generator_names() -> list[str]:
    """Every world generator a scenario may name, over all backends."""
    return [name for b in WORLD_BACKENDS.values() for name in b.generators()]


register_world("voxel", VoxelBackend)
register_world("graph", GraphBackend)

__all__ = ["BASE", "Coverage", "TeamNetwork", "WorldBackend", "WORLD_BACKENDS", "backend_for", "generator_names",
           "register_world"]
