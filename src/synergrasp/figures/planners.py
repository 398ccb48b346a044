"""Planners compared at equal cost (docs/planner.md): cost against the probability of a regret
within the aim, per object and across objects; closures (a new object's cost) in the top
row, solve time (full-set solves, measured per set size) in the bottom row."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from synergrasp.analysis.planners import OBJECTS_AIM, PROBABILITY_AIM, REGRET_AIM_PERCENT
from synergrasp.figures.output import save_figure

__all__ = ["figure_planners"]

#: Marker per planner kind (the name's prefix), colour per family.
_MARKERS = {"exhaustive": "s", "random": "o", "descent": "v", "coarse": "D", "incremental": "^", "skip": ">", "straight": "<"}
_COLOURS = {"full_set": "tab:blue", "incremental": "tab:red"}


def _kind(name: str) -> str:
    return name.split("_")[0]


def figure_planners(per_object: pd.DataFrame, across: pd.DataFrame, png: str | Path, pdf: str | Path) -> None:
    """``per_object``: table_contracts.PLANNERS rows; ``across``: table_contracts.PLANNERS_ACROSS rows."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    judged = per_object[per_object["regret_percent_mean"].notna()]
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.5), sharey="col")
    for row, (cost, label) in enumerate(
        (("closures", "closures (distinct poses asked)"), ("solve_cost", "solve time (full-set solves, measured per set size)"))
    ):
        ax_obj, ax_all = axes[row]
        for planner, part in judged.groupby("planner", sort=False):
            ax_obj.scatter(
                part[cost],
                part["within_aim_probability"],
                marker=_MARKERS.get(_kind(planner), "o"),
                color=_COLOURS[part["family"].iat[0]],
                s=22,
                alpha=0.6,
            )
        ax_obj.axhline(PROBABILITY_AIM, color="0.4", lw=0.8, ls="--")
        ax_obj.set_xscale("log")
        ax_obj.set_xlabel(label)
        ax_obj.set_ylabel(f"P(regret ≤ {REGRET_AIM_PERCENT:g} %) over seeds")
        ax_obj.set_title(f"per object ({judged['object'].nunique()} objects, one point per planner)", fontsize=10)
        for r in across.itertuples():
            chosen = bool(getattr(r, "recommended", False))
            ax_all.scatter(
                getattr(r, cost),
                r.meeting_aim_percent,
                marker=_MARKERS.get(_kind(r.planner), "o"),
                color=_COLOURS[r.family],
                s=120 if chosen else 30,
                edgecolors="k" if chosen else "none",
            )
        _label_frontier(ax_all, across, cost)
        ax_all.axhline(OBJECTS_AIM, color="0.4", lw=0.8, ls="--")
        ax_all.set_xscale("log")
        ax_all.set_xlabel(f"{label}, mean over objects")
        ax_all.set_ylabel("objects where it meets the aim (%)")
        ax_all.set_title("across objects (ringed: the rule's choice; named: each family's cheapest at its share)", fontsize=9)
    for ax in axes[:, 0]:
        ax.set_ylim(-0.05, 1.05)
    for ax in axes[:, 1]:
        ax.set_ylim(-5, 105)
    handles = [Line2D([], [], marker=m, ls="", color="0.3", label=k) for k, m in _MARKERS.items()]
    handles += [Line2D([], [], marker="o", ls="", color=c, label=f"family: {f}") for f, c in _COLOURS.items()]
    fig.legend(handles=handles, loc="lower center", ncol=9, fontsize=8, frameon=False)
    fig.suptitle(
        f"Planners at equal cost: aim = regret ≤ {REGRET_AIM_PERCENT:g} % with probability ≥ "
        f"{PROBABILITY_AIM:g} (dashed), on ≥ {OBJECTS_AIM:g} % of objects",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0.04, 1, 0.96))
    save_figure(fig, png, pdf)
    plt.close(fig)


def frontier(across: pd.DataFrame, cost: str) -> pd.DataFrame:
    """Per family, the planners no cheaper planner of the family matches: sorted by ``cost``,
    each row that meets the aim on more objects than every cheaper one (ties in cost kept
    together), with the recommended planner always in."""
    keep = []
    for _, part in across.sort_values([cost, "planner"]).groupby("family", sort=False):
        best = -1.0
        for _, same in part.groupby(part[cost].round(0), sort=True):
            if same["meeting_aim_percent"].max() > best:
                best = same["meeting_aim_percent"].max()
                keep += list(same.index[same["meeting_aim_percent"] == best])
    chosen = across.index[across.get("recommended", pd.Series(False, index=across.index)).astype(bool)]
    return across.loc[sorted(set(keep) | set(chosen))]


def _label_frontier(ax, across: pd.DataFrame, cost: str) -> None:
    """Names beside the frontier's points (planners at one point share a label, three names a
    line), full-set planners above their point and incremental ones below, so that the two
    families' labels do not overlap; the table names every planner."""
    spots = frontier(across, cost).assign(x=lambda t: t[cost].round(0), y=lambda t: t["meeting_aim_percent"].round(1))
    x_max = float(across[cost].max())
    for (x, y, family), part in spots.groupby(["x", "y", "family"], sort=False):
        names = list(part["planner"])
        text = "\n".join(", ".join(names[i : i + 3]) for i in range(0, len(names), 3))
        right = x >= x_max / 3.0  # near the axis' right end: the label to the left of the point
        ax.annotate(
            text,
            (x, y),
            fontsize=6,
            xytext=(-6 if right else 6, 5 if family == "full_set" else -5),
            textcoords="offset points",
            ha="right" if right else "left",
            va="bottom" if family == "full_set" else "top",
        )
