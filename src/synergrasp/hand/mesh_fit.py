"""Capsules and boxes that contain a collision mesh (docs/hand.md, "Meshes fitted with capsules and boxes").

The study collides the hand as one capsule per finger link and a palm of boxes
(``synergrasp.hand.checks``). A hand read from MJCF whose collision geoms are meshes (the
Inspire hand) gets, for each mesh, the shape that contains its convex hull, the body MuJoCo
itself collides for a mesh geom: its hull vertices (``mesh_graph``, in the geom's frame, mm)
are fitted

- by a **capsule** along the hull's principal axis (the eigenvector of the largest
  eigenvalue of the vertices' covariance): its radius the smallest circle that holds the
  vertices projected on the plane across the axis (:func:`enclosing_circle`), its two end
  spheres placed as close together as that radius allows (every vertex within the radius of
  the segment). The capsule is convex and holds every hull vertex, so it holds the hull;
- by a **box**: the smaller (by volume) of the vertices' bounding boxes in the principal axes
  and in the axes of a given frame (the palm frame for the palm).

Pure numpy on arrays MuJoCo compiled; :func:`hull_vertices` reads them from an ``MjModel``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["hull_vertices", "enclosing_circle", "fit_capsule", "fit_box", "MeshFitError"]

#: MuJoCo works in metres; the fits in mm.
_MM_PER_M = 1000.0
#: Relative slack when a point counts as inside a circle (floating-point round-off only).
_INSIDE = 1e-12


class MeshFitError(ValueError):
    """A mesh no capsule or box can be fitted to (no convex hull, a flat or degenerate one)."""


def hull_vertices(model: Any, geom: int) -> NDArray[np.float64]:
    """(n, 3) vertices of the convex hull MuJoCo computed for the mesh of ``geom``, in the
    geom's frame, mm. MeshFitError when MuJoCo kept no hull for it."""
    mesh = int(model.geom_dataid[geom])
    address = int(model.mesh_graphadr[mesh]) if mesh >= 0 else -1
    if address < 0:
        raise MeshFitError("MuJoCo computed no convex hull for its mesh")
    # mesh_graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert], ...
    n = int(model.mesh_graph[address])
    ids = np.asarray(model.mesh_graph[address + 2 + n : address + 2 + 2 * n], dtype=np.int64)
    start = int(model.mesh_vertadr[mesh])
    points = np.asarray(model.mesh_vert[start : start + int(model.mesh_vertnum[mesh])], dtype=float)[ids]
    return points * _MM_PER_M


def _circle_of_two(a: NDArray, b: NDArray) -> tuple[NDArray, float]:
    centre = 0.5 * (a + b)
    return centre, float(np.linalg.norm(a - centre))


def _circle_of_three(a: NDArray, b: NDArray, c: NDArray) -> tuple[NDArray, float]:
    """The circle through three points; for (nearly) collinear ones the largest of the three
    two-point circles, which then holds all three."""
    d = 2.0 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
    scale = max(float(np.ptp(np.array([a, b, c]))), 1.0)
    if abs(d) < 1e-12 * scale * scale:
        return max((_circle_of_two(a, b), _circle_of_two(a, c), _circle_of_two(b, c)), key=lambda t: t[1])
    sa, sb, sc = a @ a, b @ b, c @ c
    centre = (
        np.array(
            [
                sa * (b[1] - c[1]) + sb * (c[1] - a[1]) + sc * (a[1] - b[1]),
                sa * (c[0] - b[0]) + sb * (a[0] - c[0]) + sc * (b[0] - a[0]),
            ]
        )
        / d
    )
    return centre, float(np.linalg.norm(a - centre))


