"""Figures of the study drawn from its tables: Fig. 4 (force maps and exploded views), Fig. 5
(hierarchy matrices). Fig. 3, the rule graph, is `synergrasp.figures.fig3_rulegraph`.

Every figure function takes tables (pandas) and output paths, and writes PNG and PDF.
Forces are in N; angles in deg.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless: figures are files, never windows
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from synergrasp.analysis.verdicts import force_bound  # noqa: E402
from synergrasp.figures.output import colour_range, save_figure  # noqa: E402
from synergrasp.ids import incremental_set_id  # noqa: E402

__all__ = [
    "Fig4Params",
    "Fig5Params",
    "force_grid",
    "figure_force_maps",
    "figure_exploded_views",
    "figure_hierarchy",
    "FIG5B_RATIO_RANGE",
]


@dataclass(frozen=True)
class Fig4Params:
    """Fig. 4 of one object (the ``fig4`` step): the success verdict, the k of the
    incremental sets drawn, the α and β (deg) of the exploded views' slices and, for
    ``force_closure_bounded``, the object's weight (N) and the bound's multiple of it."""

    success: str
    panel_k: tuple[int, ...]
    alpha_slice_deg: float
    beta_slice_deg: float
    weight_N: float | None = None
    bound_multiple: float = math.inf

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> Fig4Params:
        fig4 = config["analyses"]["fig4"]
        return cls(
            config["analyses"]["success"],
            tuple(fig4["panel_k"]),
            fig4["alpha_slice_deg"],
            fig4["beta_slice_deg"],
            **force_bound(config, obj),
        )


@dataclass(frozen=True)
class Fig5Params:
    """Fig. 5 (the ``fig5`` step): the success verdict and S1..S_first of the hierarchy sets."""

    success: str
    hierarchy_first: int

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> Fig5Params:
        return cls(config["analyses"]["success"], config["synergy_sets"]["hierarchy_first"])


def force_grid(gfo: pd.DataFrame, set_id: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Optimal force of one synergy set on the (β, α) grid.

    ``gfo`` carries the columns of :func:`synergrasp.analysis.verdicts.with_verdicts`.
    Returns ``(alpha_deg, beta_deg, force)`` with ``force[i_beta, i_alpha]`` in N, NaN
    where the pose is not a success of the chosen verdict.
    """
    rows = gfo[gfo["set_id"] == set_id]
    alphas = np.sort(gfo["alpha_deg"].unique())
    betas = np.sort(gfo["beta_deg"].unique())
    force = np.full((betas.size, alphas.size), np.nan)
    fc = rows[rows["success"]]
    ia = np.searchsorted(alphas, fc["alpha_deg"].to_numpy())
    ib = np.searchsorted(betas, fc["beta_deg"].to_numpy())
    force[ib, ia] = fc["success_force"].to_numpy()
    return alphas, betas, force


def _set_label(k: int) -> str:
    return "{S1}" if k == 1 else f"{{S1..S{k}}}"


def _verdict_label(verdict: str) -> str:
    return verdict.replace("_", "-")


