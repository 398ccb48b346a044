"""The shapes an object can have, behind one interface (docs/shapes.md).

Every step that needs to know what is grasped asks its :class:`Shape`: the closure's
distance queries (the nearest surface point and inward normal from a point,
:meth:`Shape.surface_point`; the signed distance from a capsule's axis, compiled, by
``kernel_code`` and ``kernel_params`` in :mod:`synergrasp.simulation.shapes.kernels`), the distance
to a box of the palm (intersection with the open hand), the bounding radius, the starting
orientation, its symmetries (the α-period of the pose grid), the collision shape of the
dynamic closure, the ray casting of the pictures and the triangles of the 3-D views. A shape is described in its own
frame, centred on the origin (mm); the methods that answer in the palm frame take the
object's pose: ``rotation`` (3 × 3, own frame → palm frame) and ``center`` (3,) mm.

The configuration names a shape by one key, ``objects.<name>.shape: {box: {size_mm: [...]}}``
(:func:`shape_from_config`); pure numpy, no pybullet here.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Shape",
    "ShapeError",
    "SHAPES",
    "shape_from_config",
    "start_rotation",
    "positive_length",
    "Box",
    "Sphere",
    "Cylinder",
    "Mesh",
]


class ShapeError(ValueError):
    """A shape description is invalid; the message names the field."""


def positive_length(field: str, value: Any, what: str = "a finite positive length in mm") -> float:
    """``value`` as a finite positive number (``what``, a length in mm unless said);
    ShapeError("<field>: ...") otherwise."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = math.nan
    if isinstance(value, (bool, str)) or not (math.isfinite(out) and out > 0):
        raise ShapeError(f"{field}: {value!r} is not allowed; {what} is required")
    return out


def start_rotation(axes: Sequence[int]) -> NDArray:
    """The shape's orientation at α = β = 0 (own frame → palm frame): its own axis ``axes[k]``
    lies along palm axis k (x = palm normal, y, z = long fingers); ``axes`` a permutation of
    (0, 1, 2). An odd permutation is made a rotation by reversing the own axis along palm z."""
    R0 = np.zeros((3, 3))
    for k, own in enumerate(axes):
        R0[k, own] = 1.0
    if np.linalg.det(R0) < 0:
        R0[:, axes[2]] *= -1.0
    return R0


