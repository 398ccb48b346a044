"""Fig. 1 (the hand along each synergy) and Fig. 2 (representative simulated grasps), from
the shaded pictures of ``synergrasp.figures.hand_pictures``. Angles in rad (postures) and
deg (pose labels), lengths in mm.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from synergrasp.analysis.realism import SIMULATED_STATUSES, representative_grasps
from synergrasp.figures.hand_pictures import (
    ABOVE_CAMERA,
    BOX,
    PALM_CAMERA,
    SKIN,
    TOUCHING,
    Camera,
    ShapeInPicture,
    hand_shapes,
    render,
)
from synergrasp.figures.output import save_figure
from synergrasp.hand.synergies import SynergyPath

__all__ = [
    "figure_synergy_postures",
    "figure_closing_views",
    "THUMB_CAMERA",
    "figure_example_grasps",
    "figure_grasp_views",
    "draw_grasp",
    "draw_grasp_row",
    "object_of",
    "PANEL_PX",
    "GRASP_VIEWS",
    "FIG2_GRASPS",
]

#: Rendered panel size, pixels (width, height).
PANEL_PX = (330, 330)
#: Grasps per object in Fig. 2.
FIG2_GRASPS = 3
_CONTACT = "#c2000b"


@dataclass(frozen=True)
class Fig1Params:
    """Fig. 1 (the ``fig1`` step): the hand and synergy files (None: the shipped ones)."""

    hand: str | None
    synergies: str | None

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> Fig1Params:
        return cls(config["hand"], config["synergies"])


def _bare(ax: Any) -> None:
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_color("0.85")


def _frame(axes: Sequence[Any], pictures: Sequence[Any], margin_px: float = 8.0) -> None:
    """One square window for all ``axes``: the union of what their pictures show, plus a margin."""
    drawn = np.zeros(pictures[0].rgb.shape[:2], dtype=bool)
    for picture in pictures:
        drawn |= np.any(picture.rgb < 0.985, axis=2)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    if not len(rows):
        return
    half = 0.5 * max(rows[-1] - rows[0], cols[-1] - cols[0]) + margin_px
    mid_r, mid_c = 0.5 * (rows[0] + rows[-1]), 0.5 * (cols[0] + cols[-1])
    for ax in axes:
        ax.set_xlim(mid_c - half, mid_c + half)
        ax.set_ylim(mid_r + half, mid_r - half)


def _palm_point(hand: Any) -> NDArray:
    """Centre of the palm box's face toward the palm normal (mm, palm frame; the origin if the
    palm has no box): where "palm" is written and what the other labels point away from."""
    boxes = hand_shapes(hand, np.zeros(hand.n_joints)).boxes  # the palm does not move
    if not boxes:
        return np.zeros(3)
    normal = np.asarray(hand.palm_normal, dtype=float)
    front = [
        np.asarray(b.center_mm) + (np.abs(np.asarray(b.rotation).T @ normal) @ b.shape.half_extents_mm) * normal for b in boxes
    ]
    return max(front, key=lambda p: float(p @ normal))


def _fit(camera: Camera, hand: Any, postures: Sequence[NDArray], objects: Sequence[ShapeInPicture] = ()) -> Camera:
    """``camera`` centred on and sized to the hand at every posture and the objects."""
    points, radii = [], []
    for q in postures:
        p, r = hand_shapes(hand, q).extent()
        points.append(p)
        radii.append(r)
    for obj in objects:
        p, r = obj.extent()
        points.append(p)
        radii.append(r)
    return camera.fitted(np.vstack(points), np.concatenate(radii))


def _label(ax: Any, name: str, at: NDArray, away_from: NDArray, distance: float = 0.2) -> None:
    """Name a part at image point ``at``; the text sits ``distance`` (fraction of the window)
    further along the direction from ``away_from`` to ``at``, inside the window."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()  # y runs downward in an image: y0 > y1
    direction = np.asarray(at, float) - np.asarray(away_from, float)
    direction = direction / max(float(np.linalg.norm(direction)), 1e-9)
    text = np.asarray(at, float) + distance * (x1 - x0) * direction
    text = (
        np.clip(text[0], x0 + 0.1 * (x1 - x0), x1 - 0.1 * (x1 - x0)),
        np.clip(text[1], y1 + 0.05 * (y0 - y1), y0 - 0.05 * (y0 - y1)),
    )
    ax.annotate(
        name,
        xy=at,
        xytext=text,
        fontsize=8,
        color="0.1",
        ha="center",
        va="center",
        bbox=dict(boxstyle="round,pad=0.15", facecolor="white", edgecolor="none", alpha=0.8),
        arrowprops=dict(arrowstyle="-", color="0.3", lw=0.7, shrinkA=0, shrinkB=1),
    )


