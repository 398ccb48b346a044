"""The hand in pybullet: loading, postures, FK and Jacobians against numpy, boxes, closest points."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb
import pytest

import bullet_reference

from synergrasp.simulation import bullet
from synergrasp.simulation.shapes import Box
from synergrasp.hand.kinematics import JOINT_NAMES, fingertip_positions, forward_kinematics, load_hand, point_jacobian


@pytest.fixture(scope="module")
def hand():
    return load_hand()


@pytest.fixture(scope="module")
def sim(hand):
    client = bullet.connect()
    body = bullet_reference.load_hand_body(client, hand)
    yield client, body
    bullet.disconnect(client)


def random_postures(hand, n, seed):
    return np.random.default_rng(seed).uniform(hand.lower, hand.upper, size=(n, hand.n_joints))


def test_urdf_loads_with_expected_movable_joints(sim, hand):
    client, body = sim
    n = pb.getNumJoints(body.body, physicsClientId=client)
    movable = [j for j in range(n) if pb.getJointInfo(body.body, j, physicsClientId=client)[2] == pb.JOINT_REVOLUTE]
    assert len(movable) == n == 33  # 5 abductions + 14 rolling joints × 2 half axes
    assert sorted(body.joint_indices.tolist()) == movable
    assert body.link_index[0] == -1 and len(set(body.link_index.tolist())) == hand.n_links
    for i, b in enumerate(body.link_index[1:], start=1):
        assert pb.getJointInfo(body.body, int(b), physicsClientId=client)[12].decode() == hand.link_names[i]


def test_set_posture_turns_half_axes_by_half(sim, hand):
    client, body = sim
    q = random_postures(hand, 1, seed=0)[0]
    bullet.set_posture(client, body, q)
    positions = bullet_reference.joint_positions(client, body)
    for j, (k, s) in enumerate(zip(body.joint_q, body.joint_scale)):
        assert positions[j] == pytest.approx(s * q[k], abs=1e-12)
    halves = body.joint_scale == 0.5
    assert halves.sum() == 28 and np.all(body.joint_scale[~halves] == 1.0)
    # each rolling joint has exactly two half axes
    assert sorted(np.bincount(body.joint_q[halves]).tolist()) == [0] * 5 + [2] * 14
    assert all(JOINT_NAMES[k].endswith("_abd") for k in body.joint_q[~halves])


def test_numpy_fk_equals_pybullet_link_frames(sim, hand):
    client, body = sim
    for q in np.vstack([np.zeros(19), random_postures(hand, 8, seed=1)]):
        bullet.set_posture(client, body, q)
        ours = forward_kinematics(hand, q)
        theirs = bullet_reference.link_frames(client, body)
        np.testing.assert_allclose(theirs[:, :3, 3], ours[:, :3, 3], atol=1e-3)  # mm, float32
        np.testing.assert_allclose(theirs[:, :3, :3], ours[:, :3, :3], atol=1e-5)


def test_numpy_jacobian_equals_pybullet_calculate_jacobian(sim, hand):
    client, body = sim
    rng = np.random.default_rng(2)
    for q in random_postures(hand, 6, seed=3):
        frames = forward_kinematics(hand, q)
        for link in rng.choice(np.arange(1, hand.n_links), size=4, replace=False):
            point = frames[link, :3, :3] @ rng.uniform(-8, 20, size=3) + frames[link, :3, 3]
            np.testing.assert_allclose(
                bullet_reference.bullet_jacobian(client, body, q, int(link), point),
                point_jacobian(hand, q, int(link), point),
                atol=1e-3,
            )


def test_pybullet_jacobian_against_its_own_finite_differences(sim, hand):
    # single-precision link states: steps of 1e-4 rad, tolerance ~ float32 noise / step
    client, body = sim
    q = random_postures(hand, 1, seed=4)[0]
    link = hand.link_index("ring_distal")
    bullet.set_posture(client, body, q)
    frame = bullet_reference.link_frames(client, body)[link]
    local = np.array([15.0, 3.0, -2.0])
    jac = bullet_reference.bullet_jacobian(client, body, q, link, frame[:3, :3] @ local + frame[:3, 3])
    h = 1e-4
    for k in range(19):
        dq = np.zeros(19)
        dq[k] = h
        pts = []
        for sign in (1, -1):
            bullet.set_posture(client, body, q + sign * dq)
            f = bullet_reference.link_frames(client, body)[link]
            pts.append(f[:3, :3] @ local + f[:3, 3])
        np.testing.assert_allclose((pts[0] - pts[1]) / (2 * h), jac[:, k], atol=0.05)


def test_box_closest_point_and_normal_sign(sim, hand):
    client, body = sim
    bullet.set_posture(client, body, np.zeros(19))
    # a 10 mm cube in front of the middle distal phalanx; the capsule's front at x = -3.3 + 8
    tip_link = hand.link_index("middle_distal")
    z = forward_kinematics(hand, np.zeros(19))[tip_link, 2, 3] + 8.0
    box = bullet_reference.load_object(client, Box((10.0, 10.0, 10.0)), [20.0, 0.0, z])
    try:
        cp = bullet.closest_points(client, box, body, 20.0, link_b=tip_link)
        assert len(cp) == 1 and cp.link_b[0] == tip_link
        assert cp.distance[0] == pytest.approx(15.0 - 4.7, abs=0.01)
        np.testing.assert_allclose(cp.point_a[0][0], 15.0, atol=0.01)  # on the object's face
        np.testing.assert_allclose(cp.normal_on_b[0], [1.0, 0.0, 0.0], atol=1e-6)  # object's inward normal
        # all links: the middle finger's links are the nearest ones
        allcp = bullet.closest_points(client, box, body, 12.0)
        assert set(allcp.link_b.tolist()) <= {hand.link_index(n) for n in ("middle_middle", "middle_distal")}
        # a rotated, overlapping box gives a negative distance
        rot = np.array([[math.cos(0.3), -math.sin(0.3), 0], [math.sin(0.3), math.cos(0.3), 0], [0, 0, 1]])
        bullet.move_body(client, box, [5.0, 0.0, z], rot)
        assert bullet.closest_points(client, box, body, 1.0, link_b=tip_link).distance.min() < -1.0
    finally:
        bullet.remove_body(client, box)


def test_no_self_contact_at_open_hand_but_crossed_fingers_collide(sim, hand):
    client, body = sim
    bullet.set_posture(client, body, np.zeros(19))
    assert len(bullet.self_closest_points(client, body, 1.0)) == 0
    q = np.zeros(19)
    q[JOINT_NAMES.index("index_abd")] = -math.radians(30)  # index toward the middle finger
    q[JOINT_NAMES.index("middle_abd")] = math.radians(30)  # middle toward the index
    bullet.set_posture(client, body, q)
    cp = bullet.self_closest_points(client, body, 0.0)
    names = {(hand.link_names[a], hand.link_names[b]) for a, b in zip(cp.link_a, cp.link_b)}
    assert any(a.startswith("index") and b.startswith("middle") for a, b in names)
    assert cp.distance.min() < 0


def test_fully_flexed_finger_reaches_palm(sim, hand):
    client, body = sim
    q = np.zeros(19)
    q[[JOINT_NAMES.index(n) for n in ("middle_mcp", "middle_pip", "middle_dip")]] = math.pi / 2
    bullet.set_posture(client, body, q)
    cp = bullet.self_closest_points(client, body, 0.0, pairs=bullet.self_collision_pairs(hand, (0,)))
    assert hand.link_index("middle_distal") in cp.link_b.tolist()
    # the distal tip is inside the palm box here, as the numpy FK says
    assert fingertip_positions(hand, q)[2][2] < 100.7


def test_bad_inputs_raise(sim):
    client, body = sim
    with pytest.raises(ValueError, match="q must have shape"):
        bullet.set_posture(client, body, np.zeros(5))
    with pytest.raises(ValueError, match="link must be"):
        bullet.closest_points(client, body, body, 1.0, link_a=99)