class Shape(ABC):
    """One kind of object shape (subclasses are frozen dataclasses of its sizes, mm)."""

    #: the key naming it in the configuration (``objects.<name>.shape.<kind>``)
    kind: ClassVar[str]
    #: the number by which the compiled distance kernel knows it
    kernel_code: ClassVar[int]

    @property
    def kernel_params(self) -> NDArray:
        """Its sizes as the float64 array the compiled kernel reads (read-only)."""
        return self._params

    def _set_kernel_params(self, *values: float) -> None:
        """Keep ``values`` as the read-only ``kernel_params`` (from ``__post_init__``)."""
        params = np.array(values, dtype=float)
        params.setflags(write=False)
        object.__setattr__(self, "_params", params)

    @property
    @abstractmethod
    def bounding_radius_mm(self) -> float:
        """Radius of the smallest sphere about its centre that holds it, mm."""

    @property
    def across_mm(self) -> float:
        """Its size across for the configuration's checks, mm: twice ``bounding_radius_mm``; a
        mesh's from its file alone (its convex parts are made by a job, not by the checks)."""
        return 2.0 * self.bounding_radius_mm

    @property
    @abstractmethod
    def label(self) -> str:
        """Its sizes in words, for figures ("30 × 30 × 30 mm")."""

    def start_rotation(self, axes: Sequence[int]) -> NDArray:
        """Orientation at α = β = 0 (:func:`start_rotation`)."""
        return start_rotation(axes)

    @abstractmethod
    def surface_point(self, point: NDArray, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        """The surface point nearest to ``point`` (palm frame, mm) and the inward unit normal
        there. Outside: the normal points from ``point`` toward the surface; inside
        (penetration): the nearest surface point, its inward normal."""

    def segment_distance(self, p0: NDArray, p1: NDArray) -> tuple[NDArray, NDArray]:
        """Signed distances (k,) from segments p0–p1 ((k, 3), own frame, mm) to the shape and
        the segment parameters in [0, 1] attaining them (negative: the segment crosses it,
        minus a penetration depth). The closure's compiled query, here for tests."""
        from synergrasp.simulation.shapes.kernels import segment_object_distance  # compiled: numba only when asked

        return segment_object_distance(
            np.ascontiguousarray(p0, dtype=float), np.ascontiguousarray(p1, dtype=float), self.kernel_code, self.kernel_params
        )

    @abstractmethod
    def gap(self, points: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
        """(k,) distance (mm, 0 inside) of points (k, 3) (palm frame) to the shape."""

    @abstractmethod
    def samples(self, rotation: NDArray, center: NDArray) -> NDArray:
        """Points (k, 3) (palm frame) of the shape whose mean near a touching palm is the
        middle of the contact patch (``HandScene``)."""

    @abstractmethod
    def normals_near(self, point: NDArray, rotation: NDArray, center: NDArray, reach_mm: float) -> list[NDArray]:
        """Inward unit normals (palm frame) of the faces of the shape within ``reach_mm`` of
        ``point`` (for a curved surface: the one normal at the nearest point)."""

    @abstractmethod
    def box_gap(self, rotation: NDArray, center: NDArray, box_pose: NDArray, box_half: NDArray) -> tuple[float, NDArray]:
        """Signed distance (mm) from the shape to a box (4 × 4 pose in the palm frame, half
        extents mm; a part of the palm) and a point where they are closest (palm frame)."""

    @abstractmethod
    def same_region(self, rotation_a: NDArray, center_a: NDArray, rotation_b: NDArray, center_b: NDArray) -> bool:
        """Whether the shape fills the same region of space at pose a as at pose b (to
        round-off): a symmetry of the shape maps one onto the other."""

    @abstractmethod
    def collision_geometry(self) -> tuple[str, dict[str, Any]]:
        """What the physics engine collides: (``"box"``, {half_extents_mm}) etc., mm
        (``synergrasp.simulation.bullet.collision_shape``)."""

    @abstractmethod
    def ray_hits(self, origins: NDArray, direction: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Nearest entry of rays (origins (..., 3), one direction (..., 3) or (3,), own frame)
        into the shape: distance t along the ray (+inf: missed), the outward unit normal
        there (own frame) and a face index (-1: missed; one index for a curved surface)."""

    @abstractmethod
    def extent(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        """Points (k, 3) (palm frame) and radii (k,) whose spheres cover the shape (pictures)."""

    @abstractmethod
    def own_mesh(self) -> tuple[NDArray, NDArray]:
        """Triangles of its surface in its own frame (``synergrasp.simulation.shapes.surface``):
        vertices (k, 3) mm, triangles (t, 3) vertex indices, counter-clockwise from outside."""

    def surface_mesh(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        """Its surface's triangles at its pose: vertices (k, 3) palm frame, mm, and triangles
        (t, 3) (3-D views)."""
        from synergrasp.simulation.shapes.surface import placed

        return placed(self.own_mesh(), rotation, center)


def shape_from_config(spec: Mapping[str, Any], where: str = "shape") -> Shape:
    """The shape of a configuration's ``shape`` mapping (one key, the kind, holding its
    fields, e.g. ``{box: {size_mm: [30, 30, 30]}}``). A bad one raises ShapeError whose
    message starts with the key in quotes (``'<where>.box.size_mm': ...``)."""
    if not isinstance(spec, Mapping) or len(spec) != 1:
        raise ShapeError(f"'{where}': one of {sorted(SHAPES)} with its fields is required, got {spec!r}")
    ((kind, fields),) = spec.items()
    if kind not in SHAPES:
        raise ShapeError(f"'{where}': unknown shape {kind!r}; allowed: {sorted(SHAPES)}")
    if not isinstance(fields, Mapping):
        raise ShapeError(f"'{where}.{kind}': a mapping of its fields is required, got {fields!r}")
    try:
        return SHAPES[kind](**fields)
    except TypeError as err:
        raise ShapeError(f"'{where}.{kind}': {err}") from None
    except ShapeError as err:  # raised by the shape as "<field>: <problem>"
        field, _, problem = str(err).partition(": ")
        raise ShapeError(f"'{where}.{kind}.{field}': {problem}") from None


from synergrasp.simulation.shapes.box import Box  # noqa: E402
from synergrasp.simulation.shapes.cylinder import Cylinder  # noqa: E402
from synergrasp.simulation.shapes.mesh import Mesh  # noqa: E402
from synergrasp.simulation.shapes.sphere import Sphere  # noqa: E402

#: The shapes by the key that names them in the configuration.
SHAPES: dict[str, type[Shape]] = {cls.kind: cls for cls in (Box, Sphere, Cylinder, Mesh)}
