"""Headless pictures: the renderer draws the hand, S1 changes the picture, figures are written."""

from __future__ import annotations

import numpy as np
import pytest

from synergrasp.closure import ClosureParams, Placement, pose_grid, simulate_object
from synergrasp.hand import load_hand
from synergrasp.objects import Box
from synergrasp.render import figure_example_grasps, figure_synergy_postures, render_posture
from synergrasp.synergies import load_synergies


@pytest.fixture(scope="module")
def hand():
    return load_hand()


@pytest.fixture(scope="module")
def synergies(hand):
    return load_synergies(None, joint_names=hand.joint_names)


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
