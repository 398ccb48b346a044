"""Headless pictures of the hand (Fig. 1) and of simulated grasps (Fig. 2).

The figures are vector drawings from the hand's own kinematics (``draw_hand``): in an
orthographic view a capsule's image is exactly a stadium (two discs of its radius around
the projected end centres, joined), so every phalanx keeps its true outline; the palm and
the box are polygons, painted far to near, farther parts paler. ``render_posture`` keeps
pybullet's software renderer (ER_TINY_RENDERER, DIRECT mode) for a quick raster check.
Camera positions are in the palm frame, mm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["View", "PALM_VIEW", "SIDE_VIEW", "FIGURE_VIEW", "HandCapsules", "render_posture", "hand_capsules",
           "draw_hand", "figure_synergy_postures", "figure_example_grasps"]


class View:
    """A camera looking from ``eye_mm`` at ``target_mm`` (palm frame, mm) with ``up`` up."""

    def __init__(self, eye_mm: Sequence[float], target_mm: Sequence[float], up: Sequence[float] = (0.0, 0.0, 1.0),
                 fov_deg: float = 40.0) -> None:
        self.eye_mm = np.asarray(eye_mm, dtype=float)
        self.target_mm = np.asarray(target_mm, dtype=float)
        self.up = np.asarray(up, dtype=float)
        self.fov_deg = float(fov_deg)


#: Three-quarter view from the palm side, thumb toward the viewer's right, fingers up.
PALM_VIEW = View(eye_mm=(260.0, 150.0, 150.0), target_mm=(10.0, -5.0, 100.0), up=(0.0, 0.0, 1.0))
#: Side view (from the thumb side): flexion happens in the image plane.
SIDE_VIEW = View(eye_mm=(60.0, 300.0, 110.0), target_mm=(20.0, -5.0, 105.0), up=(0.0, 0.0, 1.0))


def render_posture(hand: Any, q: NDArray, view: View = PALM_VIEW, box: tuple[NDArray, Any] | None = None,
                   size_px: tuple[int, int] = (320, 320), client: int | None = None,
                   body: Any | None = None) -> NDArray:
    """RGB image (h, w, 3) uint8 of the hand at q (rad), optionally with a box.

    ``box`` = (size_mm, ObjectPose) as made by ``synergrasp.simulation.placement.object_pose``.
    """
    import pybullet as pb

    from synergrasp.simulation import bullet

    own = client is None
    if own:
        client = bullet.connect()
        body = bullet.load_hand_body(client, hand)
    try:
        for link in range(-1, pb.getNumJoints(body.body, physicsClientId=client)):
            pb.changeVisualShape(body.body, link, rgbaColor=[0.93, 0.78, 0.66, 1.0], physicsClientId=client)
        bullet.set_posture(client, body, np.asarray(q, dtype=float))
        box_id = None
        if box is not None:
            size, placed = box
            box_id = bullet.load_box(client, np.asarray(size, dtype=float), placed.center_mm, placed.rotation)
            pb.changeVisualShape(box_id, -1, rgbaColor=[0.35, 0.55, 0.85, 1.0], physicsClientId=client)
        w, h = size_px
        view_m = pb.computeViewMatrix((view.eye_mm * 1e-3).tolist(), (view.target_mm * 1e-3).tolist(),
                                      view.up.tolist(), physicsClientId=client)
        proj = pb.computeProjectionMatrixFOV(view.fov_deg, w / h, 0.01, 2.0, physicsClientId=client)
        img = pb.getCameraImage(w, h, view_m, proj, renderer=pb.ER_TINY_RENDERER,
                                lightDirection=(view.eye_mm / np.linalg.norm(view.eye_mm)).tolist(),
                                shadow=0, physicsClientId=client)
        rgb = np.reshape(np.asarray(img[2], dtype=np.uint8), (h, w, 4))[:, :, :3].copy()
        if box_id is not None:
            bullet.remove_body(client, box_id)
        return rgb
    finally:
        if own:
            bullet.disconnect(client)


# --------------------------------------------------------------------------------------
# Vector drawing of the hand from its own kinematics (figures)
# --------------------------------------------------------------------------------------

#: Three-quarter view for the figures: from the little-finger side, somewhat in front of the
#: palm and above, fingers up. Flexion (toward +x, the palm normal) runs across the image
#: toward the right, and the thumb, unhidden behind the hand, swings out to the right in
#: front of the palm as it opposes.
FIGURE_VIEW = View(eye_mm=(290.0, -405.0, 245.0), target_mm=(10.0, -5.0, 95.0), up=(0.0, 0.0, 1.0))

#: Fill colour per finger (FINGERS order: thumb, index, middle, ring, little) and of the palm.
_FINGER_COLOURS = ("#d95f02", "#1b9e77", "#7570b3", "#e7298a", "#66a61e")
_PALM_COLOUR = "#c9b8a6"
_BOX_COLOUR = "#4a78c2"


@dataclass(frozen=True)
class HandCapsules:
    """The hand's capsules at a posture, palm frame, mm.

    ends:   (n, 2, 3) centres of the two end spheres of each capsule
    radius: (n,) capsule radii
    link:   (n,) hand link index of each capsule
    palm_corners: (8, 3) corners of the palm box (empty (0, 3) if the palm has no box)
    """

    ends: NDArray
    radius: NDArray
    link: NDArray
    palm_corners: NDArray


def hand_capsules(hand: Any, q: NDArray) -> HandCapsules:
    """Capsules (and palm box corners) of ``hand`` at joint angles q (rad), from
    ``hand.forward_kinematics``; lengths in mm, palm frame."""
    from synergrasp.hand.kinematics import forward_kinematics

    frames = forward_kinematics(hand, np.asarray(q, dtype=float))
    ends, radius, link, corners = [], [], [], np.zeros((0, 3))
    for i, shapes in enumerate(hand.link_shapes):
        for shape in shapes:
            pose = frames[i] @ shape.pose
            if shape.kind == "capsule":
                half = 0.5 * shape.length * pose[:3, 2]  # capsules lie along their local z
                ends.append((pose[:3, 3] - half, pose[:3, 3] + half))
                radius.append(shape.radius)
                link.append(i)
            elif i == 0:
                corners = _box_corners(np.asarray(shape.size, dtype=float) / 2.0, pose[:3, :3], pose[:3, 3])
    return HandCapsules(np.asarray(ends, dtype=float).reshape(-1, 2, 3), np.asarray(radius, dtype=float),
                        np.asarray(link, dtype=np.int64), corners)


def _box_corners(half: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    return (signs * half) @ np.asarray(rotation).T + np.asarray(center)


#: Faces of the box of ``_box_corners`` (corner indices, counter-clockwise seen from outside).
_BOX_FACES = ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3))


def _view_basis(view: View) -> NDArray:
    """Rows: image right, image up, direction of sight (orthographic camera of ``view``)."""
    forward = view.target_mm - view.eye_mm
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, view.up)
    right = right / np.linalg.norm(right)
    return np.array([right, np.cross(right, forward), forward])


def _stadium(a: NDArray, b: NDArray, r: float, n_arc: int = 16) -> NDArray:
    """Outline (k, 2) of a capsule's orthographic image: two discs of radius r at a and b joined."""
    d = b - a
    theta = math.atan2(d[1], d[0]) if np.hypot(*d) > 1e-9 else 0.0
    t1 = theta + np.linspace(-np.pi / 2, np.pi / 2, n_arc)
    t2 = theta + np.linspace(np.pi / 2, 3 * np.pi / 2, n_arc)
    arc_b = b + r * np.column_stack([np.cos(t1), np.sin(t1)])
    arc_a = a + r * np.column_stack([np.cos(t2), np.sin(t2)])
    return np.vstack([arc_b, arc_a])


