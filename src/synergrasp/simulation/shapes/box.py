"""The box: edge lengths along its own x, y, z axes (mm), centred on the origin.

The study's four objects. Exact surface, no collision margin (pybullet's rounded edges are
not used: contact points lie on this box). The palm is made of boxes too, so the
box–box helpers here serve both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes import Shape, ShapeError

__all__ = ["Box", "box_samples", "box_gap", "box_edges"]

#: The 8 corners of a box as sign vectors and its 12 edges as pairs of corners.
_CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
_EDGES = np.array([(a, b) for a in range(8) for b in range(a + 1, 8) if np.count_nonzero(_CORNERS[a] != _CORNERS[b]) == 1])
#: Corners, edge middles, face centres and centre, as sign vectors.
_SAMPLES = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)], dtype=float)


def box_edges(pose: NDArray, half: NDArray) -> tuple[NDArray, NDArray]:
    """End points (12, 3), (12, 3) of a box's edges (pose 4 × 4 in the palm frame, half extents)."""
    corners = (_CORNERS * half) @ pose[:3, :3].T + pose[:3, 3]
    return corners[_EDGES[:, 0]], corners[_EDGES[:, 1]]


def box_samples(pose: NDArray, half: NDArray) -> NDArray:
    """(27, 3) corners, edge middles, face centres and centre of a box, palm frame."""
    return (_SAMPLES * half) @ pose[:3, :3].T + pose[:3, 3]


def box_gap(points: NDArray, pose: NDArray, half: NDArray) -> NDArray:
    """(k,) distance (mm, 0 inside) of points (palm frame) to a box."""
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    return np.linalg.norm(np.maximum(np.abs(local) - half, 0.0), axis=1)


def _pose(rotation: NDArray, center: NDArray) -> NDArray:
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, center
    return pose


def _to_local(p0: NDArray, p1: NDArray, pose: NDArray) -> tuple[NDArray, NDArray]:
    R, c = pose[:3, :3], pose[:3, 3]
    return (p0 - c) @ R, (p1 - c) @ R


@dataclass(frozen=True)
class Box(Shape):
    """A box of edge lengths ``size_mm`` along its own x, y, z axes (mm)."""

    size_mm: tuple[float, float, float]

    kind: ClassVar[str] = "box"
    kernel_code: ClassVar[int] = 0

    def __post_init__(self) -> None:
        size = self.size_mm
        try:
            values = tuple(float(v) for v in size)
        except (TypeError, ValueError):
            values = None
        if (
            values is None
            or isinstance(size, (str, bytes))
            or len(values) != 3
            or not all(math.isfinite(v) and v > 0 for v in values)
        ):
            raise ShapeError(f"size_mm: {size!r} is not allowed; three finite positive edge lengths in mm are required")
        object.__setattr__(self, "size_mm", values)
        self._set_kernel_params(*(np.array(values) / 2.0))  # the half extents
        object.__setattr__(self, "_half", self._params)

    @property
    def half_extents_mm(self) -> NDArray:
        """(3,) half edge lengths, mm (read-only)."""
        return self._half

    @property
    def bounding_radius_mm(self) -> float:
        return float(np.linalg.norm(self._half))

    @property
    def label(self) -> str:
        return f"{' × '.join(f'{v:g}' for v in self.size_mm)} mm"

    def surface_point(self, point: NDArray, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        R, c, h = rotation, center, self._half
        local = R.T @ (np.asarray(point, dtype=float) - c)
        clamped = np.clip(local, -h, h)
        gap = local - clamped
        if np.linalg.norm(gap) > 1e-6:
            n_local = -gap / np.linalg.norm(gap)
        else:  # inside: leave through the nearest face
            k = int(np.argmin(h - np.abs(local)))
            clamped = local.copy()
            sign = 1.0 if local[k] >= 0 else -1.0
            clamped[k] = sign * h[k]
            n_local = np.zeros(3)
            n_local[k] = -sign
        n = R @ n_local
        return R @ clamped + c, n / np.linalg.norm(n)

    def gap(self, points: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
        return box_gap(points, _pose(rotation, center), self._half)

    def samples(self, rotation: NDArray, center: NDArray) -> NDArray:
        return box_samples(_pose(rotation, center), self._half)

    def normals_near(self, point: NDArray, rotation: NDArray, center: NDArray, reach_mm: float) -> list[NDArray]:
        half = self._half
        local = rotation.T @ (np.asarray(point) - center)
        return [-np.sign(local[k]) * rotation[:, k] for k in range(3) if abs(abs(local[k]) - half[k]) <= reach_mm]

    def box_gap(self, rotation: NDArray, center: NDArray, box_pose: NDArray, box_half: NDArray) -> tuple[float, NDArray]:
        # two convex boxes: the closest points lie on an edge of one of them
        from synergrasp.simulation.shapes.kernels import segment_box_distance  # compiled: numba only when asked

        own_pose, own_half = _pose(rotation, center), self._half
        b0, b1 = box_edges(own_pose, own_half)
        a0, a1 = box_edges(box_pose, box_half)
        d_ab, t_ab = segment_box_distance(*_to_local(a0, a1, own_pose), np.tile(own_half, (12, 1)))
        d_ba, t_ba = segment_box_distance(*_to_local(b0, b1, box_pose), np.tile(box_half, (12, 1)))
        d = min(float(d_ab.min()), float(d_ba.min()))
        # every edge at that distance (ties are common: parallel edges and faces), so that
        # the point does not depend on the order of the edges
        ends = np.concatenate([a0 + t_ab[:, None] * (a1 - a0), b0 + t_ba[:, None] * (b1 - b0)])
        tied = np.concatenate([d_ab, d_ba]) <= d + 1e-6
        return d, ends[tied].mean(axis=0)

    def _corners(self, rotation: NDArray, center: NDArray) -> NDArray:
        return center + (_CORNERS * self._half) @ rotation.T

    def same_region(self, rotation_a: NDArray, center_a: NDArray, rotation_b: NDArray, center_b: NDArray) -> bool:
        tol = 1e-9 * max(self.size_mm) + 1e-12
        a, b = self._corners(rotation_a, center_a), self._corners(rotation_b, center_b)
        d = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
        return bool((d.min(axis=1) <= tol).all() and (d.min(axis=0) <= tol).all())

    def collision_geometry(self) -> tuple[str, dict[str, Any]]:
        return "box", {"half_extents_mm": self._half}

    def ray_hits(self, origins: NDArray, direction: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        # slabs: the entry is the last of the three near-plane crossings
        half = self._half
        d = np.where(np.abs(direction) < 1e-12, 1e-12, direction)  # parallel to a slab: far-away crossings
        t1, t2 = (-half - origins) / d, (half - origins) / d
        t_in, t_out = np.minimum(t1, t2), np.maximum(t1, t2)
        near, far = t_in.max(axis=-1), t_out.min(axis=-1)
        axis = t_in.argmax(axis=-1)
        hit = (near <= far) & (far > 0.0)
        sign = -np.sign(np.take_along_axis(np.broadcast_to(d, t1.shape), axis[..., None], axis=-1)[..., 0])
        normal = np.eye(3)[axis] * sign[..., None]  # the entry face faces against the ray
        return np.where(hit, near, np.inf), normal, np.where(hit, 2 * axis + (sign > 0), -1)

    def extent(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        return self._corners(rotation, center), np.zeros(8)

    def own_mesh(self) -> tuple[NDArray, NDArray]:
        from synergrasp.simulation.shapes.surface import box_mesh

        return box_mesh(self._half)
