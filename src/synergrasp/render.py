"""Headless pictures of the hand (Fig. 1) and of simulated grasps (Fig. 2).

pybullet's software renderer (ER_TINY_RENDERER, DIRECT mode, no display) draws the hand's
collision-sized visual shapes; matplotlib assembles the panels into PNG and PDF files.
Camera positions are in the palm frame, mm.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["View", "PALM_VIEW", "render_posture", "figure_synergy_postures", "figure_example_grasps"]


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

    ``box`` = (size_mm, ObjectPose) as made by ``synergrasp.closure.object_pose``.
    """
    import pybullet as pb

    from synergrasp import bullet

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


def _save(fig: Any, png_path: str, pdf_path: str) -> None:
    fig.savefig(png_path, dpi=150)
    fig.savefig(pdf_path)


def figure_synergy_postures(hand: Any, synergies: Any, png_path: str, pdf_path: str, n_synergies: int = 7,
                            sigmas: Sequence[float] = (-1.0, 0.0, 1.0), view: View = PALM_VIEW) -> None:
    """Fig. 1: the hand at q_m + σ·S_k (joint limits clip) for k = 1..n_synergies (rows) and
    σ in ``sigmas`` (columns)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp import bullet

    matrix = np.asarray(synergies.matrix, dtype=float)
    if not 1 <= n_synergies <= matrix.shape[1]:
        raise ValueError(f"n_synergies must be in 1 … {matrix.shape[1]}, got {n_synergies}")
    mean = np.asarray(synergies.mean, dtype=float)
    client = bullet.connect()
    body = bullet.load_hand_body(client, hand)
    try:
        fig, axes = plt.subplots(n_synergies, len(sigmas), figsize=(2.0 * len(sigmas), 2.0 * n_synergies),
                                 squeeze=False)
        for k in range(n_synergies):
            for c, sigma in enumerate(sigmas):
                q = np.clip(mean + sigma * matrix[:, k], hand.lower, hand.upper)
                ax = axes[k, c]
                ax.imshow(render_posture(hand, q, view, client=client, body=body))
                ax.set_xticks([])
                ax.set_yticks([])
                if k == 0:
                    ax.set_title(f"σ = {sigma:+g}", fontsize=10)
                if c == 0:
                    ax.set_ylabel(f"S{k + 1}", fontsize=10)
        fig.tight_layout()
        _save(fig, png_path, pdf_path)
        plt.close(fig)
    finally:
        bullet.disconnect(client)


def figure_example_grasps(hand: Any, boxes: Sequence[Any], tables: Sequence[Any], poses: Sequence[Sequence[float]],
                          png_path: str, pdf_path: str, view: View = PALM_VIEW) -> None:
    """Fig. 2: simulated grasps, one row per box, one column per (α, β) in deg of ``poses``.

    ``tables[i]`` is the contacts table of ``boxes[i]`` (it holds the final q and the box
    pose of each grasp); a pose missing from a table, or flagged, is drawn empty.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp import bullet
    from synergrasp.closure import ObjectPose

    if len(boxes) != len(tables):
        raise ValueError(f"boxes and tables must have the same length, got {len(boxes)} and {len(tables)}")
    client = bullet.connect()
    body = bullet.load_hand_body(client, hand)
    try:
        fig, axes = plt.subplots(len(boxes), len(poses), figsize=(2.4 * len(poses), 2.4 * len(boxes)),
                                 squeeze=False)
        for r, (box, table) in enumerate(zip(boxes, tables)):
            for c, (alpha, beta) in enumerate(poses):
                ax = axes[r, c]
                ax.set_xticks([])
                ax.set_yticks([])
                da = (table["alpha_deg"].to_numpy() - alpha + 180.0) % 360.0 - 180.0
                hit = table[(np.abs(da) < 1e-6) & (np.abs(table["beta_deg"].to_numpy() - beta) < 1e-6)]
                if c == 0:
                    ax.set_ylabel(str(box.name), fontsize=10)
                if hit.empty:
                    ax.set_title(f"α={alpha:g}°, β={beta:g}°\n(not simulated)", fontsize=8)
                    continue
                row = hit.iloc[0]
                placed = ObjectPose(np.asarray(row["object_center"], dtype=float),
                                    np.asarray(row["object_rotation"], dtype=float).reshape(3, 3),
                                    np.asarray(box.size_mm, dtype=float) / 2.0)
                image = render_posture(hand, np.asarray(row["q"], dtype=float), view,
                                       box=(np.asarray(box.size_mm, dtype=float), placed), client=client, body=body)
                ax.imshow(image)
                ax.set_title(f"α={alpha:g}°, β={beta:g}°\n{row['status']}, m={int(row['n_contacts'])}", fontsize=8)
        fig.tight_layout()
        _save(fig, png_path, pdf_path)
        plt.close(fig)
    finally:
        bullet.disconnect(client)
