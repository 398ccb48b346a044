"""What blocks each synergy set, drawn from the study's blockers table
(``synergrasp.analysis.blockers.blockers_summary``; docs/blockers.md).

One panel per object: rows are the sets examined ({S1..Sk}, then the singles {Sk}), each
labelled with its number of failing poses (full set yes, this set no); columns the link kinds
of the opposition rule, then the face classes and surface features; a cell is the share (%) of
the row's failing poses with a blocker of that label (a pose with several blockers counts in
several cells; e_s = 0 rows have no blocker and count in the first column).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp.analysis.blockers import SUMMARY_GROUPS
from synergrasp.figures.output import save_figure
from synergrasp.ids import ALL_OBJECTS, set_name

__all__ = ["figure_blockers"]

#: Column labels (short) of the labels counted.
_SHORT = {
    "palm": "palm",
    "palm_side": "proximal",
    "finger_middle": "middle ph.",
    "finger_pad": "fingertip",
    "thumb_pad": "thumb tip",
    "thumb_base": "thumb base",
    "palm_face": "palm face",
    "outer_face": "outer face",
    "side_face": "side face",
    "end_face": "end face",
    "face": "on a face",
    "edge": "on an edge",
    "corner": "on a corner",
}


def _columns() -> list[tuple[str, str]]:
    out = [("pct_no_internal_force", "e_s = 0")]
    for group, (_, labels) in SUMMARY_GROUPS.items():
        out += [(f"pct_{group}_{label}", _SHORT.get(label, label)) for label in labels]
    return out


def figure_blockers(summary: pd.DataFrame, png_path: str | Path, pdf_path: str | Path) -> None:
    """The heat maps of the blockers summary, one panel per object (``all`` last)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    objects = [o for o in dict.fromkeys(summary["object"]) if o != ALL_OBJECTS]
    objects += [ALL_OBJECTS] if (summary["object"] == ALL_OBJECTS).any() else []
    columns = _columns()
    n = max(len(objects), 1)
    fig, axes = plt.subplots(
        n, 1, figsize=(11.5, 0.3 * len(summary) + 0.5 * n + 2.4), squeeze=False, sharex=True, layout="constrained"
    )
    for ax, obj in zip(axes[:, 0], objects):
        part = summary[summary["object"] == obj]
        values = part[[c for c, _ in columns]].to_numpy(dtype=float)
        image = ax.imshow(np.nan_to_num(values, nan=0.0), cmap="Reds", vmin=0.0, vmax=100.0, aspect="auto")
        for (i, j), v in np.ndenumerate(values):
            if np.isfinite(v) and v >= 0.5:
                ax.text(j, i, f"{v:.0f}", ha="center", va="center", fontsize=7, color="white" if v > 60 else "black")
        ax.set_yticks(range(len(part)))
        ax.set_yticklabels(
            [f"{set_name([int(k) for k in s.split('-')])}  (n = {int(c)})" for s, c in zip(part["set_id"], part["n_failing"])],
            fontsize=7,
        )
        ax.set_xticks(range(len(columns)), [label for _, label in columns])
        # the columns are the same in every panel: named above the first and below the last
        ax.tick_params(axis="x", labelsize=7, labeltop=ax is axes[0, 0], labelbottom=ax is axes[-1, 0])
        plt.setp(ax.get_xticklabels(), rotation=35, ha="right" if ax is axes[-1, 0] else "left")
        n_kinds, n_faces = len(SUMMARY_GROUPS["kind"][1]), len(SUMMARY_GROUPS["face"][1])
        for edge in (0.5, 0.5 + n_kinds, 0.5 + n_kinds + n_faces):
            ax.axvline(edge, color="black", linewidth=0.8)
        ax.set_title(
            f"{obj}: poses where the full set is in force closure and the set is not; % with a blocker of each kind",
            fontsize=8.5,
            loc="left",
        )
        fig.colorbar(image, ax=ax, fraction=0.02, pad=0.01).ax.tick_params(labelsize=6)
    save_figure(fig, png_path, pdf_path)
