"""The hand model: names, limits, geometry against the SoftHand figures, FK signs, Jacobians, URDF."""

from __future__ import annotations

import copy
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml

from synergrasp.hand.kinematics import (
    FINGERS,
    FINGERTIP_LINKS,
    JOINT_NAMES,
    PALM_NORMAL,
    contact_jacobian,
    default_hand_path,
    fingertip_positions,
    forward_kinematics,
    build_hand,
    check_hand_doc,
    load_hand,
    matrix_rpy,
    point_jacobian,
    rpy_matrix,
    urdf_text,
    write_urdf,
)

DESIGN_JOINTS = (
    "thumb_abd thumb_flex1 thumb_flex2 "
    "index_abd index_mcp index_pip index_dip middle_abd middle_mcp middle_pip middle_dip "
    "ring_abd ring_mcp ring_pip ring_dip little_abd little_mcp little_pip little_dip"
).split()

KNUCKLES_MM = {  # hand_model.md table
    "thumb": (5.67, 29.62, 55.31),
    "index": (-3.3, 19.5, 93.70),
    "middle": (-3.3, 0.0, 100.70),
    "ring": (-3.3, -19.5, 93.70),
    "little": (-3.3, -39.0, 83.70),
}
LONG = ("index", "middle", "ring", "little")


@pytest.fixture(scope="module")
def hand():
    return load_hand()


