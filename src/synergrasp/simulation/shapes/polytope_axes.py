"""Compiled queries of convex parts along axes: ray entries (the pictures) and the separating
axes of a part and a box that overlap (the penetration depth). The parts as
``polytope.pack_parts`` packs them; mm, own frame.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes.compiled import jit
from synergrasp.simulation.shapes.polytope import _HEADER, _d3, _part, _support, convex_distance

__all__ = ["part_box_overlap", "parts_box_gap", "ray_parts"]


@jit
def _separation(params: NDArray, part: int, corners: NDArray, start: int, x: float, y: float, z: float) -> float:
    """The gap between the part and the points ``corners`` along the axis (x, y, z) (either
    way; negative where their projections overlap, by the overlap), in units of its length;
    the part's extremes searched from vertex ``start``."""
    v_off = int(params[1 + _HEADER * part])
    hi = _support(params, part, start, x, y, z)
    lo = _support(params, part, start, -x, -y, -z)
    a_hi = params[v_off + 3 * hi] * x + params[v_off + 3 * hi + 1] * y + params[v_off + 3 * hi + 2] * z
    a_lo = params[v_off + 3 * lo] * x + params[v_off + 3 * lo + 1] * y + params[v_off + 3 * lo + 2] * z
    b_lo, b_hi = np.inf, -np.inf
    for r in range(corners.shape[0]):
        s = corners[r, 0] * x + corners[r, 1] * y + corners[r, 2] * z
        b_lo, b_hi = min(b_lo, s), max(b_hi, s)
    return max(b_lo - a_hi, a_lo - b_hi) / np.sqrt(x * x + y * y + z * z)


@jit
def part_box_overlap(params: NDArray, part: int, corners: NDArray, box_axes: NDArray) -> float:
    """Signed distance (mm) between a part and a box overlapping or touching it (``corners``
    (8, 3), ``box_axes`` (3, 3) rows, own frame): minus the penetration depth, the least
    overlap of their projections over the separating axes of two polyhedra (the part's face
    normals, the box's axes, the cross products of an edge of each): exact, ~0 if they touch.
    An edge of the part farther from the box than the least overlap found cannot give a
    smaller one (after that translation the two edges would touch): it is skipped."""
    h = 1 + _HEADER * part
    v_off, p_off, n_p, a_off = int(params[h]), int(params[h + 2]), int(params[h + 3]), int(params[h + 8])
    best = -np.inf
    for f in range(n_p):  # the box beyond a face of the part (the part's extreme is the face)
        j = p_off + 4 * f
        b_lo = np.inf
        for r in range(corners.shape[0]):
            b_lo = min(b_lo, corners[r, 0] * params[j] + corners[r, 1] * params[j + 1] + corners[r, 2] * params[j + 2])
        best = max(best, b_lo - params[j + 3])
    for k in range(3):
        best = max(best, _separation(params, part, corners, 0, box_axes[k, 0], box_axes[k, 1], box_axes[k, 2]))
    centre, half = np.zeros(3), np.zeros(3)
    for k in range(3):
        lo, hi = np.inf, -np.inf
        for r in range(corners.shape[0]):
            s = corners[r, 0] * box_axes[k, 0] + corners[r, 1] * box_axes[k, 1] + corners[r, 2] * box_axes[k, 2]
            lo, hi = min(lo, s), max(hi, s)
        centre[k], half[k] = 0.5 * (lo + hi), 0.5 * (hi - lo)
    for i in range(int(params[h + 1])):
        for e in range(int(params[a_off + i]), int(params[a_off + i + 1])):
            j = int(params[e])
            if j < i:
                continue
            ex = params[v_off + 3 * j] - params[v_off + 3 * i]
            ey = params[v_off + 3 * j + 1] - params[v_off + 3 * i + 1]
            ez = params[v_off + 3 * j + 2] - params[v_off + 3 * i + 2]
            length = np.sqrt(ex * ex + ey * ey + ez * ez)
            outside = 0.0
            for k in range(3):  # the edge's middle against the box, less half its length
                m = (
                    (params[v_off + 3 * i] + 0.5 * ex) * box_axes[k, 0]
                    + (params[v_off + 3 * i + 1] + 0.5 * ey) * box_axes[k, 1]
                    + (params[v_off + 3 * i + 2] + 0.5 * ez) * box_axes[k, 2]
                )
                outside += max(abs(m - centre[k]) - half[k], 0.0) ** 2
            if np.sqrt(outside) - 0.5 * length > -best + 1e-9:
                continue
            for k in range(3):
                x = ey * box_axes[k, 2] - ez * box_axes[k, 1]
                y = ez * box_axes[k, 0] - ex * box_axes[k, 2]
                z = ex * box_axes[k, 1] - ey * box_axes[k, 0]
                if x * x + y * y + z * z > 1e-18 * length * length:
                    best = max(best, _separation(params, part, corners, i, x, y, z))
    return min(best, 0.0)


@jit
def parts_box_gap(params: NDArray, corners: NDArray, box_axes: NDArray) -> tuple[float, NDArray, NDArray]:
    """Signed distance (mm) between the union of parts and a box (``corners`` (8, 3),
    ``box_axes`` (3, 3) rows, own frame): the least over the parts of the GJK distance
    (``convex_distance``), or of minus the penetration depth where they touch
    (``part_box_overlap``); with the closest points of the nearest part and of the box
    (the first such part; zeros if there is none)."""
    best, a, b = np.inf, np.zeros(3), np.zeros(3)
    for k in range(int(params[0])):
        d, pa, pb, touching = convex_distance(params, k, corners)
        if touching:
            d = part_box_overlap(params, k, corners, box_axes)
        if d < best:
            best, a, b = d, pa, pb
    return best, a, b


@jit
def ray_parts(origins: NDArray, direction: NDArray, params: NDArray, region: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Nearest entry of rays (origins (r, 3), one direction (3,), own frame) into the union:
    distance t (+inf: missed), the outward normal of the face entered and its region
    (``region``: a label per face over all parts, in packing order; -1: missed)."""
    r = origins.shape[0]
    t_out, normals, labels = np.full(r, np.inf), np.zeros((r, 3)), np.full(r, -1, np.int64)
    first_face = 0
    for k in range(int(params[0])):
        h = 1 + _HEADER * k
        _, _, p_off, n_p = _part(params, k)
        c, radius = params[h + 4 : h + 7], params[h + 7]
        for i in range(r):
            o = origins[i]
            s = _d3(c - o, direction)
            miss = o + s * direction - c
            if _d3(miss, miss) > radius * radius:
                continue
            enter, leave, face = -np.inf, np.inf, -1
            for f in range(n_p):
                j = p_off + 4 * f
                slope = params[j] * direction[0] + params[j + 1] * direction[1] + params[j + 2] * direction[2]
                level = params[j + 3] - (params[j] * o[0] + params[j + 1] * o[1] + params[j + 2] * o[2])
                if abs(slope) < 1e-15:
                    if level < 0.0:
                        leave = -np.inf  # outside a plane it runs parallel to
                        break
                elif slope < 0.0:
                    if level / slope > enter:
                        enter, face = level / slope, f
                else:
                    leave = min(leave, level / slope)
            if face >= 0 and enter <= leave and leave > 0.0 and 0.0 < enter < t_out[i]:
                t_out[i] = enter
                normals[i] = params[p_off + 4 * face : p_off + 4 * face + 3]
                labels[i] = region[first_face + face]
        first_face += n_p
    return t_out, normals, labels
