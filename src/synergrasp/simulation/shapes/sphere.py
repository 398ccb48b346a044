"""The sphere: a radius (mm), centred on the origin. Every rotation is one of its symmetries."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes import Shape, positive_length

__all__ = ["Sphere"]


@dataclass(frozen=True)
class Sphere(Shape):
    """A sphere of radius ``radius_mm`` (mm)."""

    radius_mm: float

    kind: ClassVar[str] = "sphere"
    kernel_code: ClassVar[int] = 1

    def __post_init__(self) -> None:
        r = positive_length("radius_mm", self.radius_mm)
        object.__setattr__(self, "radius_mm", r)
        self._set_kernel_params(r)

    @property
    def bounding_radius_mm(self) -> float:
        return self.radius_mm

    @property
    def label(self) -> str:
        return f"sphere, radius {self.radius_mm:g} mm"

    def surface_point(self, point: NDArray, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        offset = np.asarray(point, dtype=float) - center
        length = float(np.linalg.norm(offset))
        out = offset / length if length > 1e-12 else rotation[:, 0]  # at the centre: any direction
        return center + self.radius_mm * out, -out

    def gap(self, points: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
        return np.maximum(np.linalg.norm(np.asarray(points, dtype=float) - center, axis=-1) - self.radius_mm, 0.0)

    def samples(self, rotation: NDArray, center: NDArray) -> NDArray:
        # a sphere touches a face at one point: the patch is the closest point (HandScene's fallback)
        return np.zeros((0, 3))

    def normals_near(self, point: NDArray, rotation: NDArray, center: NDArray, reach_mm: float) -> list[NDArray]:
        return [self.surface_point(point, rotation, center)[1]]

    def box_gap(self, rotation: NDArray, center: NDArray, box_pose: NDArray, box_half: NDArray) -> tuple[float, NDArray]:
        R, t = box_pose[:3, :3], box_pose[:3, 3]
        local = R.T @ (np.asarray(center, dtype=float) - t)
        clamped = np.clip(local, -box_half, box_half)
        outside = float(np.linalg.norm(local - clamped))
        if outside > 0.0:
            return outside - self.radius_mm, R @ clamped + t
        return -float(np.min(box_half - np.abs(local))) - self.radius_mm, np.asarray(center, dtype=float).copy()

    def same_region(self, rotation_a: NDArray, center_a: NDArray, rotation_b: NDArray, center_b: NDArray) -> bool:
        return float(np.linalg.norm(np.asarray(center_a) - np.asarray(center_b))) <= 1e-9 * self.radius_mm + 1e-12

    def collision_geometry(self) -> tuple[str, dict[str, Any]]:
        return "sphere", {"radius_mm": self.radius_mm}

    def ray_hits(self, origins: NDArray, direction: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        d = np.broadcast_to(np.asarray(direction, dtype=float), np.shape(origins))
        a = np.einsum("...k,...k->...", d, d)
        half_b = np.einsum("...k,...k->...", origins, d)
        c = np.einsum("...k,...k->...", origins, origins) - self.radius_mm**2
        disc = half_b * half_b - a * c
        t = (-half_b - np.sqrt(np.maximum(disc, 0.0))) / a
        hit = (disc >= 0.0) & (t > 0.0)
        t = np.where(hit, t, np.inf)
        normal = (origins + np.where(hit, t, 0.0)[..., None] * d) / self.radius_mm
        return t, normal, np.where(hit, 0, -1)

    def extent(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        return np.asarray(center, dtype=float).reshape(1, 3), np.array([self.radius_mm])

    def own_mesh(self) -> tuple[NDArray, NDArray]:
        from synergrasp.simulation.shapes.surface import revolution_mesh

        polar = np.linspace(0.0, np.pi, 17)
        return revolution_mesh(
            [(0.0 if k in (0, 16) else self.radius_mm * np.sin(a), -self.radius_mm * np.cos(a)) for k, a in enumerate(polar)]
        )
