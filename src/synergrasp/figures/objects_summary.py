"""The distributions over objects of the study's measures and the planner's (docs/random_objects.md)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp.figures.output import save_figure

__all__ = ["figure_objects_summary", "figure_planner_tradeoff"]


def _values(rows: pd.DataFrame, column: str) -> np.ndarray:
    if column not in rows:
        return np.zeros(0)
    v = pd.to_numeric(rows[column], errors="coerce").to_numpy(float)
    return v[np.isfinite(v)]


def figure_objects_summary(rows: pd.DataFrame, radii: Sequence[float], png: str | Path, pdf: str | Path) -> None:
    """Five panels: minimum preservation, S1 against the best other single, the k of 100 %
    (PCA and greedy order), the planner's share of solves and its force regret per radius."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 5, figsize=(17, 3.4))
    n = len(rows)
    axes[0].hist(_values(rows, "preserved_percent"), bins=np.linspace(0, 100, 21))
    axes[0].set(xlabel="minima preserved (%)", ylabel="objects", title="claim 3")
    axes[1].hist(_values(rows, "s1_minus_best_other"), bins=20)
    axes[1].axvline(0, c="k", lw=0.8)
    axes[1].set(xlabel="{S1} − best other single (points)", title="claim 4")
    ks = [_values(rows, "k_full"), _values(rows, "greedy_k_full")]
    top = max([int(k.max()) for k in ks if k.size] + [1])
    axes[2].hist(ks, bins=np.arange(0.5, top + 1.5), label=["PCA order", "greedy order"])
    axes[2].set(xlabel="k at which success reaches 100 %", title="claims 1, 2")
    axes[2].legend(fontsize=7)
    names = [f"±{r:g}°" for r in radii]
    axes[3].boxplot([_values(rows, f"solve_share_percent_{r:g}") for r in radii])
    axes[3].set_xticks(range(1, len(names) + 1), names)
    axes[3].set(ylabel="solves used (% of exhaustive)", title="planner: savings")
    regrets = [np.maximum(_values(rows, f"regret_percent_{r:g}"), 1e-3) for r in radii]
    axes[4].boxplot(regrets)
    axes[4].set_xticks(range(1, len(names) + 1), names)
    axes[4].set_yscale("log")
    axes[4].set(ylabel="force regret (%; 0 drawn at 1e-3)", title="planner: regret")
    fig.suptitle(f"{n} objects", fontsize=9)
    fig.tight_layout()
    save_figure(fig, png, pdf)


def figure_planner_tradeoff(rows: pd.DataFrame, radii: Sequence[float], png: str | Path, pdf: str | Path) -> None:
    """One panel per planner radius: each object's share of the exhaustive solves against its
    force regret, with the planner's aims (``SOLVE_SHARE_BUDGET``, ``REGRET_BUDGET``) and how
    many objects meet them (``planner_budget``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp.analysis.objects_summary import REGRET_BUDGET, SOLVE_SHARE_BUDGET, planner_budget, planner_columns

    budget = planner_budget(rows, radii).set_index("radius_deg")
    fig, axes = plt.subplots(1, len(radii), figsize=(4.2 * len(radii), 3.6), sharey=True, squeeze=False)
    floor = 1e-2  # a regret of 0 (the global minimum found) is drawn on this line of the log axis
    for ax, r in zip(axes[0], radii):
        share, regret = planner_columns(rows, r)
        ok = share.notna() & regret.notna()
        ax.scatter(share[ok], np.maximum(regret[ok], floor), s=12, alpha=0.7)
        ax.axvline(SOLVE_SHARE_BUDGET, c="k", lw=0.8, ls="--")
        ax.axhline(REGRET_BUDGET, c="k", lw=0.8, ls="--")
        ax.set_yscale("log")
        ax.set_xlim(0, 100)
        b = budget.loc[float(r)]
        ax.set_title(
            f"±{r:g}°: {b['within_both']} of {b['objects']} objects within both aims\n"
            f"(solves ≤ {SOLVE_SHARE_BUDGET:g} %: {b['within_solves']}, regret ≤ {REGRET_BUDGET:g} %: "
            f"{b['within_regret']})",
            fontsize=8,
        )
        ax.set_xlabel("solves used (% of the exhaustive search)")
    axes[0][0].set_ylabel(f"force regret (%; 0 drawn at {floor:g})")
    fig.suptitle("The incremental planner per object, by radius", fontsize=9)
    fig.tight_layout()
    save_figure(fig, png, pdf)
