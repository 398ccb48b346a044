"""Compiled segment queries of the shapes (numba; mm) and the dispatch on a shape's code.

The closure asks, at every posture, for the signed distance from each capsule's axis to the
object (``segment_object`` dispatches on the shape's ``kernel_code``; the box's query also
serves the palm's boxes in ``synergrasp.simulation.capsules``, and the convex parts' is
``polytope.segment_parts``). Every answer is in the shape's own frame and follows the same
conventions: the segment is p0 + t·d, t in [0, 1]; outside, the exact distance and the t
attaining it (on a stretch of equal distance, the middle of the stretch, so that t does not
depend on how the segment is oriented along it); crossing the shape, minus the deepest
penetration found (the box: among the breaks, the pieces' middles and nine points of the
segment).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes.compiled import jit
from synergrasp.simulation.shapes.polytope import WORK, segment_parts, segment_parts_gap

__all__ = [
    "sort_knots",
    "segment_sphere",
    "segment_cylinder",
    "cylinder_sdf",
    "segment_box",
    "segment_box_distance",
    "segment_object",
    "segment_object_distance",
]

_EPS = 1e-12
_FLAT_MM = 1e-9  # distances (mm) this close count as equal (a flat stretch of the segment)
_FLAT_MM2 = 1e-9  # squared distances (mm²) this close count as equal (the box's flat stretch)
_GOLDEN = 0.6180339887498949
_GOLDEN_STEPS = 60


@jit
def sort_knots(knots: NDArray, n: int) -> None:
    """Sort the first ``n`` values of ``knots`` in place (insertion sort: n is at most 8)."""
    for k in range(1, n):
        v, j = knots[k], k - 1
        while j >= 0 and knots[j] > v:
            knots[j + 1] = knots[j]
            j -= 1
        knots[j + 1] = v


@jit
def segment_sphere(p0: NDArray, d: NDArray, radius: float) -> tuple[float, float]:
    """Signed distance from the segment p0 + t·d to the sphere of ``radius`` about the origin
    and the t attaining it: the axis point nearest the centre (exact, also when crossing)."""
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    t = 0.0
    if dd > _EPS:
        t = min(max(-(p0[0] * d[0] + p0[1] * d[1] + p0[2] * d[2]) / dd, 0.0), 1.0)
    x, y, z = p0[0] + t * d[0], p0[1] + t * d[1], p0[2] + t * d[2]
    return np.sqrt(x * x + y * y + z * z) - radius, t


@jit
def cylinder_sdf(x: float, y: float, z: float, radius: float, half_height: float) -> float:
    """Signed distance (mm) of the point (x, y, z) to the solid cylinder about the z axis
    (radius, |z| ≤ half_height): negative inside (minus the depth)."""
    dr = np.sqrt(x * x + y * y) - radius
    dz = abs(z) - half_height
    if dr > 0.0 and dz > 0.0:
        return np.sqrt(dr * dr + dz * dz)
    return max(dr, dz)


@jit
def _sdf_at(p0: NDArray, d: NDArray, t: float, radius: float, half_height: float) -> float:
    return cylinder_sdf(p0[0] + t * d[0], p0[1] + t * d[1], p0[2] + t * d[2], radius, half_height)


@jit
def _golden(p0: NDArray, d: NDArray, lo: float, hi: float, radius: float, half_height: float) -> float:
    """The t of least signed distance on [lo, hi] (a convex function of t): golden section."""
    a, b = lo, hi
    x1, x2 = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    f1, f2 = _sdf_at(p0, d, x1, radius, half_height), _sdf_at(p0, d, x2, radius, half_height)
    for _ in range(_GOLDEN_STEPS):
        if f1 <= f2:
            b, x2, f2 = x2, x1, f1
            x1 = b - _GOLDEN * (b - a)
            f1 = _sdf_at(p0, d, x1, radius, half_height)
        else:
            a, x1, f1 = x1, x2, f2
            x2 = a + _GOLDEN * (b - a)
            f2 = _sdf_at(p0, d, x2, radius, half_height)
    return 0.5 * (a + b)


@jit
def segment_cylinder(p0: NDArray, d: NDArray, radius: float, half_height: float, knots: NDArray) -> tuple[float, float]:
    """Signed distance from the segment p0 + t·d to the solid cylinder about the z axis and
    the t attaining it (``knots``: work space of 8 values).

    The signed distance of a convex body is convex along a line, and on the pieces between
    the knots (where z crosses ±half_height or 0, where the radial distance crosses the
    radius) it has one form: beside the wall, the radial distance less the radius, least at
    the vertex of a quadratic; beyond a cap inside the radius, linear; beyond a rim or inside
    the body, minimised by golden section (to ~1e-12 of the piece). Only the two pieces about
    the best knot can hold the minimum.
    """
    knots[0], knots[1] = 0.0, 1.0
    n = 2
    if abs(d[2]) > _EPS:
        for level in (half_height, -half_height, 0.0):
            tb = (level - p0[2]) / d[2]
            if 0.0 < tb < 1.0:
                knots[n] = tb
                n += 1
    a = d[0] * d[0] + d[1] * d[1]
    b = 2.0 * (p0[0] * d[0] + p0[1] * d[1])
    c = p0[0] * p0[0] + p0[1] * p0[1] - radius * radius
    if a > _EPS:
        disc = b * b - 4.0 * a * c
        if disc > 0.0:
            root = np.sqrt(disc)
            for tb in ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a)):
                if 0.0 < tb < 1.0:
                    knots[n] = tb
                    n += 1
    sort_knots(knots, n)
    best, best_k = np.inf, 0
    for k in range(n):
        f = _sdf_at(p0, d, knots[k], radius, half_height)
        if f < best:
            best, best_k = f, k
    best_t = knots[best_k]
    for piece in range(max(best_k - 1, 0), min(best_k + 1, n - 1)):
        lo, hi = knots[piece], knots[piece + 1]
        mid = 0.5 * (lo + hi)
        x, y, z = p0[0] + mid * d[0], p0[1] + mid * d[1], p0[2] + mid * d[2]
        beside = np.sqrt(x * x + y * y) > radius and abs(z) <= half_height
        beyond_cap = np.sqrt(x * x + y * y) <= radius and abs(z) > half_height
        if beyond_cap:
            continue  # linear: least at a knot
        if beside:
            tv = min(max(-b / (2.0 * a), lo), hi) if a > _EPS else mid
        else:
            tv = _golden(p0, d, lo, hi, radius, half_height)
        f = _sdf_at(p0, d, tv, radius, half_height)
        if f < best:
            best, best_t = f, tv
    if best > 0.0:  # a stretch of equal distance (bounded by knots): its middle
        t_lo, t_hi = best_t, best_t
        for k in range(n):
            if _sdf_at(p0, d, knots[k], radius, half_height) <= best + _FLAT_MM:
                t_lo, t_hi = min(t_lo, knots[k]), max(t_hi, knots[k])
        if t_hi > t_lo:
            best_t = 0.5 * (t_lo + t_hi)
            best = min(best, _sdf_at(p0, d, best_t, radius, half_height))
    return best, best_t


@jit
def _sq_excess(p0: NDArray, d: NDArray, half: NDArray, t: float) -> float:
    total = 0.0
    for i in range(3):
        e = abs(p0[i] + t * d[i]) - half[i]
        if e > 0.0:
            total += e * e
    return total


@jit
def _depth(p0: NDArray, d: NDArray, half: NDArray, t: float) -> float:
    slack = np.inf
    for i in range(3):
        slack = min(slack, half[i] - abs(p0[i] + t * d[i]))
    return slack


@jit
def segment_box(p0: NDArray, d: NDArray, half: NDArray, knots: NDArray) -> tuple[float, float]:
    """Signed distance (mm) from segment p0–p1 (box frame) to the box [-half, half] and the
    segment parameter t in [0, 1] attaining it. The squared distance along the segment is
    convex and piecewise quadratic with breaks where a coordinate crosses ±half: its
    minimum is at a break, an end, or the vertex of one piece. ``d`` = p1 − p0; ``knots`` is
    work space of 8 values."""
    knots[0], knots[1] = 0.0, 1.0
    n = 2
    for i in range(3):
        if abs(d[i]) > _EPS:
            for k in range(2):
                tb = ((half[i] if k == 0 else -half[i]) - p0[i]) / d[i]
                if 0.0 < tb < 1.0:
                    knots[n] = tb
                    n += 1
    sort_knots(knots, n)
    best_sq, best_t = np.inf, 0.0
    for k in range(n):
        sq = _sq_excess(p0, d, half, knots[k])
        if sq < best_sq:
            best_sq, best_t = sq, knots[k]
    for k in range(n - 1):
        lo, hi = knots[k], knots[k + 1]
        mid = 0.5 * (lo + hi)
        num, den = 0.0, 0.0
        for i in range(3):
            x = p0[i] + mid * d[i]
            if x > half[i] or x < -half[i]:
                a = p0[i] - (half[i] if x > 0.0 else -half[i])
                num -= a * d[i]
                den += d[i] * d[i]
        tv = min(max(num / den, lo), hi) if den > _EPS else mid
        sq = _sq_excess(p0, d, half, tv)
        if sq < best_sq:
            best_sq, best_t = sq, tv
    if best_sq > 0.0:
        # a segment parallel to a face or edge is nearest along an interval (bounded by
        # knots): take its middle, which does not depend on the box's own axes
        t_lo, t_hi = best_t, best_t
        for k in range(n):
            if _sq_excess(p0, d, half, knots[k]) <= best_sq + _FLAT_MM2:
                t_lo, t_hi = min(t_lo, knots[k]), max(t_hi, knots[k])
        return np.sqrt(best_sq), 0.5 * (t_lo + t_hi)
    deepest, at = 0.0, best_t  # crossing the box: minus the deepest penetration found
    for k in range(2 * n):
        tc = knots[k // 2] if k % 2 == 0 else 0.5 * (knots[k // 2] + knots[min(k // 2 + 1, n - 1)])
        dep = _depth(p0, d, half, tc)
        if dep > deepest:
            deepest, at = dep, tc
    for j in range(9):
        dep = _depth(p0, d, half, j / 8.0)
        if dep > deepest:
            deepest, at = dep, j / 8.0
    return -deepest, at


@jit
def segment_box_distance(p0: NDArray, p1: NDArray, half: NDArray) -> tuple[NDArray, NDArray]:
    """Signed distances (k,) from segments p0–p1 ((k, 3), each in its box's frame) to the
    boxes [-half, half] ((k, 3)), and the segment parameters (k,) attaining them."""
    k = p0.shape[0]
    dist, t = np.empty(k), np.empty(k)
    knots = np.empty(8)
    for i in range(k):
        dist[i], t[i] = segment_box(p0[i], p1[i] - p0[i], half[i], knots)
    return dist, t


@jit
def segment_object(p0: NDArray, d: NDArray, code: int, params: NDArray, work: NDArray) -> tuple[float, float]:
    """Signed distance (mm) from the segment p0 + t·d, t in [0, 1] (the object's own frame),
    to the object's shape (``code``, ``params``: ``synergrasp.simulation.shapes``) and the t
    attaining it; ``work`` is scratch space of ``WORK`` values. 0: a box, params its half extents;
    1: a sphere about the origin, (radius); 2: a cylinder about the z axis, (radius, half height);
    3: convex parts (a mesh), ``polytope.pack_parts``."""
    if code == 0:
        return segment_box(p0, d, params, work)
    if code == 1:
        return segment_sphere(p0, d, params[0])
    if code == 2:
        return segment_cylinder(p0, d, params[0], params[1], work)
    return segment_parts(p0, d, params, work)


@jit
def segment_object_gap(p0: NDArray, d: NDArray, code: int, params: NDArray, work: NDArray, cutoff: float = np.inf) -> float:
    """:func:`segment_object`'s signed distance alone, the same to the last bit where it is below
    ``cutoff`` (mm; elsewhere at least ``cutoff``): for convex parts without seeking the t that
    attains it, nor measuring a part surely beyond ``cutoff`` (``polytope.segment_parts_gap``)."""
    if code == 3:
        return segment_parts_gap(p0, d, params, work, cutoff)
    return segment_object(p0, d, code, params, work)[0]


@jit
def segment_object_distance(p0: NDArray, p1: NDArray, code: int, params: NDArray) -> tuple[NDArray, NDArray]:
    """Signed distances (k,) from segments p0–p1 ((k, 3), the object's own frame) to one
    object shape (``code``, ``params``) and the segment parameters (k,) attaining them."""
    k = p0.shape[0]
    dist, t = np.empty(k), np.empty(k)
    work = np.empty(WORK)
    for i in range(k):
        dist[i], t[i] = segment_object(p0[i], p1[i] - p0[i], code, params, work)
    return dist, t
