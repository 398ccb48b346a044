"""Triangle meshes of the shapes' surfaces, for drawing them in 3-D (``Shape.surface_mesh``).

A mesh is ``(vertices (k, 3), triangles (t, 3))``: vertex coordinates (mm) and each
triangle's vertex indices, counter-clockwise seen from outside (its normal points out).
Vertices are shared within a smooth surface and not across a sharp edge, so a renderer that
averages normals at the vertices shades curved parts smoothly and keeps edges sharp. Pure
numpy.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["Surface", "revolution_mesh", "box_mesh", "hull_mesh", "merge_meshes", "placed", "frame_along"]

Surface = tuple[NDArray, NDArray]

#: Segments around a surface of revolution (sphere, cylinder, capsule).
SEGMENTS = 32


def revolution_mesh(profile: Sequence[tuple[float, float]], segments: int = SEGMENTS) -> Surface:
    """The surface swept by the profile ``[(r, z), ...]`` (mm, z increasing along it) turned
    about the z axis. A point with r = 0 is one vertex (a pole), the others rings of
    ``segments`` vertices."""
    angles = 2.0 * np.pi * np.arange(segments) / segments
    ring = np.c_[np.cos(angles), np.sin(angles)]
    vertices, starts = [], []  # starts[i]: index of ring i's first vertex (poles: one vertex)
    for r, z in profile:
        starts.append(sum(len(v) for v in vertices))
        vertices.append(np.array([[0.0, 0.0, z]]) if r == 0 else np.c_[r * ring, np.full(segments, z)])
    j = np.arange(segments)
    k = (j + 1) % segments
    triangles = []
    for i in range(len(profile) - 1):
        lo, hi = starts[i], starts[i + 1]
        lo_pole, hi_pole = profile[i][0] == 0, profile[i + 1][0] == 0
        if lo_pole and hi_pole:
            continue
        if lo_pole:
            triangles.append(np.c_[np.full(segments, lo), hi + k, hi + j])
        elif hi_pole:
            triangles.append(np.c_[lo + j, lo + k, np.full(segments, hi)])
        else:
            triangles += [np.c_[lo + j, lo + k, hi + k], np.c_[lo + j, hi + k, hi + j]]
    return np.vstack(vertices), np.vstack(triangles).astype(np.int64)


def box_mesh(half_extents: Sequence[float]) -> Surface:
    """A box of half extents (mm) centred on the origin: 4 vertices per face (sharp edges)."""
    half = np.asarray(half_extents, dtype=float)
    vertices, triangles = [], []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for sign in (-1.0, 1.0):
            corners = np.zeros((4, 3))
            corners[:, axis] = sign * half[axis]
            corners[:, u] = np.array([-1.0, 1.0, 1.0, -1.0]) * half[u]
            corners[:, v] = np.array([-1.0, -1.0, 1.0, 1.0]) * half[v]
            # u × v = +axis: counter-clockwise from outside on the + face, reversed on the - face
            order = [0, 1, 2, 3] if sign > 0 else [0, 3, 2, 1]
            base = 4 * len(vertices)
            vertices.append(corners[order])
            triangles += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return np.vstack(vertices), np.asarray(triangles, dtype=np.int64)


def hull_mesh(points: NDArray) -> Surface:
    """The convex hull of ``points`` (k, 3) mm: 3 vertices per triangle (flat faces, sharp edges)."""
    from scipy.spatial import ConvexHull

    pts = np.asarray(points, dtype=float)
    hull = ConvexHull(pts)
    triangles = hull.simplices.copy()
    a, b, c = (pts[triangles[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) < 0
    triangles[inward] = triangles[inward][:, [0, 2, 1]]
    return pts[triangles.ravel()], np.arange(3 * len(triangles), dtype=np.int64).reshape(-1, 3)


def merge_meshes(meshes: Sequence[Surface]) -> Surface:
    """One mesh of several (their vertices renumbered)."""
    if not meshes:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    offsets = np.cumsum([0] + [len(v) for v, _ in meshes[:-1]])
    return (np.vstack([v for v, _ in meshes]), np.vstack([t + o for (_, t), o in zip(meshes, offsets)]).astype(np.int64))


def placed(mesh: Surface, rotation: NDArray, center: NDArray) -> Surface:
    """The mesh turned by ``rotation`` (3 × 3, own frame → palm frame) and moved to ``center`` (mm)."""
    vertices, triangles = mesh
    return vertices @ np.asarray(rotation, dtype=float).T + np.asarray(center, dtype=float), triangles


def frame_along(axis: NDArray) -> NDArray:
    """A rotation (3 × 3) whose third column is the unit vector along ``axis``."""
    w = np.asarray(axis, dtype=float)
    w = w / np.linalg.norm(w)
    helper = np.eye(3)[int(np.argmin(np.abs(w)))]
    u = np.cross(helper, w)
    u = u / np.linalg.norm(u)
    return np.c_[u, np.cross(w, u), w]