def _thumb_point(hand: Any, q: ArrayLike) -> NDArray:
    """Centre of the thumb's proximal phalanx (mm): the thumb's middle, seen even when it is flexed."""
    caps = hand_shapes(hand, np.asarray(q, dtype=float))
    return caps.ends[caps.link == hand.link_index("thumb_proximal")][0].mean(axis=0)


def _label_parts(ax: Any, hand: Any, q: ArrayLike, picture: Any) -> None:
    """Name the thumb, index, little finger and palm on a picture of the hand at q (after framing)."""
    from synergrasp.hand.kinematics import fingertip_positions

    tips = picture.pixels(fingertip_positions(hand, np.asarray(q, dtype=float)))
    palm = picture.pixels(_palm_point(hand)[None])[0]
    _label(ax, "thumb", picture.pixels(_thumb_point(hand, q)[None])[0], palm)
    _label(ax, "index", tips[1], palm, 0.12)
    _label(ax, "little", tips[4], palm, 0.12)
    ax.text(*palm, "palm", fontsize=8, color="0.1", ha="center", va="center")


def figure_synergy_postures(
    hand: Any,
    synergies: Any,
    png_path: str | Path,
    pdf_path: str | Path,
    n_synergies: int = 7,
    sigmas: Sequence[float] = (-1.0, 0.0, 1.0),
    camera: Camera = PALM_CAMERA,
) -> None:
    """Fig. 1: the hand at q_m + σ·S_k (joint limits clip) for k = 1..n_synergies (rows) and
    σ in ``sigmas`` (columns), seen from the palm side; the mean posture q_m is the pale
    silhouette behind the σ ≠ 0 pictures; the parts are named on the first mean posture."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    matrix = np.asarray(synergies.matrix, dtype=float)
    if not 1 <= n_synergies <= matrix.shape[1]:
        raise ValueError(f"n_synergies must be in 1 … {matrix.shape[1]}, got {n_synergies}")
    paths = [SynergyPath.along(synergies, hand.lower, hand.upper, synergy=k + 1) for k in range(n_synergies)]
    mean = paths[0].reference(0.0)
    panel = 2.35  # inches
    fig, axes = plt.subplots(
        n_synergies, len(sigmas), figsize=(panel * len(sigmas) + 0.4, panel * n_synergies + 0.6), squeeze=False
    )
    postures = [[path.reference(sigma) for sigma in sigmas] for path in paths]
    camera = _fit(camera, hand, [q for row in postures for q in row] + [mean])
    pictures, named = [], None  # named: the first mean posture's (axes, q, picture)
    for k in range(n_synergies):
        for c, sigma in enumerate(sigmas):
            q = postures[k][c]
            ax = axes[k, c]
            picture = render(hand, q, camera, PANEL_PX, ghost_q=None if sigma == 0 else mean)
            pictures.append(picture)
            ax.imshow(picture.rgb, interpolation="antialiased")
            _bare(ax)
            if sigma == 0 and named is None:
                named = (ax, q, picture)
            if k == 0:
                ax.set_title(f"σ = {sigma:+g}" if sigma else "mean posture (σ = 0)", fontsize=10)
            if c == 0:
                ax.set_ylabel(f"S{k + 1}", fontsize=12, rotation=0, labelpad=14)
    _frame(axes.ravel(), pictures)
    if named is not None:
        _label_parts(named[0], hand, named[1], named[2])
    fig.suptitle("Right hand, palm toward the viewer, along each postural synergy (pale: the mean posture)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.99), h_pad=0.3, w_pad=0.3)
    save_figure(fig, png_path, pdf_path)


#: From the thumb's side of a right hand (+y, palm frame), a little from in front of the palm,
#: fingers up, the palm normal toward the image left: how far in front of the palm face the
#: thumb meets the fingers.
THUMB_CAMERA = Camera(direction=(-0.25, -1.0, 0.1))


def figure_closing_views(
    hand: Any, synergies: Any, png_path: str | Path, pdf_path: str | Path | None, sigmas: Sequence[float]
) -> None:
    """The hand closing along S1, q_r(σ) = clip(q_m + σ·S1) for each σ of ``sigmas`` (columns),
    seen from the palm side (top row, as Fig. 1) and from the thumb's side (bottom row, the
    palm normal to the image left: how far in front of the palm the thumb meets the fingers);
    the mean posture is the pale silhouette behind the others."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    mean = path.reference(0.0)
    postures = [path.reference(float(sigma)) for sigma in sigmas]
    panel = 2.35  # inches
    views = (("palm side", PALM_CAMERA), ("thumb side", THUMB_CAMERA))
    fig, axes = plt.subplots(
        len(views), len(sigmas), figsize=(panel * len(sigmas) + 0.4, panel * len(views) + 0.6), squeeze=False
    )
    for r, (name, camera) in enumerate(views):
        camera = _fit(camera, hand, [*postures, mean])
        pictures = []
        for c, (sigma, q) in enumerate(zip(sigmas, postures)):
            picture = render(hand, q, camera, PANEL_PX, ghost_q=None if sigma == 0 else mean)
            pictures.append(picture)
            axes[r, c].imshow(picture.rgb, interpolation="antialiased")
            _bare(axes[r, c])
            if r == 0:
                axes[r, c].set_title(f"σ = {sigma:+.2f}", fontsize=10)
            if c == 0:
                axes[r, c].set_ylabel(name, fontsize=11)
        _frame(axes[r], pictures)
    fig.suptitle(f"{hand.name}: closing along S1 (pale: the mean posture)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.99), h_pad=0.3, w_pad=0.3)
    save_figure(fig, png_path, pdf_path)


def _touching_words(hand: Any, links: Sequence[int]) -> str:
    """The touching links in words, finger by finger: "palm, thumb tip, index middle + tip"."""
    import textwrap

    parts = []
    for finger in ("palm", "thumb", "index", "middle", "ring", "little"):
        segments = [hand.link_names[i].split("_", 1)[-1] for i in sorted(links) if hand.link_finger[i] == finger]
        if finger == "palm" and segments:
            parts.append("palm")
        elif segments:
            parts.append(f"{finger} " + " + ".join("tip" if s == "distal" else s for s in segments))
    return "\n".join(textwrap.wrap("touching: " + ", ".join(parts), 48))


def object_of(row: pd.Series, shape: Any) -> ShapeInPicture:
    """The object of a contacts table's row (its end pose) with its ``shape``."""
    return ShapeInPicture(
        shape, np.asarray(row["object_center"], dtype=float), np.asarray(row["object_rotation"], dtype=float).reshape(3, 3)
    )


def _legend(fig: Any, ncol: int = 5) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [
        Patch(facecolor=SKIN, edgecolor="0.2", label="hand"),
        Patch(facecolor=TOUCHING, edgecolor="0.2", label="link touching the object"),
        Patch(facecolor=BOX, edgecolor="#1f3f7a", alpha=0.5, label="object (see-through)"),
        Line2D([], [], ls="", marker="o", color=_CONTACT, markeredgecolor="white", label="contact point"),
        Line2D([], [], ls="", marker="o", markerfacecolor="none", color=_CONTACT, label="contact point behind the hand"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=8, frameon=False)


def draw_grasp(
    ax: Any, hand: Any, q: NDArray, shape: ShapeInPicture, touching: Sequence[int], points_mm: ArrayLike, camera: Camera
) -> Any:
    """One grasp of Fig. 2 on ``ax``: the hand at q (rad) seen by ``camera``, the links in
    ``touching`` highlighted, the object see-through, the contact points (mm, palm frame;
    hollow where the hand hides them). Returns the rendered ``Picture``."""
    points = np.asarray(points_mm, dtype=float).reshape(-1, 3)
    picture = render(hand, q, camera, PANEL_PX, shape=shape, touching=touching)
    ax.imshow(picture.rgb, interpolation="antialiased")
    px, hidden = picture.pixels(points), picture.hidden(points)
    ax.scatter(px[~hidden, 0], px[~hidden, 1], s=16, c=_CONTACT, edgecolors="white", linewidths=0.6, zorder=3)
    ax.scatter(px[hidden, 0], px[hidden, 1], s=16, facecolors="none", edgecolors=_CONTACT, linewidths=0.9, zorder=3)
    return picture


#: The two views of one grasp (``figure_grasp_views``): Fig. 2's, and from above the
#: fingertips with the palm at the bottom and the palm normal up, where the tips and the thumb
#: are seen on the object side by side.
GRASP_VIEWS = (("palm side (as Fig. 2)", PALM_CAMERA), ("from above the fingertips (palm below)", ABOVE_CAMERA))


def draw_grasp_row(
    axes: Sequence[Any],
    hand: Any,
    obj: Any,
    table: pd.DataFrame,
    cameras: Sequence[Camera] = (PALM_CAMERA,),
    oppositions: Mapping[int, str] | None = None,
) -> None:
    """One row of Fig. 2 on ``axes``: the representative grasps of ``obj`` (a
    ``synergrasp.simulation.objects.GraspedObject``) in its contacts ``table``
    (``synergrasp.analysis.realism.representative_grasps``), each drawn from every camera of
    ``cameras`` (grasp c on ``axes[c * len(cameras) + v]``), one window per camera, with the
    touching links, the contact points, the touching links in words and, where
    ``oppositions`` (pose -> class, docs/opposition.md) is given, the grasp's opposition."""
    k = len(cameras)
    n_grasps = len(axes) // k
    chosen = representative_grasps(table, n_grasps)
    simulated = int(table["status"].isin(SIMULATED_STATUSES).sum())
    rows = [table[table["pose"] == pose].iloc[0] for pose in chosen["pose"]]
    fitted = [
        _fit(camera, hand, [np.asarray(row["q"], dtype=float) for row in rows], [object_of(row, obj.shape) for row in rows])
        if rows
        else camera
        for camera in cameras
    ]
    pictures, thumbs = [], []
    axes[0].set_ylabel(f"{obj.name}\n{obj.shape.label}", fontsize=10)
    for ax in axes:
        _bare(ax)
    for c in range(n_grasps):
        if c >= len(chosen):
            axes[c * k].text(
                0.5,
                0.5,
                "no other contact set" if c else f"no grasp with contacts\n({simulated} simulated)",
                ha="center",
                va="center",
                transform=axes[c * k].transAxes,
                fontsize=8,
                color="0.4",
            )
            continue
        pick, row = chosen.iloc[c], rows[c]
        q = np.asarray(row["q"], dtype=float)
        kind = "" if oppositions is None else f"\n{oppositions.get(int(pick['pose']), 'none')} opposition"
        for v, camera in enumerate(fitted):
            ax = axes[c * k + v]
            picture = draw_grasp(ax, hand, q, object_of(row, obj.shape), pick["pattern"], row["contact_point"], camera)
            pictures.append((ax, picture))
            thumbs.append((ax, picture, q))
            if v == 0:
                ax.set_title(
                    f"{pick['reason']}: {pick['share_pct']:.0f} % of grasps\n"
                    f"α = {pick['alpha_deg']:g}°, β = {pick['beta_deg']:g}°, {int(row['n_contacts'])} contacts"
                    f"{kind}",
                    fontsize=8,
                )
                ax.set_xlabel(_touching_words(hand, pick["pattern"]), fontsize=7, labelpad=2)
            else:
                ax.set_title("the same grasp,\nfrom above the fingertips" if k == 2 else f"view {v + 1}", fontsize=8)
    for v in range(k):
        mine = [(ax, p) for i, (ax, p) in enumerate(pictures) if i % k == v]
        if mine:
            _frame([ax for ax, _ in mine], [p for _, p in mine])
    for ax, picture, q in thumbs:
        _label(ax, "thumb", picture.pixels(_thumb_point(hand, q)[None])[0], picture.pixels(_palm_point(hand)[None])[0])


def figure_example_grasps(
    hand: Any,
    objects: Sequence[Any],
    tables: Sequence[pd.DataFrame],
    png_path: str | Path,
    pdf_path: str | Path,
    n_grasps: int = FIG2_GRASPS,
    cameras: Sequence[Camera] = tuple(c for _, c in GRASP_VIEWS),
    oppositions: Sequence[Mapping[int, str]] | None = None,
) -> None:
    """Fig. 2: representative simulated grasps, one row per object, chosen by rule
    (``synergrasp.analysis.realism.representative_grasps``: the most common set of touching
    links, the most common one at the typical contact count, the next most common), each at
    its pose nearest (α, β) = (0, 0), each from the palm side (the view of Fig. 1) and from
    above the fingertips (``GRASP_VIEWS``). ``objects`` are
    ``synergrasp.simulation.objects.GraspedObject``; ``tables[i]`` is the contacts table of
    ``objects[i]``; ``oppositions[i]`` its grasps' opposition by pose (titles name it).
    Links touching the object are highlighted, contact points are dots (hollow where the
    hand hides them); the object is see-through.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if len(objects) != len(tables):
        raise ValueError(f"objects and tables must have the same length, got {len(objects)} and {len(tables)}")
    panel, k = 2.4, len(cameras)  # inches
    fig, axes = plt.subplots(
        len(objects), n_grasps * k, figsize=(panel * n_grasps * k + 0.5, panel * len(objects) + 0.9), squeeze=False
    )
    for r, (obj, table) in enumerate(zip(objects, tables)):
        draw_grasp_row(axes[r], hand, obj, table, cameras, None if oppositions is None else oppositions[r])
    _legend(fig)
    fig.tight_layout(rect=(0, 0.035, 1, 1), h_pad=0.6, w_pad=0.3)
    save_figure(fig, png_path, pdf_path)


def figure_grasp_views(
    hand: Any,
    shape: ShapeInPicture,
    q: ArrayLike,
    links: Sequence[int],
    points_mm: ArrayLike,
    title: str,
    png_path: str | Path,
    pdf_path: str | Path | None = None,
    views: Sequence[tuple[str, Camera]] = GRASP_VIEWS,
) -> None:
    """One grasp drawn as in Fig. 2 from each of ``views`` (name, camera): the hand at q
    (rad), the object ``shape`` see-through, the ``links`` touching it highlighted (hand
    link indices, one per contact), the contact points (mm, palm frame)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    q = np.asarray(q, dtype=float)
    touching = sorted({int(k) for k in links})
    panel = 3.0  # inches
    fig, axes = plt.subplots(1, len(views), figsize=(panel * len(views) + 0.4, panel + 1.3), squeeze=False)
    for ax, (name, camera) in zip(axes[0], views):
        picture = draw_grasp(ax, hand, q, shape, touching, points_mm, _fit(camera, hand, [q], [shape]))
        _bare(ax)
        _frame([ax], [picture])
        _label(ax, "thumb", picture.pixels(_thumb_point(hand, q)[None])[0], picture.pixels(_palm_point(hand)[None])[0])
        ax.set_title(name, fontsize=9)
    fig.suptitle(title, fontsize=9)
    fig.text(0.5, 0.13, _touching_words(hand, touching).replace("\n", " "), ha="center", va="bottom", fontsize=8)
    _legend(fig, ncol=3)
    fig.tight_layout(rect=(0, 0.16, 1, 1), w_pad=0.4)
    save_figure(fig, png_path, pdf_path)
