"""Geometry of the hand model: rigid transforms (mm, rad; URDF roll-pitch-yaw) and the
collision shapes of a link (capsules and boxes). Pure numpy; imports nothing of the project."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["SHAPE_KINDS", "Shape", "rpy_matrix", "matrix_rpy", "pose_matrix", "axis_rotation", "z_to"]

SHAPE_KINDS = ("capsule", "box")


@dataclass(frozen=True)
class Shape:
    """One collision shape of a link.

    ``pose`` (4 × 4, mm) places the shape in its link frame. A capsule lies along the
    pose's local z axis: ``length`` mm between the centres of its two end spheres of
    ``radius`` mm. A box is centred on the pose with full edge lengths ``size`` (mm).
    """

    kind: str
    pose: NDArray[np.float64]
    radius: float = 0.0
    length: float = 0.0
    size: NDArray[np.float64] | None = None


def rpy_matrix(rpy: NDArray | tuple[float, float, float]) -> NDArray[np.float64]:
    """Rotation matrix of URDF roll-pitch-yaw angles (rad): Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_rpy(rotation: NDArray) -> NDArray[np.float64]:
    """URDF roll-pitch-yaw angles (rad) of a rotation matrix (inverse of ``rpy_matrix``)."""
    m = np.asarray(rotation, dtype=float)
    pitch = math.asin(-max(-1.0, min(1.0, m[2, 0])))
    if abs(m[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(m[2, 1], m[2, 2])
        yaw = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = math.atan2(-m[0, 1], m[1, 1])
    return np.array([roll, pitch, yaw])


def pose_matrix(xyz: NDArray | tuple[float, ...], rpy: NDArray | tuple[float, ...] = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """4 × 4 homogeneous transform from a translation (mm) and URDF rpy (rad)."""
    t = np.eye(4)
    t[:3, :3] = rpy_matrix(rpy)
    t[:3, 3] = np.asarray(xyz, dtype=float)
    return t


def axis_rotation(axis: NDArray, angle: float) -> NDArray[np.float64]:
    """Rotation matrix of ``angle`` rad about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    return np.array(
        [
            [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
            [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
            [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
        ]
    )


def z_to(direction: NDArray) -> NDArray[np.float64]:
    """A rotation taking the z axis onto the unit vector ``direction`` (shortest arc)."""
    d = direction / np.linalg.norm(direction)
    z = np.array([0.0, 0.0, 1.0])
    c = float(d @ z)
    if c > 1.0 - 1e-12:
        return np.eye(3)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    k = np.cross(z, d)
    return axis_rotation(k / np.linalg.norm(k), math.acos(c))
