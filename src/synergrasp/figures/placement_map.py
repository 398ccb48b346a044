"""The placement map of one object: the search's score over its targets, the chosen target
marked, and grasps at the chosen target drawn as in Fig. 2 (docs/placement_search.md).
mm, palm frame."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from synergrasp.figures.fig1_fig2_postures_grasps import GRASP_VIEWS, draw_grasp_row
from synergrasp.figures.output import save_figure

__all__ = ["figure_placement_map"]


def _palm_outline(hand: Any) -> tuple[float, float, float, float]:
    """(y0, y1, z0, z1) of the palm's bounding box seen along the palm normal, mm."""
    from synergrasp.simulation.capsules import HandCapsules

    caps = HandCapsules.of(hand)
    lo = np.min(caps.palm_centre - np.abs(caps.palm_half @ np.abs(caps.palm_rotation[0]).T), axis=0)
    hi = np.max(caps.palm_centre + np.abs(caps.palm_half @ np.abs(caps.palm_rotation[0]).T), axis=0)
    return float(lo[1]), float(hi[1]), float(lo[2]), float(hi[2])


def _level_panel(
    ax: Any,
    level: pd.DataFrame,
    spacing_mm: float,
    outline: tuple[float, float, float, float],
    limits: tuple[float, float, float, float],
) -> None:
    from matplotlib.patches import Rectangle

    half = spacing_mm / 2.0
    for _, row in level.iterrows():
        colour = image_colour(row["typed_percent"])
        ax.add_patch(
            Rectangle(
                (row["y_mm"] - half, row["z_mm"] - half),
                spacing_mm,
                spacing_mm,
                facecolor=colour,
                edgecolor="white",
                linewidth=0.4,
            )
        )
    y0, y1, z0, z1 = outline
    ax.add_patch(Rectangle((y0, z0), y1 - y0, z1 - z0, fill=False, edgecolor="0.3", linewidth=1.0, linestyle="--"))
    ax.text(
        max(y0, limits[0]) + 2, max(z0, limits[2]) + 2, "palm", fontsize=6, color="0.3", va="bottom", clip_on=True
    )  # inside the panel where the palm reaches beyond the targets
    for _, row in level[level["distinct_rank"].between(1, 3)].iterrows():
        k = int(row["distinct_rank"])
        ax.plot(
            row["y_mm"],
            row["z_mm"],
            marker="*" if k == 1 else "o",
            ms=13 if k == 1 else 7,
            mfc="#c2000b" if k == 1 else "none",
            mec="#c2000b" if k == 1 else "black",
            mew=1.2,
        )
        if k > 1:
            ax.text(row["y_mm"] + 3, row["z_mm"] + 3, str(k), fontsize=7)
    ax.set_xlim(limits[0], limits[1])
    ax.set_ylim(limits[2], limits[3])
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)


def image_colour(percent: float) -> Any:
    """The map's colour of a share of scored poses (%)."""
    import matplotlib

    return matplotlib.colormaps["viridis"](float(percent) / 100.0)


def figure_placement_map(
    hand: Any,
    obj: Any,
    placement: pd.DataFrame,
    contacts: pd.DataFrame,
    spacing_mm: float,
    png_path: str | Path,
    pdf_path: str | Path,
    n_grasps: int = 2,
    oppositions: Mapping[int, str] | None = None,
) -> None:
    """The placement map of ``obj`` (a ``synergrasp.simulation.objects.GraspedObject``): one panel per
    distance x of the targets from the palm
    (palm frame, mm): every scored target as a square coloured by the search's score T (the
    share of scored poses whose grasp is of the object's type and in force closure with the
    full synergy set), the chosen target a red star, the second and third distinct targets
    circles; the palm's outline dashed. Below, ``n_grasps`` representative grasps of
    ``contacts`` (the object's closure at the chosen target) from the palm side and from
    above the fingertips, as in Fig. 2, titled with their opposition (``oppositions``: pose
    -> class)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    levels = sorted(placement["x_mm"].unique())
    chosen = placement[placement["chosen"]].iloc[0]
    half = spacing_mm / 2.0
    limits = (
        placement["y_mm"].min() - half - 2,
        placement["y_mm"].max() + half + 2,
        placement["z_mm"].min() - half - 2,
        placement["z_mm"].max() + half + 2,
    )
    outline = _palm_outline(hand)
    views = len(GRASP_VIEWS)
    fig = plt.figure(figsize=(max(2.2 * len(levels) + 1.0, 2.6 * n_grasps * views), 8.8))
    grid = fig.add_gridspec(2, 1, height_ratios=(1.1, 1.0), hspace=0.25)
    top, bottom = grid[0].subgridspec(1, len(levels)), grid[1].subgridspec(1, n_grasps * views)
    for i, x in enumerate(levels):
        ax = fig.add_subplot(top[0, i])
        _level_panel(ax, placement[np.isclose(placement["x_mm"], x)], spacing_mm, outline, limits)
        ax.set_title(f"x = {x:g} mm", fontsize=8)
        ax.set_xlabel("y (mm, thumb side +)", fontsize=7)
        if i == 0:
            ax.set_ylabel("z (mm, along the fingers)", fontsize=7)
    bar = fig.colorbar(ScalarMappable(Normalize(0, 100), "viridis"), ax=list(fig.axes), fraction=0.02, pad=0.01)
    bar.set_label(f"{chosen['grasp_type']} grasps in force closure (full set), % of scored poses", fontsize=7)
    bar.ax.tick_params(labelsize=7)
    grasp_axes = [fig.add_subplot(bottom[0, c]) for c in range(n_grasps * views)]
    draw_grasp_row(grasp_axes, hand, obj, contacts, tuple(c for _, c in GRASP_VIEWS), oppositions)
    fig.suptitle(
        f"{obj.name} ({chosen['grasp_type']}): chosen target ({chosen['x_mm']:g}, {chosen['y_mm']:g}, "
        f"{chosen['z_mm']:g}) mm,\n{chosen['typed_percent']:.0f} % {chosen['grasp_type']} grasps in force "
        f"closure ({chosen['force_closure_percent']:.0f} % force closure of any kind), median force "
        f"{chosen['median_force_per_weight']:.2g} × weight, {len(placement)} targets scored on "
        f"{int(chosen['n_poses'])} poses; grasps at it below",
        fontsize=9,
    )
    save_figure(fig, png_path, pdf_path)
