"""The thumb-opposition check (synergrasp.simulation.thumb_check, docs/synergies.md): along S1 the
thumb meets the index or middle fingertip 20 mm in front of the palm face, no thumb link on
the palm before. Checked on the shipped hands, on the Shadow hand's joint-by-joint mapping
(a thumb folded onto the palm: it must fail) and against the hands' geometry computed here."""

import numpy as np
import pytest

from synergrasp.hand.kinematics import fingertip_positions, forward_kinematics, load_hand
from synergrasp.hand.synergies import (
    SynergyPath,
    load_human_synergies,
    load_synergies,
    load_synergy_mapping,
    map_human_synergies,
    shadow_hand_files,
)
from synergrasp.simulation.thumb_check import MIN_FRONT_MM, closing_sigmas, thumb_opposition


def _capsule_gap(hand, q, a, b):
    """Distance (mm) between the capsules of links a and b at q, sampled densely (401 points per
    axis): an independent reading of the hand's geometry."""
    frames = forward_kinematics(hand, q)

    def segment(link):
        (shape,) = hand.link_shapes[link]
        pose = frames[link] @ shape.pose
        half = 0.5 * shape.length * pose[:3, 2]
        t = np.linspace(0.0, 1.0, 401)[:, None]
        return pose[:3, 3] - half + t * 2 * half, shape.radius

    (pa, ra), (pb, rb) = segment(a), segment(b)
    return float(np.min(np.linalg.norm(pa[:, None] - pb[None], axis=2))) - ra - rb


def _joint_by_joint_shadow():
    hand_path, mapping_path, _ = shadow_hand_files()
    hand = load_hand(hand_path)
    return hand, map_human_synergies(load_human_synergies(), load_synergy_mapping(mapping_path), hand.joint_names)


def test_the_shadow_joint_by_joint_mapping_fails_on_the_palm():
    """The deliberately broken mapping (the Shadow's former table: THJ4 driven by the human j1,
    the thumb flexions copied from the SoftHand's ratios): the thumb's middle link is on the
    palm from the start of the closure, and the fingertips meet the thumb at the palm face."""
    hand, table = _joint_by_joint_shadow()
    check = thumb_opposition(hand, table)
    assert not check.opposes
    assert check.palm_link == "thumb_middle" and check.palm_sigma == pytest.approx(-2.28, abs=0.02)
    assert check.meet_sigma is not None and check.front_mm < 5.0
    warning = check.warning()
    assert "hand 'shadow_hand'" in warning and "sigma = -2.29" in warning and "thumb_middle" in warning
    assert "\n" not in warning


def test_the_meeting_agrees_with_the_hands_geometry():
    """Where the check says the thumb meets a finger, the independently sampled capsules touch
    (and did not one step before); its height is the fingertips' along the palm normal above
    the palm face (the outermost point of the palm's boxes)."""
    hand, table = _joint_by_joint_shadow()
    check = thumb_opposition(hand, table)
    path = SynergyPath.along(table, hand.lower, hand.upper)
    lo, hi = path.closure_range(hand.flexion_joints)
    step = (hi - lo) / 4000
    thumb, partner = hand.link_index("thumb_distal"), hand.link_index(f"{check.partner}_distal")
    assert _capsule_gap(hand, path.reference(check.meet_sigma), thumb, partner) <= 0.05
    assert _capsule_gap(hand, path.reference(check.meet_sigma - step), thumb, partner) > -0.05
    face = max(float(np.max(s.pose[0, 3] + 0.5 * np.abs(s.pose[0, :3]) @ s.size)) for s in hand.link_shapes[0])
    tips = fingertip_positions(hand, path.reference(check.meet_sigma))
    f = ("thumb", "index", "middle").index(check.partner)
    assert check.front_mm == pytest.approx(min(tips[0, 0], tips[f, 0]) - face, abs=1e-9)


def test_the_shipped_shadow_table_keeps_the_thumb_off_the_palm():
    """The object-based mapping: no thumb link touches the palm before the thumb meets the
    middle fingertip, 16.5 mm in front of the palm face: below the check's 20 mm, so it warns
    (measured; docs/synergies.md), and passes a 15 mm threshold."""
    hand = load_hand("shadow_hand")
    check = thumb_opposition(hand, load_synergies("shadow_hand", joint_names=hand.joint_names))
    assert check.palm_sigma is None and check.partner == "middle"
    assert 15.0 < check.front_mm < MIN_FRONT_MM and not check.opposes
    assert closing_sigmas(check) == [-1.0, 0.0, 1.0, round(check.meet_sigma, 2)]


@pytest.mark.parametrize("table", ["softhand_opposed", "softhand_human_higher"])
def test_the_study_hand_folds_its_thumb_onto_the_palm_before_the_pinch(table):
    """Measured on the study's own hand: along S1 the thumb's distal link reaches the palm at
    σ ≈ 1.31 and meets the middle fingertip at σ ≈ 1.60, 2 mm below the palm face: the check
    warns on the SoftHand too (docs/synergies.md)."""
    hand = load_hand(None)
    check = thumb_opposition(hand, load_synergies(table))
    assert check.palm_link == "thumb_distal" and check.palm_sigma == pytest.approx(1.31, abs=0.01)
    assert check.partner == "middle" and check.meet_sigma == pytest.approx(1.60, abs=0.01)
    assert check.front_mm == pytest.approx(-2.0, abs=0.1) and not check.opposes
    path = SynergyPath.along(load_synergies(table), hand.lower, hand.upper)
    palm = hand.link_shapes[0][0]
    tip = fingertip_positions(hand, path.reference(check.palm_sigma))[0]  # the thumb's tip over the palm box
    assert abs(tip[1] - palm.pose[1, 3]) < palm.size[1] / 2 and abs(tip[2] - palm.pose[2, 3]) < palm.size[2] / 2


def test_workflow_checks_and_hand_show_warn(tmp_path, capsys):
    from synergrasp.cli import main
    from synergrasp.input_checks import checked_scenario

    _, warnings = checked_scenario({"hand": "shadow_hand", "synergies": "shadow_hand"})
    assert [w for w in warnings if w.startswith("thumb opposition: hand 'shadow_hand': along S1 the thumb meets")]
    png = tmp_path / "closing.png"
    assert main(["hand", "show", "shadow_hand", "--closing-png", str(png)]) == 0
    out = capsys.readouterr().out
    assert "WARNING: thumb opposition: hand 'shadow_hand'" in out and png.stat().st_size > 10_000


def test_a_table_whose_s1_opens_a_joint_cannot_be_checked_and_says_why():
    """S1 with a negative flexion entry does not close the hand: no check, one warning line
    naming the hand and the reason (the closure's own message), not a traceback."""
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.thumb_check import opposition_line, opposition_warnings

    hand = load_hand(None)
    table = load_synergies(None)
    matrix = table.matrix.copy()
    matrix[hand.joint_names.index("index_pip"), 0] = -0.1
    broken = Synergies(table.joint_names, table.mean, matrix, table.names)
    (warning,) = opposition_warnings(hand, broken)
    assert (
        warning.startswith(
            "thumb opposition: hand 'softhand_like': cannot be checked: the closing synergy S1 must have flexion entries >= 0"
        )
        and "\n" not in warning
    )
    assert opposition_line(hand, broken) == (f"WARNING: {warning}", [-1.0, 0.0, 1.0])