def random_postures(hand, n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(hand.lower, hand.upper, size=(n, hand.n_joints))


def jidx(name):
    return JOINT_NAMES.index(name)


def test_joint_order_names_and_limits_match_design(hand):
    assert list(JOINT_NAMES) == DESIGN_JOINTS
    assert hand.joint_names == JOINT_NAMES
    for k, name in enumerate(JOINT_NAMES):
        lo, hi = np.degrees([hand.lower[k], hand.upper[k]])
        if name == "thumb_abd":
            expected = (0.0, 90.0)
        elif name.endswith("_abd"):
            expected = (-30.0, 30.0)
        else:
            expected = (0.0, 90.0)
        assert (lo, hi) == pytest.approx(expected), name


def test_links_palm_first_then_finger_segments(hand):
    assert hand.link_names[0] == "palm" and hand.link_finger[0] == "palm"
    assert hand.n_links == 1 + 3 + 4 * 4
    for name, finger in zip(hand.link_names[1:], hand.link_finger[1:]):
        assert name.startswith(finger + "_") and finger in FINGERS
    assert tuple(hand.link_names[i] for i in hand.fingertip_link) == FINGERTIP_LINKS
    # every joint moves exactly one link, the chains follow the joint order
    assert sorted(hand.link_parent_joint[1:].tolist()) == list(range(19))
    for f, finger in enumerate(FINGERS):
        assert [JOINT_NAMES[k].split("_")[0] for k in hand.finger_joints[f]] == [finger] * len(hand.finger_joints[f])


def test_knuckles_at_table_positions_for_any_posture(hand):
    for q in np.vstack([np.zeros(19), random_postures(hand, 5)]):
        frames = forward_kinematics(hand, q)
        for finger, xyz in KNUCKLES_MM.items():
            # the abduction axis passes through the knuckle origin
            np.testing.assert_allclose(frames[hand.link_index(f"{finger}_knuckle"), :3, 3], xyz, atol=1e-9)


def test_long_finger_length_abduction_axis_to_tip(hand):
    tips = fingertip_positions(hand, np.zeros(19))
    for f, finger in enumerate(FINGERS):
        if finger in LONG:
            # 9 + 13 + 9 + 13 + 9 + 13 + 23.3 mm
            assert np.linalg.norm(tips[f] - KNUCKLES_MM[finger]) == pytest.approx(89.3, abs=1e-9)


def test_open_hand_fingers_straight_along_z(hand):
    tips = fingertip_positions(hand, np.zeros(19))
    for f, finger in enumerate(FINGERS):
        if finger in LONG:
            d = (tips[f] - KNUCKLES_MM[finger]) / 89.3
            assert d[2] > 0.99 and abs(d[0]) < 1e-9  # straight, in the palm plane
    # the open thumb points to the thumb side, not in front of the palm
    assert tips[0][1] > 90.0


def test_palm_normal_is_unit_x(hand):
    np.testing.assert_allclose(PALM_NORMAL, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(hand.palm_normal, PALM_NORMAL)


def test_flexion_moves_tips_toward_palm_normal(hand):
    q0 = np.zeros(19)
    tips0 = fingertip_positions(hand, q0)
    for f, finger in enumerate(FINGERS):
        if finger not in LONG:
            continue
        for k in hand.finger_joints[f][1:]:
            q = q0.copy()
            q[k] = 0.2
            step = fingertip_positions(hand, q)[f] - tips0[f]
            assert step @ PALM_NORMAL > 0.9 * np.linalg.norm(step) > 0
    # a fully flexed long finger curls over the palm side. By hand, (x, z) from the knuckle with
    # r = 13/√2: up 9, pair (r, r), along +x 9, pair (r, −r) -> middle phalanx frame at
    # (9 + 2r, 9); down 9, pair (−r, −r), back 23.3 -> tip at (9 + r − 23.3, −r): the tip
    # comes back to the palm's thickness, below the knuckle (the palm must stop it)
    q = np.zeros(19)
    q[[jidx("middle_mcp"), jidx("middle_pip"), jidx("middle_dip")]] = math.pi / 2
    r = 13.0 / math.sqrt(2.0)
    frames = forward_kinematics(hand, q)
    knuckle = np.array(KNUCKLES_MM["middle"])
    np.testing.assert_allclose(frames[hand.link_index("middle_middle"), :3, 3] - knuckle, [9.0 + 2 * r, 0.0, 9.0], atol=1e-9)
    tip = fingertip_positions(hand, q)[FINGERS.index("middle")]
    np.testing.assert_allclose(tip - knuckle, [9.0 + r - 23.3, 0.0, -r], atol=1e-9)


def test_positive_abduction_turns_every_long_finger_toward_plus_y(hand):
    tips0 = fingertip_positions(hand, np.zeros(19))
    for f, finger in enumerate(FINGERS):
        if finger in LONG:
            q = np.zeros(19)
            q[jidx(f"{finger}_abd")] = 0.2
            dy = fingertip_positions(hand, q)[f][1] - tips0[f][1]
            assert dy == pytest.approx(89.3 * math.sin(0.2), rel=0.02)


def test_thumb_abduction_brings_thumb_in_front_of_palm(hand):
    palm_front = max(0.5 * s.size[0] + s.pose[0, 3] for s in hand.link_shapes[0])
    q = np.zeros(19)
    q[jidx("thumb_abd")] = math.pi / 2
    tip = fingertip_positions(hand, q)[0]
    assert tip[0] > palm_front + 40.0
    # flexing the opposed thumb moves its tip toward the middle of the palm (y toward 0)
    q[[jidx("thumb_flex1"), jidx("thumb_flex2")]] = math.pi / 4
    assert abs(fingertip_positions(hand, q)[0][1]) < abs(tip[1])


def test_jacobian_by_hand_for_straight_middle_finger(hand):
    q = np.zeros(19)
    m = FINGERS.index("middle")
    tip = fingertip_positions(hand, q)[m]
    jac = point_jacobian(hand, q, "middle_distal", tip)
    # each rolling joint: two axes at distances d and d + 13 from the tip, half a turn each
    for name, d in (("middle_dip", 23.3), ("middle_pip", 45.3), ("middle_mcp", 67.3)):
        np.testing.assert_allclose(jac[:, jidx(name)], [0.5 * (d + d + 13.0), 0.0, 0.0], atol=1e-9)
    # abduction: 89.3 mm lever, toward +y
    np.testing.assert_allclose(jac[:, jidx("middle_abd")], [0.0, 89.3, 0.0], atol=1e-9)
    # other fingers' joints do not move it
    others = [k for k in range(19) if not JOINT_NAMES[k].startswith("middle")]
    assert np.all(jac[:, others] == 0.0)


def test_jacobian_matches_finite_differences(hand):
    rng = np.random.default_rng(1)
    for q in random_postures(hand, 6, seed=2):
        frames = forward_kinematics(hand, q)
        for link in rng.choice(np.arange(1, hand.n_links), size=5, replace=False):
            local = rng.uniform(-10, 20, size=3)
            point = frames[link, :3, :3] @ local + frames[link, :3, 3]
            jac = point_jacobian(hand, q, int(link), point)
            fd = np.zeros_like(jac)
            h = 1e-6
            for k in range(19):
                dq = np.zeros(19)
                dq[k] = h
                fp, fm = forward_kinematics(hand, q + dq)[link], forward_kinematics(hand, q - dq)[link]
                fd[:, k] = ((fp[:3, :3] @ local + fp[:3, 3]) - (fm[:3, :3] @ local + fm[:3, 3])) / (2 * h)
            np.testing.assert_allclose(jac, fd, atol=1e-5)


def test_palm_jacobian_zero_and_contact_jacobian_stacks(hand):
    q = random_postures(hand, 1, seed=3)[0]
    assert np.all(point_jacobian(hand, q, 0, np.array([5.0, 0.0, 50.0])) == 0.0)
    links = np.array([0, 7, 3, 11])
    points = np.array([[9.0, 0.0, 40.0], [10.0, 20.0, 150.0], [40.0, 70.0, 80.0], [20.0, 0.0, 170.0]])
    stacked = contact_jacobian(hand, q, links, points)
    assert stacked.shape == (12, 19)
    for i, (link, p) in enumerate(zip(links, points)):
        np.testing.assert_array_equal(stacked[3 * i : 3 * i + 3], point_jacobian(hand, q, int(link), p))
    assert contact_jacobian(hand, q, np.zeros(0, int), np.zeros((0, 3))).shape == (0, 19)


def test_rpy_round_trip():
    rng = np.random.default_rng(4)
    for rpy in rng.uniform([-3, -1.5, -3], [3, 1.5, 3], size=(20, 3)):
        np.testing.assert_allclose(rpy_matrix(matrix_rpy(rpy_matrix(rpy))), rpy_matrix(rpy), atol=1e-12)
    # URDF convention: yaw about z applied last
    np.testing.assert_allclose(rpy_matrix([0, 0, math.pi / 2]) @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_urdf_is_deterministic_and_complete(hand, tmp_path):
    text = urdf_text(hand)
    assert text == urdf_text(load_hand())
    write_urdf(hand, tmp_path / "h.urdf")
    assert (tmp_path / "h.urdf").read_text() == text
    root = ET.fromstring(text)
    joints = root.findall("joint")
    assert len(joints) == 19 + 14  # 14 rolling joints of two half axes each
    assert all(j.get("type") == "revolute" for j in joints)
    mcp = [j for j in joints if j.get("name").startswith("index_mcp")]
    assert [j.get("name") for j in mcp] == ["index_mcp_a", "index_mcp_b"]
    assert float(mcp[0].find("limit").get("upper")) == pytest.approx(math.pi / 4)
    # metres: the index knuckle at 93.7 mm
    abd = next(j for j in joints if j.get("name") == "index_abd")
    assert [float(v) for v in abd.find("origin").get("xyz").split()] == pytest.approx([-0.0033, 0.0195, 0.0937])
    for link in root.findall("link"):
        assert link.find("inertial/origin").get("xyz") == "0 0 0"


def test_ignored_pairs_are_parent_child_or_palm_knuckle(hand):
    for a, b in hand.ignored_link_pairs:
        assert a < b
        assert hand.link_parent[b] == a


def _doc():
    with open(default_hand_path(), encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def test_loading_explicit_path_equals_default(hand):
    other = load_hand(default_hand_path())
    np.testing.assert_array_equal(other.frame_offset, hand.frame_offset)
    assert other.link_names == hand.link_names


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d.pop("fingers"), "fingers"),
        (lambda d: d["fingers"]["index"]["joints"][1].update(name="index_pip"), "fingers.index.joints[1].name"),
        (lambda d: d["fingers"]["ring"]["joints"][2].update(limits_deg=[90, 0]), "fingers.ring.joints[2].limits_deg"),
        (lambda d: d["fingers"]["thumb"]["knuckle"].update(xyz_mm=[1, 2]), "fingers.thumb.knuckle.xyz_mm"),
        (lambda d: d["palm"]["shapes"][0].update(sphere={"r": 1}), "palm.shapes[0]"),
        (
            lambda d: d["fingers"]["little"]["joints"][0]["shapes"][0]["capsule"].update(radius_mm=-1),
            "fingers.little.joints[0].shapes[0].capsule.radius_mm",
        ),
        (lambda d: d.update(palm_normal=[1, 1, 0]), "palm_normal"),
        # a misspelt optional key is an error, not a silent default (rolling joints would vanish)
        (lambda d: d["fingers"]["index"]["joints"][1].update(rolling_gap=13.0), "fingers.index.joints[1]: unknown key"),
        (lambda d: d.update(palm_normals=[1, 0, 0]), "<top level>: unknown key"),
        (lambda d: d["fingers"]["thumb"].update(tip=[1, 0, 0]), "fingers.thumb: unknown key"),
        (lambda d: d["fingers"]["thumb"]["knuckle"].update(rpy=[0, 0, 0]), "fingers.thumb.knuckle: unknown key"),
        (lambda d: d["palm"]["shapes"][0]["box"].update(centre_mm=[0, 0, 0]), "palm.shapes[0].box: unknown key"),
    ],
)
def test_load_hand_rejects_malformed_file_naming_the_file_and_field(tmp_path, mutate, field):
    doc = copy.deepcopy(_doc())
    mutate(doc)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    with pytest.raises(ValueError) as info:
        load_hand(path)
    assert str(info.value).startswith(f"hand file '{path}': ")
    assert field in str(info.value)


@pytest.mark.parametrize(
    "content, reason",
    [(None, "No such file"), ("dir", "is a folder"), (b"", "is empty"), (bytes(range(256)), "not a readable YAML file")],
)
def test_unreadable_hand_file_gives_one_message_naming_it(tmp_path, content, reason):
    path = tmp_path / "hand.yaml"
    if content == "dir":
        path.mkdir()
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(ValueError, match=f"hand file '{path}': .*{reason}"):
        load_hand(path)


def test_single_axis_rolling_variant():
    # rolling_gap_mm = 0 models a joint as one axis: one frame per joint
    doc = copy.deepcopy(_doc())
    for finger in doc["fingers"].values():
        for joint in finger["joints"]:
            joint["rolling_gap_mm"] = 0.0
    variant = build_hand(check_hand_doc(doc))
    assert len(variant.frame_names) == 1 + 19
    assert np.all(variant.frame_scale[1:] == 1.0)


def test_bad_q_shape_and_link_raise(hand):
    with pytest.raises(ValueError, match="q must have shape"):
        forward_kinematics(hand, np.zeros(18))
    with pytest.raises(ValueError, match="link must be"):
        point_jacobian(hand, np.zeros(19), "index_tip", np.zeros(3))
