"""The explained-variance figure of a synergy fit (``synergrasp.hand.synergy_fit``): the share
of the postures' variance along each synergy (bars) and S1 … Si together (line), %."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from synergrasp.figures.output import save_figure
from synergrasp.hand.synergy_fit import SynergyFit

__all__ = ["figure_explained_variance"]


def figure_explained_variance(fit: SynergyFit, png_path: str | Path) -> None:
    """Write the explained variance of ``fit`` per synergy and cumulated (PNG, %)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = np.arange(1, len(fit.explained) + 1)
    fig, ax = plt.subplots(figsize=(6.0, 3.5))
    ax.bar(k, 100.0 * fit.explained, color="#4c72b0", label="per synergy")
    ax.plot(k, 100.0 * fit.cumulative, "o-", color="#dd8452", label="S1 … Si together")
    ax.set_xticks(k, [f"S{i}" for i in k], fontsize=8)
    ax.set_ylim(0, 100)
    ax.set_ylabel("explained variance (%)")
    ax.set_title(f"{len(fit.synergies.joint_names)} joints; total variance {fit.total_variance_rad2:.4g} rad²", fontsize=9)
    ax.legend(loc="center right", fontsize=8)
    fig.tight_layout()
    save_figure(fig, png_path, None)
