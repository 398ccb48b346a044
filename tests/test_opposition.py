"""The opposition rule on hand-made grasps whose answer is known (docs/opposition.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from synergrasp.config import defaults
from synergrasp.hand.kinematics import load_hand
from synergrasp.simulation.opposition import (
    GRASP_TYPES,
    HandAxes,
    OppositionRule,
    classify_grasp,
    contacts_oppositions,
    face_classes,
    of_grasp_type,
    surface_features,
)
from synergrasp.simulation.shapes import shape_from_config

RULE = OppositionRule(45.0, 1.0)
X, Y, Z = np.eye(3)


@pytest.fixture(scope="module")
def hand():
    return load_hand()


@pytest.fixture(scope="module")
def axes(hand):
    return HandAxes.from_hand(hand)


def link(hand, name):
    return hand.link_index(name)


def test_the_shipped_hands_axes_and_link_kinds(hand, axes):
    assert np.allclose(axes.palm_normal, X)
    assert np.allclose(axes.finger_axis, Z, atol=0.05)  # knuckles lie beyond the palm centre along z
    assert math.isclose(float(axes.lateral_axis @ axes.finger_axis), 0.0, abs_tol=1e-12)
    kinds = dict(zip(hand.link_names, axes.link_kind))
    assert kinds["palm"] == "palm"
    assert kinds["thumb_distal"] == "thumb_pad" and kinds["thumb_knuckle"] == kinds["thumb_proximal"] == "thumb_base"
    for finger in ("index", "middle", "ring", "little"):
        assert kinds[f"{finger}_distal"] == "finger_pad" and kinds[f"{finger}_middle"] == "finger_middle"
        assert kinds[f"{finger}_knuckle"] == kinds[f"{finger}_proximal"] == "palm_side"
    assert {hand.link_names[i] for i in axes.index_links} == {f"index_{s}" for s in ("knuckle", "proximal", "middle", "distal")}


def test_a_box_squeezed_between_palm_and_fingers_is_palm_opposition(hand, axes):
    # the palm pushes the box off the palm (+x), two fingertips push it back (-x)
    links = [link(hand, "palm"), link(hand, "middle_distal"), link(hand, "ring_distal")]
    assert classify_grasp(links, np.array([X, -X, -X]), axes, RULE) == "palm"
    # a proximal phalanx may stand for the palm, the thumb for the fingers
    links = [link(hand, "index_proximal"), link(hand, "thumb_distal")]
    assert classify_grasp(links, np.array([X, -X]), axes, RULE) == "palm"


def test_a_pinch_between_thumb_and_fingertip_pads_is_pad_opposition(hand, axes):
    links = [link(hand, "thumb_distal"), link(hand, "index_distal"), link(hand, "middle_distal")]
    assert classify_grasp(links, np.array([-Y, Y, Y]), axes, RULE) == "pad"
    # the same pinch with the palm touching is not pad opposition: the palm carries load
    assert classify_grasp(links + [link(hand, "palm")], np.array([-Y, Y, Y, Z]), axes, RULE) == "none"


def test_the_thumb_pad_against_the_side_of_the_index_is_side_opposition(hand, axes):
    links = [link(hand, "thumb_distal"), link(hand, "index_middle")]
    assert classify_grasp(links, np.array([Y, -Y]), axes, RULE) == "side"
    # the same pair pushing along the fingers is no side of the index
    assert classify_grasp(links, np.array([Z, -Z]), axes, RULE) == "none"


def test_a_one_sided_fingertip_push_is_no_opposition(hand, axes):
    # obj4's grasp: the palm and the fingertips all push the box away from the palm (+x),
    # the thumb and little tips touch its sides
    links = [link(hand, n) for n in ("palm", "index_distal", "middle_distal", "ring_distal", "thumb_distal", "little_distal")]
    normals = np.array([X, X, X, X, -Y, Y])
    assert classify_grasp(links, normals, axes, RULE) == "none"
    assert classify_grasp(links[:1], normals[:1], axes, RULE) == "none"
    assert classify_grasp([], np.zeros((0, 3)), axes, RULE) == "none"


@pytest.mark.parametrize("degrees, expected", [(44.0, "palm"), (46.0, "none")])
def test_the_angle_bounds_the_push_toward_the_palm(hand, axes, degrees, expected):
    a = math.radians(degrees)
    tilted = -math.cos(a) * X + math.sin(a) * Z  # a fingertip push tilted off the palm normal's reverse
    links = [link(hand, "palm"), link(hand, "middle_distal")]
    assert classify_grasp(links, np.array([X, tilted]), axes, RULE) == expected
    # a wider rule accepts what the default refuses
    assert classify_grasp(links, np.array([X, tilted]), axes, OppositionRule(50.0, 1.0)) == "palm"


def test_grasp_types_and_the_rule_from_the_configuration():
    assert of_grasp_type("palm", "power") and not of_grasp_type("pad", "power")
    assert of_grasp_type("pad", "precision") and not of_grasp_type("side", "precision")
    assert all(of_grasp_type(o, "any") for o in ("palm", "pad", "side")) and not of_grasp_type("none", "any")
    assert set(GRASP_TYPES) == {"power", "precision", "any"}
    with pytest.raises(ValueError, match="grasp_type"):
        of_grasp_type("palm", "wrap")
    rule = OppositionRule.from_config(defaults())
    assert (rule.angle_deg, rule.reach_mm) == (45.0, 1.0)
    with pytest.raises(ValueError, match="angle_deg"):
        OppositionRule(90.0, 1.0)


def test_faces_and_surface_features_of_contacts_on_a_box(axes):
    assert face_classes(np.array([X, -X, Y, -Z]), axes) == ["palm_face", "outer_face", "side_face", "end_face"]
    box = shape_from_config({"box": {"size_mm": [20, 40, 60]}})
    R, c = np.eye(3), np.array([20.0, 0.0, 50.0])
    points = np.array(
        [
            [10.0, 0.0, 50.0],  # middle of the face toward the palm
            [10.0, 20.0, 50.0],  # edge
            [10.0, 20.0, 80.0],  # corner
            [10.5, 19.5, 50.0],
        ]
    )  # within 1 mm of two faces: an edge
    assert surface_features(points, box, R, c, RULE) == ["face", "edge", "corner", "edge"]
    assert surface_features(points[3:], box, R, c, OppositionRule(45.0, 0.2)) == ["face"]


def test_a_contacts_table_is_classified_row_by_row(hand, axes):
    import pandas as pd

    rows = pd.DataFrame(
        {
            "status": ["grasp", "grasp", "no_contact", "lost"],
            "contact_link": [
                [0, link(hand, "middle_distal")],
                [link(hand, "thumb_distal"), link(hand, "index_distal")],
                [],
                [0, link(hand, "middle_distal")],
            ],
            "contact_normal": [np.r_[X, -X], np.r_[-Y, Y], np.zeros(0), np.r_[X, -X]],
        }
    )
    assert contacts_oppositions(rows, axes, RULE) == ["palm", "pad", "none", "none"]
