"""Headless pictures: the renderer draws the hand, S1 changes the picture, figures are written."""

from __future__ import annotations

import numpy as np
import pytest

from synergrasp.simulation.closure import ClosureParams, simulate_object
from synergrasp.simulation.placement import Placement, pose_grid
from synergrasp.simulation.objects import Box
from synergrasp.figures.hand_drawing import figure_example_grasps, figure_synergy_postures, render_posture


def _hand_pixels(image):
    return np.count_nonzero(np.any(image < 250, axis=2))


def test_render_draws_the_hand_and_closing_changes_it(hand, synergies):
    s1 = synergies.matrix[:, 0]
    open_ = render_posture(hand, np.clip(synergies.mean - s1, hand.lower, hand.upper))
    closed = render_posture(hand, np.clip(synergies.mean + 2 * s1, hand.lower, hand.upper))
    assert open_.shape == (320, 320, 3) and open_.dtype == np.uint8
    assert _hand_pixels(open_) > 0.03 * open_.shape[0] * open_.shape[1]
    assert np.mean(np.abs(open_.astype(int) - closed.astype(int))) > 1.0


def test_figures_are_written(hand, synergies, tmp_path):
    figure_synergy_postures(hand, synergies, str(tmp_path / "f1.png"), str(tmp_path / "f1.pdf"), n_synergies=2)
    box = Box("obj1", (30.0, 30.0, 30.0), 1.0)
    placement = Placement()
    pose = pose_grid(placement).index(0.0, 0.0)
    table = simulate_object(hand, synergies, box, placement, ClosureParams(), poses=[pose])
    figure_example_grasps(hand, [box], [table], [(0.0, 0.0), (90.0, 0.0)],
                          str(tmp_path / "f2.png"), str(tmp_path / "f2.pdf"))
    for name in ("f1.png", "f1.pdf", "f2.png", "f2.pdf"):
        assert (tmp_path / name).stat().st_size > 1000


def test_capsules_end_at_the_fingertips(hand):
    """The distal capsule's far end (sphere centre + radius along the axis) is the fingertip."""
    from synergrasp.hand.kinematics import fingertip_positions
    from synergrasp.figures.hand_drawing import hand_capsules

    rng = np.random.default_rng(3)
    for _ in range(3):
        q = rng.uniform(hand.lower, hand.upper)
        caps = hand_capsules(hand, q)
        tips = fingertip_positions(hand, q)
        for f, link in enumerate(hand.fingertip_link):
            (a, b), r = caps.ends[caps.link == link][0], caps.radius[caps.link == link][0]
            axis = (b - a) / np.linalg.norm(b - a)
            ends = np.array([a - r * axis, b + r * axis])
            assert np.min(np.linalg.norm(ends - tips[f], axis=1)) < 1e-9
        assert caps.palm_corners.shape == (8, 3)
        np.testing.assert_allclose(caps.palm_corners.min(axis=0), [-14.5, -48.0, 14.0], atol=1e-9)


def test_drawing_spans_the_projected_capsules_and_closing_moves_toward_the_palm_side(hand, synergies):
    """Outline extent = capsule ends ± radius in the orthographic image (to the arc sampling);
    in the figure view the palm normal points to the image right, so flexing the straight
    long fingers moves their tips to the right."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp.hand.kinematics import fingertip_positions
    from synergrasp.figures.hand_drawing import FIGURE_VIEW, draw_hand, hand_capsules

    eye = FIGURE_VIEW.target_mm - FIGURE_VIEW.eye_mm
    forward = eye / np.linalg.norm(eye)
    right = np.cross(forward, FIGURE_VIEW.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    q = np.clip(synergies.mean, hand.lower, hand.upper)
    fig, ax = plt.subplots()
    drawn = draw_hand(ax, hand, q)
    plt.close(fig)
    caps = hand_capsules(hand, q)
    for direction, column in ((right, 0), (up, 1)):
        ends = caps.ends @ direction
        expected_hi = max(np.max(ends.max(axis=1) + caps.radius), np.max(caps.palm_corners @ direction))
        expected_lo = min(np.min(ends.min(axis=1) - caps.radius), np.min(caps.palm_corners @ direction))
        assert abs(drawn[:, column].max() - expected_hi) < 0.05
        assert abs(drawn[:, column].min() - expected_lo) < 0.05
    assert right @ hand.palm_normal > 0.5
    flat = np.zeros(hand.n_joints)
    flexed = flat.copy()
    flexed[[j for joints in hand.finger_joints[1:] for j in joints[1:]]] = 0.4  # MCP, PIP, DIP
    moved = (fingertip_positions(hand, flexed) - fingertip_positions(hand, flat))[1:] @ right
    assert np.mean(moved) > 5.0