def _shade(colour: str, fade: float) -> tuple[float, float, float]:
    """``colour`` mixed with white by ``fade`` in [0, 1] (farther parts paler: a depth cue)."""
    from matplotlib.colors import to_rgb

    rgb = np.asarray(to_rgb(colour))
    return tuple(rgb + (1.0 - rgb) * float(np.clip(fade, 0.0, 1.0)))


def _items(hand: Any, caps: HandCapsules, basis: NDArray, box: tuple[NDArray, Any] | None):
    """Drawable pieces (depth, outline (k, 2) in the image plane, kind, colour)."""
    items = []
    finger_of = {name: k for k, name in enumerate(("thumb", "index", "middle", "ring", "little"))}
    for (a, b), r, link in zip(caps.ends, caps.radius, caps.link):
        pa, pb_ = basis @ a, basis @ b
        fk = finger_of.get(hand.link_finger[link])
        colour = _PALM_COLOUR if fk is None else _FINGER_COLOURS[fk]
        items.append((0.5 * (pa[2] + pb_[2]), _stadium(pa[:2], pb_[:2], r), "hand", colour))
    solids = [(caps.palm_corners, "hand", _PALM_COLOUR)] if len(caps.palm_corners) else []
    if box is not None:
        size, placed = box
        solids.append((_box_corners(np.asarray(size, dtype=float) / 2.0, placed.rotation, placed.center_mm),
                       "box", _BOX_COLOUR))
    for corners, kind, colour in solids:
        centre = corners.mean(axis=0)
        for face in _BOX_FACES:
            pts = corners[list(face)]
            normal = np.cross(pts[1] - pts[0], pts[3] - pts[0])
            if np.dot(normal, pts.mean(axis=0) - centre) < 0:
                normal = -normal
            front = np.dot(normal, basis[2]) < 0  # faces the viewer
            if kind == "hand" and not front:
                continue  # the opaque palm hides its back faces
            proj = pts @ basis.T
            depth = float(proj[:, 2].mean())
            items.append((depth, proj[:, :2], kind if front else "box_back", colour))
    return items


