"""The incremental planner's figure for one object (docs/planner.md): the full set's force map
with the poses the planner solved at the last level (smallest radius) and the pose it returned, beside the
success of the greedy and the PCA enrollment orders."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp.analysis.planner import Plan
from synergrasp.figures.output import save_figure

__all__ = ["figure_plan"]


def figure_plan(
    full: pd.DataFrame,
    plans: Mapping[float, Plan],
    plan_table: pd.DataFrame,
    enrollment: pd.DataFrame,
    name: str,
    png: str | Path,
    pdf: str | Path,
) -> None:
    """``full``: the full set's rows of the object's judged gfo table, one per pose in pose
    order (alpha_deg, beta_deg, success_force in N)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_map, ax_k) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
    alphas, betas = np.unique(full["alpha_deg"]), np.unique(full["beta_deg"])
    grid = full.pivot_table(index="beta_deg", columns="alpha_deg", values="success_force", dropna=False)
    grid = grid.reindex(index=betas, columns=alphas)
    image = ax_map.imshow(
        np.log10(grid.to_numpy(float)),
        origin="lower",
        aspect="auto",
        cmap="viridis",
        extent=(alphas[0] - 2.5, alphas[-1] + 2.5, betas[0] - 2.5, betas[-1] + 2.5),
    )
    fig.colorbar(image, ax=ax_map, label="log10 optimal force, full set (N)")
    a, b = full["alpha_deg"].to_numpy(float), full["beta_deg"].to_numpy(float)
    radius, plan = min(plans.items())  # the smallest radius: the others' squares cover the map
    last = plan.solved[-1]
    ax_map.scatter(
        a[last],
        b[last],
        s=6,
        marker="o",
        facecolors="none",
        edgecolors="w",
        linewidths=0.5,
        label=f"solved at k = n, ±{radius:g}°",
    )
    rows = plan_table.sort_values("radius_deg")
    first = rows.iloc[0]
    if first["best_pose"] >= 0:
        ax_map.scatter(
            [first["best_alpha_deg"]],
            [first["best_beta_deg"]],
            marker="*",
            s=120,
            c="r",
            label=f"planner (±{first['radius_deg']:g}°)",
        )
    if first["exhaustive_best_pose"] >= 0:
        e = int(first["exhaustive_best_pose"])
        ax_map.scatter([a[e]], [b[e]], marker="x", s=60, c="k", label="exhaustive minimum")
    ax_map.set(xlabel="α (deg)", ylabel="β (deg)", title=f"{name}: incremental planner")
    ax_map.legend(fontsize=6, loc="upper right")
    ax_k.plot(enrollment["k"], enrollment["pca_success_rate"], "o-", label="PCA order {S1..Sk}")
    ax_k.plot(enrollment["k"], enrollment["greedy_success_rate"], "s--", label="greedy order")
    for k, added in zip(enrollment["k"], enrollment["greedy_added"]):
        ax_k.annotate(
            f"S{added}",
            (k, enrollment["greedy_success_rate"].iat[k - 1]),
            fontsize=5,
            xytext=(0, 4),
            textcoords="offset points",
            ha="center",
        )
    ax_k.set(xlabel="k synergies", ylabel="success (% of the full set's)", ylim=(0, 105), title="enrollment order")
    ax_k.legend(fontsize=7, loc="lower right")
    text = "; ".join(
        f"±{r['radius_deg']:g}°: {r['solve_share_percent']:.1f} % solves, regret {r['regret_percent']:.2g} %"
        for _, r in rows.iterrows()
    )
    fig.text(0.01, 0.01, text, fontsize=7)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    save_figure(fig, png, pdf)
