"""pybullet's own view of the hand and of a static object, for tests only: the independent
model the package's kinematics (forward kinematics, Jacobians) and shapes are checked against."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pybullet as pb
from numpy.typing import NDArray

from synergrasp.hand.kinematics import Hand, write_urdf
from synergrasp.simulation.bullet import (
    MM,
    HandBody,
    _exact_surface,
    _hand_body,
    _to_hand_links,
    collision_shape,
    move_body,
    set_posture,
)


def load_hand_body(client: int, hand: Hand) -> HandBody:
    """Load ``hand`` (generated URDF) as a fixed-base body at the origin, posture q = 0."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "hand.urdf"
        write_urdf(hand, path)
        body = pb.loadURDF(
            str(path),
            basePosition=[0, 0, 0],
            baseOrientation=[0, 0, 0, 1],
            useFixedBase=True,
            flags=pb.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=client,
        )
    return _hand_body(client, body, hand)


def joint_positions(client: int, body: HandBody) -> NDArray[np.float64]:
    """Current pybullet joint positions of every elementary axis (rad), HandBody order."""
    states = pb.getJointStates(body.body, body.joint_indices.tolist(), physicsClientId=client)
    return np.array([s[0] for s in states])


def link_frames(client: int, body: HandBody) -> NDArray[np.float64]:
    """(n_links, 4, 4) hand link frames as pybullet has them, palm frame, mm (single precision)."""
    states = pb.getLinkStates(body.body, body.link_index[1:].tolist(), computeForwardKinematics=1, physicsClientId=client)
    pos = np.array([s[4] for s in states]) / MM
    x, y, z, w = np.array([s[5] for s in states]).T  # pybullet quaternions (x, y, z, w)
    out = np.zeros((body.hand.n_links, 4, 4))
    out[:, 3, 3] = 1.0
    out[0, :3, :3] = np.eye(3)
    out[1:, :3, :3] = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )
    out[1:, :3, 3] = pos
    return out


def bullet_jacobian(client: int, body: HandBody, q: NDArray, link: int, point_mm: NDArray) -> NDArray[np.float64]:
    """(3, 19) translational Jacobian of a point of hand link ``link`` from pybullet, mm/rad.

    ``point_mm`` in the palm frame. Independent check of ``hand.point_jacobian``: pybullet's
    per-axis columns are summed per joint with the half-angle weights.
    """
    hand = body.hand
    if link == 0:
        return np.zeros((3, hand.n_joints))
    set_posture(client, body, q)
    frame = link_frames(client, body)[link]
    local = frame[:3, :3].T @ (np.asarray(point_mm, dtype=float) - frame[:3, 3])
    n = pb.getNumJoints(body.body, physicsClientId=client)
    positions = [0.0] * n
    values = body.joint_scale * np.asarray(q, dtype=float)[body.joint_q]
    for j, v in zip(body.joint_indices, values):
        positions[int(j)] = float(v)
    lin, _ = pb.calculateJacobian(
        body.body, int(body.link_index[link]), (local * MM).tolist(), positions, [0.0] * n, [0.0] * n, physicsClientId=client
    )
    lin = np.array(lin)  # (3, n) m/rad, columns in pybullet joint order
    jac = np.zeros((3, hand.n_joints))
    for j, qi, s in zip(body.joint_indices, body.joint_q, body.joint_scale):
        jac[:, qi] += s * lin[:, j] / MM
    return jac


def load_object(client: int, shape: Any, center_mm: NDArray, rotation: NDArray | None = None) -> int:
    """A static body of ``shape`` (``synergrasp.simulation.shapes``) centred at ``center_mm``
    (palm frame), oriented by the 3 × 3 rotation matrix ``rotation`` (identity if None).
    Returns its body id."""
    body = pb.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=collision_shape(client, shape), physicsClientId=client)
    _exact_surface(client, body, shape)
    move_body(client, body, center_mm, rotation)
    return body


def contact_force_vectors(client: int, body_a: int | HandBody, body_b: HandBody) -> tuple[NDArray, NDArray, NDArray]:
    """Per contact point of the last step between A and the hand B: hand links of A and B
    (-1 where A is not the hand), the point on B (mm) and the total force B applies to A
    (normal plus the two friction components, N, palm frame)."""
    a = body_a.body if isinstance(body_a, HandBody) else body_a
    pts = pb.getContactPoints(a, body_b.body, physicsClientId=client)
    links_a = _to_hand_links(body_a, [p[3] for p in pts]) if isinstance(body_a, HandBody) else np.full(len(pts), -1)
    links = np.stack([links_a, _to_hand_links(body_b, [p[4] for p in pts])], axis=1) if pts else np.zeros((0, 2), np.int64)
    points = np.array([p[6] for p in pts]).reshape(-1, 3) / MM
    # pybullet's friction components act on B along its lateral directions: on A, opposite
    # (checked by the soft-synergy balance at rest, tests/test_dynamic_closure.py)
    force = np.array([p[9] * np.array(p[7]) - p[10] * np.array(p[11]) - p[12] * np.array(p[13]) for p in pts]).reshape(-1, 3)
    return links, points, force