def draw_hand(ax: Any, hand: Any, q: NDArray, view: View = FIGURE_VIEW, box: tuple[NDArray, Any] | None = None,
              contacts_mm: NDArray | None = None, ghost_q: NDArray | None = None,
              depth_range_mm: tuple[float, float] | None = None) -> NDArray:
    """Draw the hand at q (rad) on a 2-D matplotlib axes as seen by the orthographic camera
    ``view``: each capsule is the exact outline of its image (a stadium), the palm and the
    optional box are polygons, painted far to near; farther parts are paler.

    ``box`` = (size_mm, ObjectPose) is drawn translucent, ``contacts_mm`` (m, 3) as dots,
    ``ghost_q`` as a pale grey silhouette under the hand (e.g. the mean posture).
    Returns the (k, 2) image-plane points drawn (mm), for common axis limits.
    """
    from matplotlib.patches import Polygon

    basis = _view_basis(view)
    drawn = []
    if ghost_q is not None:
        for _, outline, kind, _ in _items(hand, hand_capsules(hand, ghost_q), basis, None):
            ax.add_patch(Polygon(outline, closed=True, facecolor="0.88", edgecolor="0.75", linewidth=0.4,
                                 zorder=0.5))
            drawn.append(outline)
    items = _items(hand, hand_capsules(hand, q), basis, box)
    depths = np.array([d for d, *_ in items])
    lo, hi = depth_range_mm if depth_range_mm is not None else (depths.min(), depths.max())
    order = sorted(range(len(items)), key=lambda k: -items[k][0])  # far first
    for z, k in enumerate(order, start=1):
        depth, outline, kind, colour = items[k]
        fade = 0.4 * (depth - lo) / max(hi - lo, 1e-9)
        if kind == "hand":
            patch = Polygon(outline, closed=True, facecolor=_shade(colour, fade), edgecolor="0.15",
                            linewidth=0.6, zorder=1 + z * 1e-3)
        else:  # the box: translucent, so the fingers behind and on it stay visible
            patch = Polygon(outline, closed=True, facecolor=colour, alpha=0.18 if kind == "box_back" else 0.30,
                            edgecolor="#1f3f7a", linewidth=0.7, zorder=1 + z * 1e-3)
        ax.add_patch(patch)
        drawn.append(outline)
    if contacts_mm is not None and len(contacts_mm):
        pts = np.asarray(contacts_mm, dtype=float).reshape(-1, 3) @ basis.T
        ax.scatter(pts[:, 0], pts[:, 1], s=22, c="#d7191c", edgecolors="white", linewidths=0.6, zorder=5)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    return np.vstack(drawn)


def _set_limits(axes: Sequence[Any], points: NDArray, margin_mm: float = 6.0) -> None:
    lo, hi = points.min(axis=0) - margin_mm, points.max(axis=0) + margin_mm
    half = 0.5 * max(hi - lo)
    mid = 0.5 * (lo + hi)
    for ax in axes:
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)


def _draw_triad(ax: Any, view: View, origin: tuple[float, float] = (0.1, 0.1)) -> None:
    """Palm-frame axes in an image corner: x (palm normal), y (thumb side), z (fingers)."""
    basis = _view_basis(view)
    for axis, label in zip(np.eye(3), ("x", "y", "z")):
        d = 0.07 * (basis[:2] @ axis)
        ax.annotate("", xy=(origin[0] + d[0], origin[1] + d[1]), xytext=origin, xycoords="axes fraction",
                    arrowprops=dict(arrowstyle="->", color="0.3", lw=0.9))
        ax.text(origin[0] + 1.35 * d[0], origin[1] + 1.35 * d[1], label, transform=ax.transAxes,
                fontsize=7, color="0.3", ha="center", va="center")


def _save(fig: Any, png_path: str, pdf_path: str) -> None:
    fig.savefig(png_path, dpi=150)
    fig.savefig(pdf_path)


