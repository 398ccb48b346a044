"""The grasp-realism figure, drawn from the grasp-realism table (``synergrasp.analysis.realism``).

Four panels, one bar (group) per object and closure model: (A) contacts per grasp, stacked
shares 0 … 6+; (B) share of grasps touching with the thumb, the index finger, the palm, a
proximal or middle phalanx, and with rank(G) = 6; (C) the median optimal contact force with
every synergy enrolled, in multiples of the object's weight (log scale); (D) equilibrium of the
end state: the median relative torque residual and the share of grasps with a contact S1
pushes outside its friction cone (``synergrasp.optimisation.equilibrium``).

Its size is bounded whatever the number of objects (the ``realism`` job's memory is the
figure's canvas): the title names each object's dropped poses for at most
:data:`LISTED_OBJECTS` rows (else their totals: the table has each), and the figure is
0.6 in a row tall up to :data:`TALL_ROWS` rows, then no taller (the rows get thinner).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp.analysis.realism import CONTACT_BINS
from synergrasp.figures.output import save_figure

__all__ = ["LISTED_OBJECTS", "TALL_ROWS", "figure_grasp_realism"]

#: Rows (object, closure model) whose dropped poses the title names one by one; beyond, their totals.
LISTED_OBJECTS = 12
#: Rows drawn 0.6 in tall each; a figure of more rows is as tall as one of these (its canvas,
#: the job's memory, does not grow with the objects).
TALL_ROWS = 100

#: (column, legend label) of panel B.
_SHARES = (
    ("pct_thumb", "thumb"),
    ("pct_index", "index finger"),
    ("pct_palm", "palm"),
    ("pct_proximal_or_middle", "proximal/middle phalanx"),
    ("pct_rank6", "rank G = 6"),
)
#: (column, legend label, scale to %) of panel D.
_EQUILIBRIUM = (
    ("median_torque_residual", "median torque residual", 100.0),
    ("pct_s1_outside_cone", "S1 pushes a contact outside its cone", 1.0),
)


def _labels(table: pd.DataFrame) -> list[str]:
    several = table["closure_model"].nunique() > 1
    return [f"{o}\n{m}" if several else str(o) for o, m in zip(table["object"], table["closure_model"])]


def _contacts_panel(ax, table: pd.DataFrame, labels: list[str]) -> None:
    import matplotlib.pyplot as plt

    columns = [f"pct_m{b}plus" if b == CONTACT_BINS[-1] else f"pct_m{b}" for b in CONTACT_BINS]
    colours = plt.get_cmap("viridis")(np.linspace(0.05, 0.95, len(columns)))
    y = np.arange(len(table))
    left = np.zeros(len(table))
    for b, column, colour in zip(CONTACT_BINS, columns, colours):
        width = table[column].fillna(0.0).to_numpy(dtype=float)
        ax.barh(
            y,
            width,
            left=left,
            color=colour,
            edgecolor="white",
            linewidth=0.5,
            label=f"{b}+" if b == CONTACT_BINS[-1] else str(b),
        )
        for yi, (start, w) in enumerate(zip(left, width)):
            if w >= 8.0:
                ax.text(start + w / 2, yi, f"{w:.0f}", ha="center", va="center", fontsize=7, color="white" if b < 4 else "black")
        left += width
    ax.set_yticks(y, labels)
    ax.set_xlim(0, 100)
    ax.set_xlabel("share of simulated grasps (%)")
    ax.set_title("A  contacts per grasp", loc="left", fontsize=10)
    ax.legend(
        title="contacts",
        ncol=len(columns),
        fontsize=7,
        title_fontsize=7,
        loc="lower center",
        bbox_to_anchor=(0.5, -0.5),
        frameon=False,
        handlelength=1.2,
        columnspacing=0.8,
    )


def _shares_panel(ax, table: pd.DataFrame, labels: list[str]) -> None:
    y = np.arange(len(table))
    colours = ("#d95f02", "#e7298a", "#1b9e77", "#7570b3", "0.45")
    _grouped_bars(ax, table, [(c, label, 1.0) for c, label in _SHARES], colours)
    ax.set_xlabel("share of simulated grasps (%)")
    ax.set_title("B  grasps touching with …", loc="left", fontsize=10)
    ax.legend(fontsize=7, ncol=2, loc="lower center", bbox_to_anchor=(0.5, -0.5), frameon=False)
    ax.set_yticks(y, labels)


def _grouped_bars(ax, table: pd.DataFrame, columns, colours) -> None:
    """One bar per (column, label, scale) in each row's group, its value (%) written at its end."""
    y = np.arange(len(table))
    height = 0.8 / len(columns)
    for k, ((column, label, scale), colour) in enumerate(zip(columns, colours)):
        value = scale * table[column].to_numpy(dtype=float)
        yk = y - 0.4 + (k + 0.5) * height
        ax.barh(yk, np.nan_to_num(value), height=height, color=colour, label=label)
        for yi, v in zip(yk, value):
            inside = np.isfinite(v) and v >= 15.0  # the number at the bar's end, inside it when it fits
            ax.text(
                v - 1.0 if inside else np.nan_to_num(v) + 1.0,
                yi,
                f"{v:.0f}" if np.isfinite(v) else "–",
                va="center",
                ha="right" if inside else "left",
                fontsize=6,
                color="white" if inside else "black",
            )
    ax.set_xlim(0, 100)