def enclosing_circle(points: NDArray) -> tuple[NDArray[np.float64], float]:
    """(centre, radius) of the smallest circle holding the (n, 2) ``points`` (mm): the
    incremental algorithm (each point outside the current circle lies on the next one's
    boundary), over the points in a fixed shuffled order (deterministic)."""
    p = np.asarray(points, dtype=float)
    p = p[np.random.default_rng(0).permutation(len(p))]

    def outside(x: NDArray, centre: NDArray, radius: float) -> bool:
        return float(np.linalg.norm(x - centre)) > radius * (1.0 + _INSIDE) + _INSIDE

    centre, radius = p[0].copy(), 0.0
    for i in range(1, len(p)):
        if not outside(p[i], centre, radius):
            continue
        centre, radius = p[i].copy(), 0.0
        for j in range(i):
            if not outside(p[j], centre, radius):
                continue
            centre, radius = _circle_of_two(p[i], p[j])
            for k in range(j):
                if outside(p[k], centre, radius):
                    centre, radius = _circle_of_three(p[i], p[j], p[k])
    return centre, radius


def _principal_axes(points: NDArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(mean, 3 × 3 rotation whose columns are the principal axes, the last the longest)."""
    mean = points.mean(axis=0)
    _, vectors = np.linalg.eigh(np.cov((points - mean).T))
    if np.linalg.det(vectors) < 0:
        vectors[:, 0] = -vectors[:, 0]
    return mean, vectors


def _check_points(points: NDArray) -> NDArray[np.float64]:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 4 or np.linalg.matrix_rank(p - p.mean(axis=0), tol=1e-6) < 3:
        raise MeshFitError(f"its convex hull is flat or degenerate ({len(p)} vertices); no capsule or box fits it")
    return p


def fit_capsule(points: NDArray) -> tuple[NDArray[np.float64], float, float]:
    """(pose 4 × 4, radius mm, length mm) of the capsule along the principal axis of the
    (n, 3) ``points`` (mm) that holds every point: the pose's z is the axis, its origin the
    middle of the segment between the end spheres' centres, ``length`` that segment."""
    p = _check_points(points)
    mean, axes = _principal_axes(p)
    local = (p - mean) @ axes  # columns: across, across, along
    centre, radius = enclosing_circle(local[:, :2])
    across = np.linalg.norm(local[:, :2] - centre, axis=1)
    reach = np.sqrt(np.maximum(radius * radius - across * across, 0.0))
    # every point within the radius of the segment [lo, hi] along the axis: lo ≤ t + reach, hi ≥ t − reach
    lo, hi = float(np.min(local[:, 2] + reach)), float(np.max(local[:, 2] - reach))
    if hi < lo:  # the radius alone reaches every point from one sphere centre
        lo = hi = 0.5 * (lo + hi)
        radius = float(np.max(np.linalg.norm(local - np.array([*centre, lo]), axis=1)))
    pose = np.eye(4)
    pose[:3, :3] = axes
    pose[:3, 3] = mean + axes @ np.array([centre[0], centre[1], 0.5 * (lo + hi)])
    return pose, float(radius), hi - lo


def fit_box(points: NDArray, frame_rotation: NDArray | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(pose 4 × 4, full edge lengths mm) of the box holding the (n, 3) ``points`` (mm): the
    smaller by volume of their bounding boxes in the principal axes and in the axes of
    ``frame_rotation`` (3 × 3, columns; None: the points' own frame)."""
    p = _check_points(points)
    _, principal = _principal_axes(p)
    best: tuple[float, NDArray, NDArray] | None = None
    for rotation in (principal, np.eye(3) if frame_rotation is None else np.asarray(frame_rotation, dtype=float)):
        local = p @ rotation
        low, high = local.min(axis=0), local.max(axis=0)
        volume = float(np.prod(high - low))
        if best is None or volume < best[0] - 1e-9:
            pose = np.eye(4)
            pose[:3, :3] = rotation
            pose[:3, 3] = rotation @ (0.5 * (low + high))
            best = (volume, pose, high - low)
    assert best is not None
    return best[1], best[2]
