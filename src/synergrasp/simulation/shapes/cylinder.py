"""The cylinder: a radius and a height (mm), its axis along its own z, centred on the origin.

Its symmetries: every turn about its axis, and the half turns that swap its caps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes import Shape, positive_length
from synergrasp.simulation.shapes.box import box_edges

__all__ = ["Cylinder"]

_EPS = 1e-12


@dataclass(frozen=True)
class Cylinder(Shape):
    """A cylinder of radius ``radius_mm`` and height ``height_mm`` (mm) about its own z axis."""

    radius_mm: float
    height_mm: float

    kind: ClassVar[str] = "cylinder"
    kernel_code: ClassVar[int] = 2

    def __post_init__(self) -> None:
        r, h = positive_length("radius_mm", self.radius_mm), positive_length("height_mm", self.height_mm)
        object.__setattr__(self, "radius_mm", r)
        object.__setattr__(self, "height_mm", h)
        self._set_kernel_params(r, h / 2.0)

    @property
    def half_height_mm(self) -> float:
        return float(self._params[1])

    @property
    def bounding_radius_mm(self) -> float:
        return float(np.hypot(self.radius_mm, self.half_height_mm))

    @property
    def label(self) -> str:
        return f"cylinder, r {self.radius_mm:g} × h {self.height_mm:g} mm"

    def surface_point(self, point: NDArray, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        r, hh = self.radius_mm, self.half_height_mm
        local = rotation.T @ (np.asarray(point, dtype=float) - center)
        rho = float(np.hypot(local[0], local[1]))
        radial = local[:2] / rho if rho > _EPS else np.array([1.0, 0.0])
        nearest = np.array([*(local[:2] * min(1.0, r / rho) if rho > _EPS else local[:2]), np.clip(local[2], -hh, hh)])
        gap = local - nearest
        if np.linalg.norm(gap) > 1e-6:
            n_local = -gap / np.linalg.norm(gap)
        elif r - rho < hh - abs(local[2]):  # inside: leave through the nearer of wall and cap
            nearest = np.array([*(r * radial), local[2]])
            n_local = np.array([-radial[0], -radial[1], 0.0])
        else:
            sign = 1.0 if local[2] >= 0 else -1.0
            nearest = np.array([local[0], local[1], sign * hh])
            n_local = np.array([0.0, 0.0, -sign])
        n = rotation @ n_local
        return rotation @ nearest + center, n / np.linalg.norm(n)

    def gap(self, points: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
        local = (np.asarray(points, dtype=float) - center) @ rotation
        dr = np.maximum(np.hypot(local[..., 0], local[..., 1]) - self.radius_mm, 0.0)
        dz = np.maximum(np.abs(local[..., 2]) - self.half_height_mm, 0.0)
        return np.hypot(dr, dz)

    def samples(self, rotation: NDArray, center: NDArray) -> NDArray:
        # the caps' centres only: samples must not turn with the cylinder about its axis (a
        # symmetry), so that a cap on the palm gives the cap's centre and a rim or a wall on
        # it the closest point (``box_gap``), at every α
        return np.array([[0.0, 0.0, self.half_height_mm], [0.0, 0.0, -self.half_height_mm]]) @ rotation.T + center

    def normals_near(self, point: NDArray, rotation: NDArray, center: NDArray, reach_mm: float) -> list[NDArray]:
        r, hh = self.radius_mm, self.half_height_mm
        local = rotation.T @ (np.asarray(point, dtype=float) - center)
        rho = float(np.hypot(local[0], local[1]))
        out = []
        if abs(rho - r) <= reach_mm and abs(local[2]) <= hh + reach_mm and rho > _EPS:
            out.append(rotation @ np.array([-local[0] / rho, -local[1] / rho, 0.0]))
        if abs(abs(local[2]) - hh) <= reach_mm and rho <= r + reach_mm:
            out.append(-np.sign(local[2]) * rotation[:, 2])
        return out

    def _support(self, direction: NDArray) -> NDArray:
        """A point of the cylinder farthest along ``direction`` (own frame): on a rim; the
        middle of the generator or the cap's centre where the farthest set is a line or a disc."""
        rho = float(np.hypot(direction[0], direction[1]))
        xy = self.radius_mm * direction[:2] / rho if rho > _EPS else np.zeros(2)
        z = np.sign(direction[2]) * self.half_height_mm if abs(direction[2]) > _EPS else 0.0
        return np.array([xy[0], xy[1], z])

    def box_gap(self, rotation: NDArray, center: NDArray, box_pose: NDArray, box_half: NDArray) -> tuple[float, NDArray]:
        # The closest points are a box edge and the cylinder, or a box face and the
        # cylinder's farthest point toward that face (a face parallel to a generator or a cap
        # is reached by an edge where the middle point misses the face): every candidate is
        # the distance of an actual pair of points, and the closest pair is among them.
        from synergrasp.simulation.shapes.kernels import segment_box_distance  # compiled: numba only when asked

        a0, a1 = box_edges(box_pose, box_half)
        d_edge, t_edge = self.segment_distance((a0 - center) @ rotation, (a1 - center) @ rotation)
        on_edges = a0 + t_edge[:, None] * (a1 - a0)
        R_b, c_b = box_pose[:3, :3], box_pose[:3, 3]
        faces = np.vstack([R_b.T, -R_b.T])  # the box's outward face normals (palm frame)
        support = np.array([self._support(rotation.T @ -n) for n in faces]) @ rotation.T + center
        local = (support - c_b) @ R_b
        outside = np.linalg.norm(np.maximum(np.abs(local) - box_half, 0.0), axis=1)
        depth = np.min(box_half - np.abs(local), axis=1)
        d_face = np.where(outside > 0.0, outside, -depth)
        d_all = np.concatenate([d_edge, d_face])
        d = float(d_all.min())
        ends = (center + np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]]) * self.half_height_mm @ rotation.T - c_b) @ R_b
        axis_gap, _ = segment_box_distance(ends[:1], ends[1:], box_half[None])
        if axis_gap[0] < 0.0:  # the axis crosses the box: they overlap at least that deep
            d = min(d, float(axis_gap[0]) - self.radius_mm)
        tied = d_all <= d + 1e-6
        points = np.concatenate([on_edges, support])[tied]
        return d, points.mean(axis=0) if len(points) else center.copy()

    def same_region(self, rotation_a: NDArray, center_a: NDArray, rotation_b: NDArray, center_b: NDArray) -> bool:
        tol = 1e-9 * max(self.radius_mm, self.height_mm) + 1e-12
        # the axes' angle θ moves the rim and the end faces by about sin θ times the bounding
        # radius (1 − cos θ would accept θ up to √(2 tol / R))
        sine = float(np.linalg.norm(np.cross(rotation_a[:, 2], rotation_b[:, 2])))
        return float(np.linalg.norm(np.asarray(center_a) - np.asarray(center_b))) <= tol and sine * self.bounding_radius_mm <= tol

    def collision_geometry(self) -> tuple[str, dict[str, Any]]:
        return "cylinder", {"radius_mm": self.radius_mm, "height_mm": self.height_mm}

    def ray_hits(self, origins: NDArray, direction: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        r, hh = self.radius_mm, self.half_height_mm
        o = np.asarray(origins, dtype=float)
        d = np.broadcast_to(np.asarray(direction, dtype=float), o.shape)
        a = d[..., 0] ** 2 + d[..., 1] ** 2
        half_b = o[..., 0] * d[..., 0] + o[..., 1] * d[..., 1]
        c = o[..., 0] ** 2 + o[..., 1] ** 2 - r * r
        disc = half_b * half_b - a * c
        safe_a = np.where(a > _EPS, a, 1.0)
        t_side = (-half_b - np.sqrt(np.maximum(disc, 0.0))) / safe_a
        z_side = o[..., 2] + t_side * d[..., 2]
        side = (a > _EPS) & (disc >= 0.0) & (t_side > 0.0) & (np.abs(z_side) <= hh)
        dz = np.where(np.abs(d[..., 2]) > _EPS, d[..., 2], _EPS)
        t_cap = (-np.sign(dz) * hh - o[..., 2]) / dz  # the cap facing the ray
        x_cap, y_cap = o[..., 0] + t_cap * d[..., 0], o[..., 1] + t_cap * d[..., 1]
        cap = (np.abs(d[..., 2]) > _EPS) & (t_cap > 0.0) & (x_cap**2 + y_cap**2 <= r * r)
        t = np.where(side, t_side, np.inf)
        t = np.where(cap & (t_cap < t), t_cap, t)
        use_cap = cap & (t == t_cap)
        hit = side | cap
        at = o + np.where(hit, t, 0.0)[..., None] * d
        normal = np.where(
            use_cap[..., None],
            np.stack([np.zeros_like(a), np.zeros_like(a), -np.sign(dz)], axis=-1),
            np.stack([at[..., 0] / r, at[..., 1] / r, np.zeros_like(a)], axis=-1),
        )
        face = np.where(use_cap, np.where(dz < 0, 1, 2), 0)
        return t, normal, np.where(hit, face, -1)

    def extent(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        r, hh = self.radius_mm, self.half_height_mm
        corners = np.array([[x, y, z] for x in (-r, r) for y in (-r, r) for z in (-hh, hh)])
        return corners @ rotation.T + center, np.zeros(8)

    def own_mesh(self) -> tuple[NDArray, NDArray]:
        from synergrasp.simulation.shapes.surface import merge_meshes, revolution_mesh

        r, hh = self.radius_mm, self.half_height_mm
        # caps and side apart, so that the rims stay sharp
        return merge_meshes(
            [revolution_mesh([(0.0, -hh), (r, -hh)]), revolution_mesh([(r, -hh), (r, hh)]), revolution_mesh([(r, hh), (0.0, hh)])]
        )
