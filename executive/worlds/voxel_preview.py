"""Pictures of a voxel world before a run (``delve world SCENARIO --preview DIR``): a
top-down and a side view of its free space, coloured by free region, with each
robot's start and where it landed."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from ...sim.world import World  # noqa: E402
from .height_bands import ALL_HEIGHTS, HeightBand, height_bands  # noqa: E402

if TYPE_CHECKING:
    from ..scenario import Scenario
    from .voxel_check import StartPlacement

#: Colours: the largest free region, the other free regions, rock and outside.
MAIN_RGB = (0.62, 0.79, 0.93)
OTHER_RGB = (0.98, 0.66, 0.35)
ROCK_RGB = (0.93, 0.93, 0.93)
#: The longer side of a picture (inches) and its limits on the shorter one.
FIGURE_IN = 10.0
MIN_SIDE_IN = 3.0
#: A side view flatter than this (height / length) is stretched upwards to it, at most MAX_STRETCH times.
FLAT_VIEW = 0.2
MAX_STRETCH = 10


def draw_preview(scenario: "Scenario", world: World, starts: list["StartPlacement"], out: Path) -> list[Path]:
    """Write ``top.png`` (looking down; one view per level, the lowest first, on a world of
    several: :func:`height_bands`) and ``side.png`` (looking along +y) into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    labels, sizes = world.free_regions()
    main = labels == int(np.argmax(sizes)) if sizes.any() else np.zeros(world.shape, bool)
    other = (labels > 0) & ~main
    n_regions = int(np.count_nonzero(sizes))
    bands = height_bands(world.free, float(world.origin[2]), world.voxel_size_m)
    paths = []
    for name, (a, b), flat in (("top", (0, 1), 2), ("side", (0, 2), 1)):
        lo, hi = world.bounds_min, world.bounds_max
        extent = (lo[a], hi[a], lo[b], hi[b])
        w, h = hi[a] - lo[a], hi[b] - lo[b]
        stretch = 1 if name == "top" or h >= FLAT_VIEW * w else min(int(round(FLAT_VIEW * w / h)), MAX_STRETCH)
        views = bands if name == "top" else [ALL_HEIGHTS]
        fw, fh = _figsize(w, h * stretch)
        fig, axes = plt.subplots(len(views), 1, figsize=(fw, fh * len(views)), squeeze=False)
        for ax, band in zip(axes[:, 0], views):
            at = band.layers(float(world.origin[2]), world.voxel_size_m, world.shape[2])
            img = np.empty((world.shape[a], world.shape[b], 3))
            img[:] = ROCK_RGB
            img[other[..., at].any(axis=flat)] = OTHER_RGB
            img[main[..., at].any(axis=flat)] = MAIN_RGB
            ax.imshow(np.transpose(img, (1, 0, 2)), origin="lower", extent=extent, interpolation="nearest",
                      aspect=stretch)
            handles = [Patch(color=MAIN_RGB, label="free space (largest region)"),
                       Patch(color=ROCK_RGB, label="rock / outside")]
            if other.any():
                handles.insert(1, Patch(color=OTHER_RGB, label=f"other free regions ({n_regions - 1})"))
            if name == "side" and world.source is not None and world.source.ceiling_z is not None:
                ax.axhline(world.source.ceiling_z, color="0.4", ls="--", lw=1)
                handles.append(Line2D([], [], color="0.4", ls="--", label="ceiling added"))
            handles += _draw_starts(ax, world, starts, scenario, (a, b), band)
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)" if name == "top" else "z (m, up)")
            view = "top view" if name == "top" else "side view (looking along +y" + (
                f", heights stretched ×{stretch})" if stretch > 1 else ")")
            if len(views) > 1:
                view += f", level {views.index(band) + 1} of {len(views)}: {band.label}"
            ax.set_title(f"{scenario.name}: {view}\nfree {world.free_volume_m3:.0f} m³ in {n_regions} region(s), "
                         f"voxels of {world.voxel_size_m:g} m", fontsize=10)
            ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
        fig.tight_layout()
        path = out / f"{name}.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        paths.append(path)
    return paths


def _figsize(w: float, h: float) -> tuple[float, float]:
    """Figure inches for a w x h view: the longer side FIGURE_IN, room for the legend."""
    if w >= h:
        fw, fh = FIGURE_IN, max(FIGURE_IN * h / max(w, 1e-9), MIN_SIDE_IN)
    else:
        fw, fh = max(FIGURE_IN * w / max(h, 1e-9), MIN_SIDE_IN), FIGURE_IN
    return fw + 3.0, fh + 1.2


def _draw_starts(ax, world: World, starts: list["StartPlacement"], scenario: "Scenario",
                 axes: tuple[int, int], band: HeightBand) -> list:
    """Mark each start at ``band``'s heights (green: stands as given; orange: moved down onto
    the floor; red cross: an error, with the nearest free floor); the base station as a
    triangle."""
    a, b = axes
    seen: dict[str, Line2D] = {}
    named: list[tuple[np.ndarray, int]] = []   # each name's point and row
    # Names of starts closer than this (6 % of the view) go one above the other, with a line.
    near_m = 0.06 * float(max(world.free.shape[a], world.free.shape[b]) * world.voxel_size_m)

    def mark(p, style, label, **kw):
        (h,) = ax.plot(p[a], p[b], style, ms=kw.pop("ms", 9), label=label, **kw)
        seen.setdefault(label, h)

    def name(p, text, **kw):
        q = np.array([p[a], p[b]], float)
        row = max((k + 1 for r, k in named if np.linalg.norm(q - r) < near_m), default=0)
        named.append((q, row))
        line = dict(arrowstyle="-", lw=0.6, color="0.3", shrinkA=0, shrinkB=4) if row else None
        ax.annotate(text, tuple(q), xytext=(6, 6 + 11 * row), textcoords="offset points", fontsize=8,
                    arrowprops=line, **kw)

    for s in starts:
        ld = s.landing
        if not band.holds(ld.given if ld.problem else ld.start).all():
            continue
        if ld.problem:
            mark(ld.given, "x", "start that is an error", color="red", mew=2.5)
            floor = world.nearest_floor(ld.given)
            if floor is not None:
                ax.plot([ld.given[a], floor[a]], [ld.given[b], floor[b]], ":", color="red", lw=1.2)
                mark(floor, "P", "nearest free floor", color="green", mec="white")
            name(ld.given, s.name, color="red")
            continue
        if ld.moved_m > 0:
            ax.annotate("", xy=(ld.start[a], ld.start[b]), xytext=(ld.given[a], ld.given[b]),
                        arrowprops=dict(arrowstyle="->", color="darkorange", lw=1.5))
            mark(ld.start, "o", "start moved onto the floor", color="darkorange", mec="black")
        else:
            mark(ld.start, "o", "start", color="limegreen", mec="black")
        name(ld.start, s.name)
    if scenario.base_position is not None and band.holds(scenario.base_position).all():
        mark(np.asarray(scenario.base_position, float), "^", "base station", color="black")
    return list(seen.values())
