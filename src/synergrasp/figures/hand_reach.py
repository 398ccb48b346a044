"""The hand's reach seen from the side (docs/hand_reach.md): per finger, its links along the S1
closure path and over every posture within its joint limits, beside the study's boxes lying on
the palm, with the thickest box a link of the finger presses toward the palm (d_max).

Side view: the palm frame's z (along the long fingers) across, x (the palm normal, out of the
palm) up; y is not drawn. mm.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from synergrasp.figures.output import save_figure

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.simulation.reach import HandReach
    from synergrasp.simulation.shapes import Shape

__all__ = ["figure_hand_reach"]

#: Postures of the S1 path drawn per finger.
_PATH_DRAWN = 7


def figure_hand_reach(
    hand: Hand,
    path: np.ndarray,
    reach: HandReach,
    objects: Mapping[str, Shape],
    posture_steps: int,
    png_path: str | Path,
    pdf_path: str | Path,
) -> None:
    """One panel per finger: its capsules at ``_PATH_DRAWN`` postures of the free S1 path
    ``path`` ((n, n_joints) rad), the axis end points of its capsules over a lattice of its
    joint limits (grey: any posture), the palm, each object lying on the palm as a box of its
    thickness (dashed), and lines at the finger's reach along S1 and its d_max."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    from synergrasp.simulation.capsules import HandCapsules
    from synergrasp.simulation.placement import _palm_points
    from synergrasp.simulation.reach import finger_postures, object_extents

    capsules = HandCapsules.of(hand)
    palm = _palm_points(hand)
    face = reach.palm_face_mm
    names = [hand.link_finger[chain[0]] for chain in hand.finger_links]
    fig, axes = plt.subplots(1, len(names), figsize=(3.4 * len(names), 4.4))
    colours = plt.get_cmap("viridis")(np.linspace(0.1, 0.9, _PATH_DRAWN))
    drawn = np.linspace(0, len(path) - 1, _PATH_DRAWN).round().astype(int)
    z_lo, z_hi = float(palm[:, 2].min()), float(palm[:, 2].max())
    by_thickness: dict[float, list[str]] = {}
    for name, shape in objects.items():
        by_thickness.setdefault(round(float(object_extents(shape)[0]), 6), []).append(name)
    top = float(reach.table["reach_any_mm"].max()) + 6.0
    for ax, finger, chain in zip(axes, names, hand.finger_links):
        row = reach.table[reach.table["finger"] == finger].iloc[0]
        rows = np.flatnonzero(np.isin(capsules.links, list(chain)))
        cloud = []
        for q in finger_postures(hand, path[0], names.index(finger), posture_steps):
            p0, p1 = capsules.segments(q)
            cloud.append(np.concatenate([p0[rows], p1[rows]]))
        cloud = np.concatenate(cloud)
        ax.scatter(cloud[:, 2], cloud[:, 0], s=1, color="0.8", rasterized=True, label="any posture (axes)")
        ax.add_patch(Rectangle((z_lo, palm[:, 0].min()), z_hi - z_lo, face - palm[:, 0].min(), color="0.55"))
        for k, i in enumerate(drawn):
            p0, p1 = capsules.segments(path[i])
            for r in rows:
                ax.plot(
                    [p0[r, 2], p1[r, 2]],
                    [p0[r, 0], p1[r, 0]],
                    color=colours[k],
                    lw=2.0 * capsules.radius[r] / 3.0,
                    solid_capstyle="round",
                    alpha=0.8,
                )
        for d, held in sorted(by_thickness.items()):
            ax.add_patch(Rectangle((z_lo, face), z_hi - z_lo, d, fill=False, ls="--", lw=0.8, edgecolor="#c2000b"))
            ax.text(z_lo + 1, face + d + 0.5, f"{', '.join(held)}: {d:g} mm", fontsize=6, color="#c2000b", va="bottom")
        ax.axhline(row["reach_s1_mm"], color="black", lw=0.8, label=f"reach along S1 {row['reach_s1_mm']:.1f}")
        ax.axhline(row["reach_any_mm"], color="0.5", lw=0.8, ls=":", label=f"reach, any posture {row['reach_any_mm']:.1f}")
        if row["press_mm"] > 0:
            ax.axhline(
                face + row["press_mm"], color="#1f77b4", lw=1.2, label=f"d_max {row['press_mm']:g} (presses toward the palm)"
            )
        ax.set_title(f"{finger}", fontsize=9)
        ax.set_xlabel("z, along the fingers (mm)", fontsize=8)
        ax.set_ylim(float(palm[:, 0].min()) - 2.0, top)
        ax.set_xlim(z_lo - 5.0, max(float(cloud[:, 2].max()), z_hi) + 10.0)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=5.5, loc="upper right")
    axes[0].set_ylabel("x, out of the palm (mm)", fontsize=8)
    fig.suptitle(
        f"What each finger reaches closing along S1 (colour: open to closed) and in any posture (grey); "
        f"boxes lying on the palm (dashed); hand d_max {reach.d_max_mm:g} mm",
        fontsize=9,
    )
    fig.tight_layout()
    save_figure(fig, png_path, pdf_path)