def figure_synergy_postures(hand: Any, synergies: Any, png_path: str, pdf_path: str, n_synergies: int = 7,
                            sigmas: Sequence[float] = (-1.0, 0.0, 1.0), view: View = FIGURE_VIEW) -> None:
    """Fig. 1: the hand at q_m + σ·S_k (joint limits clip) for k = 1..n_synergies (rows) and
    σ in ``sigmas`` (columns), drawn from the hand's kinematics (``draw_hand``) in a
    three-quarter view; the mean posture q_m is the grey silhouette under the σ ≠ 0 panels."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    matrix = np.asarray(synergies.matrix, dtype=float)
    if not 1 <= n_synergies <= matrix.shape[1]:
        raise ValueError(f"n_synergies must be in 1 … {matrix.shape[1]}, got {n_synergies}")
    mean = np.clip(np.asarray(synergies.mean, dtype=float), hand.lower, hand.upper)
    panel = 2.9  # inches
    fig, axes = plt.subplots(n_synergies, len(sigmas), figsize=(panel * len(sigmas), panel * n_synergies + 0.5),
                             squeeze=False)
    points = []
    for k in range(n_synergies):
        for c, sigma in enumerate(sigmas):
            q = np.clip(mean + sigma * matrix[:, k], hand.lower, hand.upper)
            ax = axes[k, c]
            points.append(draw_hand(ax, hand, q, view, ghost_q=None if sigma == 0 else mean))
            if k == 0:
                ax.set_title(f"σ = {sigma:+g}", fontsize=11)
            if c == 0:
                ax.set_ylabel(f"S{k + 1}", fontsize=12)
            for spine in ax.spines.values():
                spine.set_color("0.8")
    _set_limits(axes.ravel(), np.vstack(points))
    _draw_triad(axes[0, 0], view)
    fig.suptitle("Hand postures along each synergy (grey: mean posture)", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.995))
    _save(fig, png_path, pdf_path)
    plt.close(fig)


def figure_example_grasps(hand: Any, boxes: Sequence[Any], tables: Sequence[Any], poses: Sequence[Sequence[float]],
                          png_path: str, pdf_path: str, view: View = FIGURE_VIEW) -> None:
    """Fig. 2: simulated grasps, one row per box, one column per (α, β) in deg of ``poses``.

    ``tables[i]`` is the contacts table of ``boxes[i]`` (it holds the final q, the box pose
    and the contact points of each grasp); a pose missing from a table is drawn empty. The
    box is translucent, contact points are red dots; the panels of a row share one scale.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp.simulation.placement import ObjectPose

    if len(boxes) != len(tables):
        raise ValueError(f"boxes and tables must have the same length, got {len(boxes)} and {len(tables)}")
    panel = 3.0  # inches
    fig, axes = plt.subplots(len(boxes), len(poses), figsize=(panel * len(poses), panel * len(boxes)),
                             squeeze=False)
    for r, (box, table) in enumerate(zip(boxes, tables)):
        points = []
        for c, (alpha, beta) in enumerate(poses):
            ax = axes[r, c]
            ax.set_xticks([])
            ax.set_yticks([])
            for spine in ax.spines.values():
                spine.set_color("0.8")
            da = (table["alpha_deg"].to_numpy() - alpha + 180.0) % 360.0 - 180.0
            hit = table[(np.abs(da) < 1e-6) & (np.abs(table["beta_deg"].to_numpy() - beta) < 1e-6)]
            if c == 0:
                ax.set_ylabel(str(box.name), fontsize=11)
            if hit.empty:
                ax.set_title(f"α={alpha:g}°, β={beta:g}°\n(not simulated)", fontsize=9)
                continue
            row = hit.iloc[0]
            size = np.asarray(box.size_mm, dtype=float)
            placed = ObjectPose(np.asarray(row["object_center"], dtype=float),
                                np.asarray(row["object_rotation"], dtype=float).reshape(3, 3), size / 2.0)
            contacts = np.asarray(row["contact_point"], dtype=float).reshape(-1, 3)
            points.append(draw_hand(ax, hand, np.asarray(row["q"], dtype=float), view, box=(size, placed),
                                    contacts_mm=contacts))
            ax.set_title(f"α={alpha:g}°, β={beta:g}°\n{row['status']}, m={int(row['n_contacts'])}", fontsize=9)
        if points:
            _set_limits(axes[r], np.vstack(points))
    _draw_triad(axes[0, 0], view)
    fig.tight_layout()
    _save(fig, png_path, pdf_path)
    plt.close(fig)
