"""Figures of a sensitivity sweep: the claims' verdicts across scenarios, and Table II's
curves per object across scenarios (docs/sensitivity.md)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from synergrasp.analysis.claims import UNDEFINED  # noqa: E402
from synergrasp.config import DEFAULT_SCENARIO  # noqa: E402
from synergrasp.figures.output import VERDICT_COLOURS, save_figure  # noqa: E402

__all__ = ["figure_claims_grid", "figure_table2_curves"]

#: Cell colour of a claim a scenario did not produce (a verdict's: VERDICT_COLOURS).
_MISSING = "#dddddd"


def _claim_ids(summary: pd.DataFrame) -> list[str]:
    return [
        c[len("claim") : -len("_verdict")]
        for c in summary.columns
        if c.startswith("claim") and c.endswith("_verdict") and c[len("claim") : -len("_verdict")].isdigit()
    ]


def figure_claims_grid(summary: pd.DataFrame, png: str | Path, pdf: str | Path) -> None:
    """Claims (columns) × scenarios (rows), each cell coloured by the headline verdict and
    holding the compared difference with its interval (with the reason's first clause when
    undefined), or the claims table's ``measured`` for a summary without intervals."""
    claims = _claim_ids(summary)
    n_rows, n_cols = len(summary), max(len(claims), 1)
    fig, ax = plt.subplots(figsize=(1.7 * n_cols + 2.2, 0.42 * n_rows + 1.0))
    for i in range(n_rows):
        for j, claim in enumerate(claims):
            verdict = summary.iloc[i][f"claim{claim}_verdict"]
            shown = summary.iloc[i].get(f"claim{claim}_interval", summary.iloc[i][f"claim{claim}_measured"])
            reason = summary.iloc[i].get(f"claim{claim}_reason")
            colour = VERDICT_COLOURS.get(verdict, _MISSING) if isinstance(verdict, str) else _MISSING
            ax.add_patch(plt.Rectangle((j, i), 1, 1, facecolor=colour, edgecolor="white"))
            text = str(shown) if isinstance(shown, str) else "—"
            if isinstance(reason, str) and verdict == UNDEFINED:  # the rest is in claims.md
                text = _wrap(text, 26) + "\n" + _first_clause(reason)
            else:
                text = _wrap(text, 26)
            ax.text(j + 0.5, i + 0.5, text, ha="center", va="center", fontsize=6)
    ax.set_xlim(0, n_cols)
    ax.set_ylim(n_rows, 0)
    ax.set_xticks(np.arange(n_cols) + 0.5, [f"claim {c}" for c in claims])
    ax.set_yticks(np.arange(n_rows) + 0.5, list(summary["scenario"]))
    ax.xaxis.tick_top()
    handles = [plt.Rectangle((0, 0), 1, 1, facecolor=c) for c in VERDICT_COLOURS.values()]
    ax.legend(handles, list(VERDICT_COLOURS), loc="upper center", bbox_to_anchor=(0.5, -0.01), ncol=3, frameon=False, fontsize=7)
    fig.tight_layout()
    save_figure(fig, png, pdf)


def _first_clause(reason: str, width: int = 34) -> str:
    """A verdict's reason up to its first colon, semicolon or parenthesis, at most ``width`` characters."""
    clause = reason.split(":")[0].split(";")[0].split(" (")[0].strip()
    return clause if len(clause) <= width else clause[: width - 1] + "…"


def _wrap(text: str, width: int) -> str:
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    return "\n".join([*lines, line])


def figure_table2_curves(table2: pd.DataFrame, png: str | Path, pdf: str | Path, k_max: int = 7) -> None:
    """One panel per object: Table II's success rate (%) of {S1..Sk}, k = 1..``k_max``, one
    line per scenario (the default drawn thick and black). ``table2``: scenario, object, k,
    success_rate (analysis.sensitivity.table2_long)."""
    data = table2[table2["k"] <= k_max]
    objects = sorted(data["object"].unique())
    fig, axes = plt.subplots(1, len(objects), figsize=(3.2 * len(objects), 4.6), sharey=True, squeeze=False)
    scenarios = list(dict.fromkeys(data["scenario"]))
    colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(len(scenarios), 2)))
    for ax, obj in zip(axes[0], objects):
        for colour, name in zip(colours, scenarios):
            curve = data[(data["object"] == obj) & (data["scenario"] == name)].sort_values("k")
            default = name == DEFAULT_SCENARIO
            ax.plot(
                curve["k"],
                curve["success_rate"],
                marker=".",
                label=name,
                color="black" if default else colour,
                lw=2.2 if default else 1.0,
                zorder=3 if default else 2,
            )
        ax.set_title(obj)
        ax.set_xlabel("k of {S1..Sk}")
        ax.set_xticks(range(1, k_max + 1))
        ax.set_ylim(0, 102)
    axes[0][0].set_ylabel("success rate (%)")
    # the legend below the panels: inside one it hides that object's curves
    handles, labels = axes[0][0].get_legend_handles_labels()
    n_cols = min(len(scenarios), 6)
    fig.tight_layout(rect=(0, 0.06 * (1 + (len(scenarios) - 1) // n_cols), 1, 1))
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=n_cols, frameon=False)
    save_figure(fig, png, pdf)