def _equilibrium_panel(ax, table: pd.DataFrame, labels: list[str]) -> None:
    _grouped_bars(ax, table, _EQUILIBRIUM, ("#a6761d", "#666666"))
    ax.set_yticks(np.arange(len(table)), labels)
    ax.set_xlabel("% (residual: of the box joints' torque)")
    ax.set_title("D  end state an equilibrium?", loc="left", fontsize=10)
    ax.legend(fontsize=7, ncol=1, loc="lower center", bbox_to_anchor=(0.5, -0.5), frameon=False)


def _force_panel(ax, table: pd.DataFrame, labels: list[str]) -> None:
    y = np.arange(len(table))
    value = table["median_force_per_weight"].to_numpy(dtype=float)
    shown = np.where(np.isfinite(value), value, np.nan)
    ax.barh(y, shown, color="#4a78c2")
    for yi, v in enumerate(value):
        ax.text(v if np.isfinite(v) else 1.0, yi, f" {v:.3g}" if np.isfinite(v) else " no force closure", va="center", fontsize=7)
    ax.axvline(1.0, color="0.3", lw=0.8, ls="--")
    ax.set_xscale("log")
    finite = value[np.isfinite(value)]
    hi = max(10.0, float(finite.max()) * 8) if finite.size else 10.0
    lo = min(0.1, float(finite.min()) / 2) if finite.size else 0.1
    ax.set_xlim(lo, hi)
    ax.set_yticks(y, labels)
    ax.set_xlabel("median ‖f‖ with all synergies / weight")
    ax.set_title("C  force needed (dashed: the weight)", loc="left", fontsize=10)


def figure_grasp_realism(table: pd.DataFrame, png_path: str | Path, pdf_path: str | Path) -> None:
    """Write the grasp-realism figure of ``table`` (columns of ``synergrasp.table_contracts.GRASP_REALISM``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if table.empty:
        raise ValueError("the grasp-realism table has no rows: no object was simulated")
    labels = _labels(table)
    fig, axes = plt.subplots(1, 4, figsize=(17.0, 1.8 + 0.6 * min(len(table), TALL_ROWS)), sharey=True)
    _contacts_panel(axes[0], table, labels)
    _shares_panel(axes[1], table, labels)
    _force_panel(axes[2], table, labels)
    _equilibrium_panel(axes[3], table, labels)
    axes[0].invert_yaxis()  # the first row on top (the axes share y: once for all)
    dropped = (
        ", ".join(f"{o}: {int(d)} of {int(p)}" for o, d, p in zip(labels, table["dropped"], table["poses"]))
        if len(table) <= LISTED_OBJECTS
        else f"{int(table['dropped'].sum())} of {int(table['poses'].sum())} over {len(table)} rows (each row's in the table)"
    )
    fig.suptitle(
        f"How realistic are the simulated grasps?   Poses dropped — {dropped}".replace("\n", " "),
        fontsize=10,
        x=0.01,
        ha="left",
        y=1.0,
        va="bottom",  # above the panels' top, whatever the figure's height (the saved bounding box holds it)
    )
    fig.tight_layout()
    save_figure(fig, png_path, pdf_path, tight=True)
