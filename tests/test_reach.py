"""The hand's reach and the grasp-type feasibility it gives (docs/hand_reach.md)."""

from pathlib import Path

import numpy as np
import pytest
import yaml

import synergrasp
from synergrasp.config import defaults
from synergrasp.hand.hand_file import check_hand_doc
from synergrasp.hand.kinematics import build_hand, load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.placement import hand_region
from synergrasp.simulation.reach import ReachStepParams, feasible_types, hand_reach, object_extents, shape_class
from synergrasp.simulation.shapes.box import Box

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def _params(**reach):
    params = ReachStepParams.from_config(defaults())
    from dataclasses import replace

    return replace(params, reach=replace(params.reach, posture_steps=3, **reach))


def _scaled_hand(factor: float):
    """The shipped hand with every long finger's lengths (joint offsets, rolling gaps,
    capsule ends, tip) multiplied by ``factor``: longer fingers, the same radii and palm."""
    doc = yaml.safe_load((Path(synergrasp.__file__).parent / "data" / "hand.yaml").read_text())
    for name, finger in doc["fingers"].items():
        if name == "thumb":
            continue
        finger["tip_mm"] = [factor * v for v in finger["tip_mm"]]
        for joint in finger["joints"]:
            joint["offset_mm"] = [factor * v for v in joint["offset_mm"]]
            joint["rolling_gap_mm"] = factor * joint["rolling_gap_mm"]
            for shape in joint["shapes"]:
                capsule = shape["capsule"]
                capsule["from_mm"] = [factor * v for v in capsule["from_mm"]]
                capsule["to_mm"] = [factor * v for v in capsule["to_mm"]]
    return build_hand(check_hand_doc(doc))


@pytest.fixture(scope="module")
def shipped_reach():
    hand = load_hand(None)
    params = _params()
    return hand, hand_reach(hand, load_synergies(None, joint_names=hand.joint_names), params.closure, params.reach)


def _obj(name):
    return GraspedObject.from_config(defaults(), name, with_mass=False).shape


def test_reach_along_s1_agrees_with_the_hand_region(shipped_reach):
    """The farthest link surface along S1 less the capsule radius (8 mm) is the axes' reach
    that hand_region rounds up to its x bound (55 mm for the shipped hand)."""
    hand, reach = shipped_reach
    region = hand_region(hand, load_synergies(None, joint_names=hand.joint_names))
    assert np.ceil(reach.table["reach_s1_mm"].max() - 8.0) == region[0][1] == 55.0
    # in any posture at least as far as along S1, per finger
    assert (reach.table["reach_any_mm"] >= reach.table["reach_s1_mm"] - 1e-9).all()
    assert reach.palm_face_mm == pytest.approx(9.5)


def test_shipped_hand_cannot_press_a_60_mm_box_toward_the_palm(shipped_reach):
    _, reach = shipped_reach
    assert 0 < reach.d_max_mm < 60.0
    # no finger's link surface reaches the outer face of a 60 mm box lying on the palm along S1
    assert (reach.table["reach_s1_mm"] < reach.palm_face_mm + 60.0).all()
    power, reason = feasible_types(_obj("obj3"), reach)["power"]
    assert not power and "thickness 60 mm > d_max" in reason
    assert feasible_types(_obj("obj3"), reach)["precision"][0]


def test_longer_fingers_make_power_feasible_for_obj3(shipped_reach):
    """The gate is computed from the hand: the shipped hand with long fingers twice as long
    presses a 60 mm box toward the palm, so obj3 admits a power grasp."""
    _, shipped = shipped_reach
    hand = _scaled_hand(2.0)
    params = _params()
    longer = hand_reach(hand, load_synergies(None, joint_names=hand.joint_names), params.closure, params.reach)
    assert longer.d_max_mm >= 60.0 > shipped.d_max_mm
    assert feasible_types(_obj("obj3"), longer)["power"][0]
    assert (longer.table["reach_s1_mm"].iloc[1:] > shipped.table["reach_s1_mm"].iloc[1:]).all()


def test_object_extents_and_shape_class():
    assert list(object_extents(Box((100.0, 60.0, 100.0)))) == [60.0, 100.0, 100.0]
    assert shape_class(Box((60.0, 60.0, 60.0)), 1.5) == "circular"
    assert shape_class(Box((30.0, 30.0, 30.0)), 1.5) == "circular"
    assert shape_class(Box((100.0, 60.0, 100.0)), 1.5) == "prismatic"
    assert shape_class(Box((30.0, 60.0, 60.0)), 1.5) == "prismatic"
    assert shape_class(Box((30.0, 60.0, 60.0)), 2.5) == "circular"


def test_precision_gate_reads_the_aperture(shipped_reach):
    _, reach = shipped_reach
    wide = Box((reach.aperture_mm + 1.0, 300.0, 300.0))
    ok, reason = feasible_types(wide, reach)["precision"]
    assert not ok and "> aperture" in reason


def test_the_reach_of_the_shadow_hand():
    """Every shipped hand: the Shadow hand (MJCF) gets a reach table of its five fingers, a
    d_max below the 60 mm boxes and an aperture above them."""
    hand = load_hand("shadow_hand")
    params = _params()
    reach = hand_reach(hand, load_synergies("shadow_hand", joint_names=hand.joint_names), params.closure, params.reach)
    assert list(reach.table["finger"]) == ["thumb", "index", "middle", "ring", "little"]
    assert (reach.table["reach_s1_mm"] > reach.palm_face_mm).all()
    assert 0 < reach.d_max_mm < 60.0 < reach.aperture_mm
    assert not feasible_types(_obj("obj3"), reach)["power"][0]
