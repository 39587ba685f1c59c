"""delve.skills: the py_trees behaviours that YAML trees name by ``type``.

Imports ``delve.planners`` only; reaches robots only through :mod:`.robot`.
"""

from __future__ import annotations

import importlib
import pkgutil

from .base import Skill

__all__ = ["Skill", "all_skills"]


def _subclasses(cls: type) -> list[type]:
    out = []
    for sub in cls.__subclasses__():
        out.append(sub)
        out.extend(_subclasses(sub))
    return out


def all_skills() -> dict[str, type]:
    """Every concrete behaviour class defined in this package, by its YAML ``type`` name.


    A class is concrete when it sets ``ABSTRACT = False`` (the default); its YAML
    name is its ``TYPE_NAME`` attribute, or its class name.
    """
    for mod in pkgutil.iter_modules(__path__):
        if not mod.name.startswith("_"):
            importlib.import_module(f"{__name__}.{mod.name}")
    found: dict[str, type] = {}
    for cls in _subclasses(Skill):
        if cls.__dict__.get("ABSTRACT", False) or not cls.__module__.startswith(f"{__name__}."):
            continue  # abstract, or defined elsewhere (a test's or a user's own registry)
        found[getattr(cls, "TYPE_NAME", cls.__name__)] = cls
    return found