def figure_force_maps(
    gfo: pd.DataFrame,
    minima: pd.DataFrame,
    panel_k: Sequence[int],
    object_name: str,
    png: str | Path,
    pdf: str | Path,
    verdict: str = "force_closure",
) -> None:
    """Fig. 4 (maps): log10 of the optimal force (N) over (α, β), one panel per {S1..Sk};
    empty cells where the pose is not a success (``verdict``, the name of the success
    verdict in use, labels the titles), dots on the local minima."""
    grids = [force_grid(gfo, incremental_set_id(k)) for k in panel_k]
    finite = np.concatenate([np.log10(g[2][np.isfinite(g[2])]) for g in grids] + [np.zeros(0)])
    vmin, vmax = colour_range(finite)  # one colour where it is constant (a sphere's)
    fig, axes = plt.subplots(len(panel_k), 1, figsize=(9, 2.4 * len(panel_k) + 0.6), sharex=True, squeeze=False)
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="white")
    for ax, k, (alphas, betas, force) in zip(axes[:, 0], panel_k, grids):
        with np.errstate(divide="ignore", invalid="ignore"):
            logf = np.log10(force)
        step_a = alphas[1] - alphas[0] if alphas.size > 1 else 5.0
        step_b = betas[1] - betas[0] if betas.size > 1 else 5.0
        image = ax.imshow(
            np.ma.masked_invalid(logf),
            origin="lower",
            aspect="auto",
            cmap=cmap,
            vmin=vmin,
            vmax=vmax,
            extent=(alphas[0] - step_a / 2, alphas[-1] + step_a / 2, betas[0] - step_b / 2, betas[-1] + step_b / 2),
        )
        mins = minima[minima["set_id"] == incremental_set_id(k)]
        ax.plot(mins["alpha_deg"], mins["beta_deg"], "o", ms=3.5, mfc="none", mec="red", mew=0.8, label="local minimum")
        n_fc = int(np.isfinite(force).sum())
        ax.set_title(
            f"{object_name}, {_set_label(k)}: {n_fc} {_verdict_label(verdict)} poses, {len(mins)} local minima", fontsize=9
        )
        ax.set_ylabel("β (deg)")
        fig.colorbar(image, ax=ax, label="log10 ‖f‖ (N)", pad=0.01)
    axes[-1, 0].set_xlabel("α (deg)")
    save_figure(fig, png, pdf, tight=True)


def figure_exploded_views(
    gfo: pd.DataFrame,
    panel_k: Sequence[int],
    alpha_deg: float,
    beta_deg: float,
    object_name: str,
    png: str | Path,
    pdf: str | Path,
    verdict: str = "force_closure",
) -> None:
    """Fig. 4 (exploded views): optimal force vs β at α = ``alpha_deg`` and vs α at
    β = ``beta_deg`` (nearest grid values), one line per {S1..Sk}; gaps where the pose is
    not a success of ``verdict``."""
    fig, (ax_b, ax_a) = plt.subplots(1, 2, figsize=(11, 3.8))
    # viridis sampled as seaborn's color_palette("viridis", n) does (importing seaborn cost
    # the job more CPU than drawing: it imports scipy.stats)
    palette = matplotlib.colormaps["viridis"](np.linspace(0.0, 1.0, len(panel_k) + 2)[1:-1])[:, :3]
    for colour, k in zip(palette, panel_k):
        alphas, betas, force = force_grid(gfo, incremental_set_id(k))
        ia = int(np.argmin(np.abs(((alphas - alpha_deg) + 180.0) % 360.0 - 180.0)))
        ib = int(np.argmin(np.abs(betas - beta_deg)))
        ax_b.plot(betas, force[:, ia], "-o", ms=2.5, color=colour, label=_set_label(k))
        ax_a.plot(alphas, force[ib, :], "-o", ms=2.5, color=colour, label=_set_label(k))
        ax_b.set_title(f"{object_name}: α = {alphas[ia]:g} deg", fontsize=9)
        ax_a.set_title(f"{object_name}: β = {betas[ib]:g} deg", fontsize=9)
    alphas, betas = np.sort(gfo["alpha_deg"].unique()), np.sort(gfo["beta_deg"].unique())
    for ax, xlabel, grid in ((ax_b, "β (deg)", betas), (ax_a, "α (deg)", alphas)):
        ax.set_xlim(grid[0], grid[-1])
        ax.set_xlabel(xlabel)
        if not any(np.isfinite(line.get_ydata()).any() for line in ax.get_lines()):
            ax.text(
                0.5,
                0.5,
                f"no {_verdict_label(verdict)} pose on this slice",
                transform=ax.transAxes,
                ha="center",
                va="center",
                fontsize=9,
                color="0.4",
            )
            ax.set_yticks([])
            continue
        ax.set_yscale("log")
        ax.set_ylabel("optimal ‖f‖ (N)")
        ax.grid(alpha=0.3, which="both")
    ax_a.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    save_figure(fig, png, pdf, tight=True)


#: Fixed grey range of Fig. 5B: paired force ratio 1 (the full set's force, black) to 10
#: (white; larger ratios take white too). The ratio is >= 1 up to solver tolerance.
FIG5B_RATIO_RANGE = (1.0, 10.0)
#: Colour of hierarchy cells without a value (a set that never succeeds has no force).
NO_VALUE_COLOUR = "#b9cde5"


