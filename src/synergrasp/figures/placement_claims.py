"""The claims over the placement search's targets: for each object and claim, the share of
scored targets where the claim holds, does not hold or is undefined, and the verdict at the
chosen target (docs/placement_search.md, "The claims over the targets")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp.analysis.claims import FAILS, HOLDS, UNDEFINED
from synergrasp.figures.output import VERDICT_COLOURS, save_figure

__all__ = ["figure_placement_claims"]

_MARK = {HOLDS: "Y", FAILS: "n", UNDEFINED: "?"}


def figure_placement_claims(summary: pd.DataFrame, png_path: str | Path, pdf_path: str | Path) -> None:
    """One panel per object: a horizontal bar per claim split into the shares (%) of the
    scored targets where it holds, does not hold and is undefined (``summary``: the table
    of ``synergrasp.analysis.target_claims.claims_summary``); the verdict at the chosen
    target written at the bar's end (Y, n, ?)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    objects = list(dict.fromkeys(summary["object"]))
    fig, axes = plt.subplots(1, max(len(objects), 1), figsize=(2.9 * max(len(objects), 1) + 0.8, 3.6), sharey=True, squeeze=False)
    columns = {HOLDS: "holds_percent", FAILS: "does_not_hold_percent", UNDEFINED: "undefined_percent"}
    for ax, obj in zip(axes[0], objects):
        rows = summary[summary["object"] == obj].sort_values("claim")
        y = np.arange(len(rows))
        left = np.zeros(len(rows))
        for verdict, column in columns.items():
            width = rows[column].to_numpy(float)
            ax.barh(y, width, left=left, color=VERDICT_COLOURS[verdict], edgecolor="0.5", linewidth=0.5, label=verdict)
            left += width
        for yi, at_chosen in zip(y, rows["at_chosen_target"]):
            ax.text(102, yi, _MARK.get(at_chosen, ""), va="center", fontsize=8, fontweight="bold", color="black")
        ax.set_yticks(y, [f"claim {int(c)}" for c in rows["claim"]], fontsize=7)
        ax.set_xlim(0, 110)
        ax.set_xticks([0, 25, 50, 75, 100])
        ax.tick_params(labelsize=7)
        ax.invert_yaxis()
        ax.set_xlabel("% of scored targets", fontsize=7)
        ax.set_title(f"{obj} ({int(rows['n_targets'].iloc[0])} targets)", fontsize=8)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.suptitle(
        "The study's claims at every target of the placement search (letter: the verdict at the chosen target)", fontsize=9
    )
    fig.tight_layout(rect=(0, 0.07, 1, 0.93))
    save_figure(fig, png_path, pdf_path)
