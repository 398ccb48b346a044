"""Quality maps of one object: the grasp quality indices over the (α, β) grid, beside Fig. 4
(docs/quality.md). Angles in deg."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: figures are files, never windows
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from synergrasp.figures.output import colour_range, save_figure  # noqa: E402

__all__ = ["quality_grid", "figure_quality_maps", "QUALITY_PANELS"]

#: (column, title, colour-bar label, log10 of the value) of each panel.
QUALITY_PANELS = (
    ("epsilon", "Ferrari–Canny ε (fully actuated, L1)", "ε (× total normal force)", False),
    ("isotropy", "grasp isotropy σ_min / σ_max", "isotropy", False),
    ("force_per_weight", "optimal force with every synergy, force-closure poses", "log10 ‖f‖ / weight", True),
)


def quality_grid(quality: pd.DataFrame, column: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(alpha_deg, beta_deg, value)`` with ``value[i_beta, i_alpha]`` the column's value at
    the pose (NaN where there is none)."""
    alphas = np.sort(quality["alpha_deg"].unique())
    betas = np.sort(quality["beta_deg"].unique())
    grid = np.full((betas.size, alphas.size), np.nan)
    grid[np.searchsorted(betas, quality["beta_deg"]), np.searchsorted(alphas, quality["alpha_deg"])] = quality[column].to_numpy(
        dtype=float
    )
    return alphas, betas, grid


def figure_quality_maps(quality: pd.DataFrame, object_name: str, png: str | Path, pdf: str | Path) -> None:
    """Three maps over (α, β): ε, isotropy (both NaN where there is no grasp) and the full
    set's optimal force over the weight where the full set is in force closure."""
    shown = quality.copy()
    shown.loc[~shown["force_closure"].astype(bool), "force_per_weight"] = np.nan
    fig, axes = plt.subplots(len(QUALITY_PANELS), 1, figsize=(9, 2.4 * len(QUALITY_PANELS) + 0.6), sharex=True, squeeze=False)
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="white")
    for ax, (column, title, label, log) in zip(axes[:, 0], QUALITY_PANELS):
        alphas, betas, values = quality_grid(shown, column)
        with np.errstate(divide="ignore", invalid="ignore"):
            values = np.log10(values) if log else values
        lo, hi = colour_range(values)  # one colour where it is constant (a sphere's)
        step_a = alphas[1] - alphas[0] if alphas.size > 1 else 5.0
        step_b = betas[1] - betas[0] if betas.size > 1 else 5.0
        image = ax.imshow(
            np.ma.masked_invalid(values),
            origin="lower",
            aspect="auto",
            cmap=cmap,
            vmin=lo,
            vmax=hi,
            extent=(alphas[0] - step_a / 2, alphas[-1] + step_a / 2, betas[0] - step_b / 2, betas[-1] + step_b / 2),
        )
        positive = int((np.isfinite(values) & (values > 0)).sum()) if not log else int(np.isfinite(values).sum())
        ax.set_title(f"{object_name}: {title} ({positive} of {values.size} poses {'shown' if log else 'above 0'})", fontsize=9)
        ax.set_ylabel("β (deg)")
        fig.colorbar(image, ax=ax, label=label, pad=0.01)
    axes[-1, 0].set_xlabel("α (deg)")
    save_figure(fig, png, pdf, tight=True)