def _hierarchy_panel(
    ax: plt.Axes,
    grid: np.ndarray,
    norm: matplotlib.colors.Normalize,
    fmt: str,
    labels: list[str],
    counts: np.ndarray | None = None,
) -> matplotlib.image.AxesImage:
    """One 7 × 7 matrix in grey (black = low, white = high), its value printed in every cell
    ("–" where it has none) and, if given, the count below it."""
    cmap = matplotlib.colormaps["Greys_r"].with_extremes(bad=NO_VALUE_COLOUR)
    image = ax.imshow(np.ma.masked_invalid(grid), cmap=cmap, norm=norm)
    for (i, j), value in np.ndenumerate(grid):
        if np.isfinite(value):
            shade = float(norm(np.clip(value, norm.vmin, norm.vmax)))
            text = format(value, fmt) + (f"\n{int(counts[i, j])}" if counts is not None else "")
            ax.text(
                j,
                i,
                text,
                ha="center",
                va="center",
                fontsize=6 if counts is None else 5,
                color="black" if shade > 0.5 else "white",
                linespacing=0.9,
            )
        else:
            ax.text(j, i, "–", ha="center", va="center", fontsize=6, color="0.25")
    ax.set_xticks(range(len(labels)), labels, fontsize=7)
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.set_xticks(np.arange(len(labels) + 1) - 0.5, minor=True)
    ax.set_yticks(np.arange(len(labels) + 1) - 0.5, minor=True)
    ax.grid(which="minor", color="0.6", linewidth=0.3)
    ax.tick_params(which="minor", length=0)
    return image


def figure_hierarchy(
    matrices: pd.DataFrame,
    value: str,
    first: int,
    title: str,
    fmt: str,
    value_range: tuple[float, float],
    colorbar_label: str,
    png: str | Path,
    pdf: str | Path,
    log_scale: bool = False,
    counts: str | None = None,
) -> None:
    """Fig. 5: ``first`` matrices ``first`` × ``first``, one per first synergy S_k; cell
    (i, j) of matrix k is the set {S_k, S_i, S_j}. Grey scale on the fixed ``value_range``
    (black = its low end, white = its high end; values beyond it take the end's grey), the
    value printed in every cell and, with ``counts`` (a column), that count below it.

    ``matrices`` has one row per (k, i, j) with 1-based columns ``k``, ``i``, ``j`` and the
    column ``value``. ``log_scale`` spaces the grey levels logarithmically.
    """
    low, high = value_range
    norm = matplotlib.colors.LogNorm(vmin=low, vmax=high) if log_scale else matplotlib.colors.Normalize(vmin=low, vmax=high)
    ncols = min(first, 4)
    nrows = int(np.ceil(first / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.1 * ncols + 0.8, 3.1 * nrows), squeeze=False)
    labels = [f"S{i}" for i in range(1, first + 1)]
    image = None
    for index, ax in enumerate(axes.flat):
        if index >= first:
            ax.axis("off")
            continue
        k = index + 1
        sub = matrices[matrices["k"] == k]
        grid = np.full((first, first), np.nan)
        cells = (sub["i"].to_numpy() - 1, sub["j"].to_numpy() - 1)
        grid[cells] = sub[value].to_numpy(dtype=float)
        count_grid = None
        if counts is not None:
            count_grid = np.zeros((first, first))
            count_grid[cells] = sub[counts].fillna(0).to_numpy(dtype=float)
        image = _hierarchy_panel(ax, grid, norm, fmt, labels, count_grid)
        ax.set_title(f"first synergy S{k}", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.93, 1))
    if image is not None:
        bar = fig.colorbar(image, ax=list(axes.flat), label=colorbar_label, fraction=0.02, pad=0.02)
        if log_scale:  # plain numbers, not powers of ten
            ticks = [t for t in (1, 1.5, 2, 3, 5, 7, 10, 20, 50, 100) if low <= t <= high]
            bar.set_ticks(ticks, labels=[f"{t:g}" for t in ticks])
            bar.ax.minorticks_off()
    save_figure(fig, png, pdf, tight=True)
