"""Compiled queries of a union of convex polytopes: GJK distances and depths inside (mm).

A mesh shape is one convex polytope (a convex mesh: its hull) or several (a non-convex one:
the parts of its convex decomposition). The kernel knows them as one float64 array,
``pack_parts``: ``[n_parts, (v_off, n_v, p_off, n_p, cx, cy, cz, radius, a_off, n_off) per
part, vertices (3 per vertex), planes (nx, ny, nz, b per face: n·x ≤ b inside, n the outward
unit normal), the vertex graph (starts, neighbours)]``, with each part's bounding sphere
(centre, radius) to skip parts that cannot be nearer.

Outside a part, distances are GJK's (Gilbert–Johnson–Keerthi) on the Minkowski difference
of the part and the query's convex set (a segment, a point, a box's corners), whose support
points carry their vertex pair, so the closest points come out as barycentric combinations
of the two sets' vertices: exact to round-off (~1e-12 relative) for polytopes. Inside (the
sets overlap), a part's signed distance is the largest of its face planes' (exact for a
point in a convex polytope), and a segment's is minimised along it by cutting planes.
Over the union, the least over the parts (outside: the exact distance to the union). Ray
entries and penetration depths: ``polytope_axes``."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes.compiled import jit

__all__ = ["WORK", "pack_parts", "segment_parts", "point_parts", "points_gap", "convex_distance"]

_HEADER = 10
#: Scratch space (float64 values) a segment query needs (``segment_parts``).
WORK = 48
_MAX_ITER = 64
_REL = 1e-15  # GJK stops when |v|² − v·w ≤ _REL·|v|² (no more progress)
_TOUCH_MM2 = 1e-20  # |v|² at or below this: the sets touch or overlap
_FLAT_MM = 1e-9  # a segment whose distance changes less than this along its length is parallel
_ON_PLANE_MM = 1e-7  # slack of the face planes when finding the stretch of equal distance


def pack_parts(parts: list[tuple[NDArray, NDArray]]) -> NDArray:
    """The kernel's array of convex parts, each (vertices (k, 3) mm, planes (f, 4): outward
    unit normal and offset b, n·x ≤ b inside). Each part's vertex graph (the edges of its
    hull) is packed too, for the support search (``_support``)."""
    header = [float(len(parts))]
    data: list[NDArray] = []
    offset = 1 + _HEADER * len(parts)
    for vertices, planes in parts:
        centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
        radius = float(np.linalg.norm(vertices - centre, axis=1).max())
        starts, neighbours = _vertex_graph(vertices)
        v_off = offset
        p_off = v_off + vertices.size
        a_off = p_off + planes.size
        header += [v_off, len(vertices), p_off, len(planes), *centre, radius, a_off, a_off + len(starts)]
        data += [vertices.ravel(), planes.ravel(), starts + (a_off + len(starts)), neighbours]
        offset = a_off + len(starts) + len(neighbours)
    return np.concatenate([np.asarray(header, dtype=float), *[np.asarray(d, dtype=float) for d in data]])


def _vertex_graph(vertices: NDArray) -> tuple[NDArray, NDArray]:
    """The neighbours of every vertex along the hull's edges, as (starts (k + 1,), neighbours):
    vertex i's are neighbours[starts[i]:starts[i + 1]] (every vertex with every other when
    there is no hull: fewer than 4 points or flat)."""
    from scipy.spatial import ConvexHull, QhullError

    k = len(vertices)
    try:
        simplices = ConvexHull(vertices).simplices
        edges = np.concatenate([simplices[:, [0, 1]], simplices[:, [1, 2]], simplices[:, [2, 0]]])
    except (QhullError, ValueError):
        edges = np.array([(i, j) for i in range(k) for j in range(k) if i != j]).reshape(-1, 2)
    edges = np.unique(np.concatenate([edges, edges[:, ::-1]]), axis=0)
    starts = np.searchsorted(edges[:, 0], np.arange(k + 1))
    return starts.astype(float), edges[:, 1].astype(float)


@jit
def _d3(a: NDArray, b: NDArray) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def _part(params: NDArray, k: int) -> tuple[int, int, int, int]:
    h = 1 + _HEADER * k
    return int(params[h]), int(params[h + 1]), int(params[h + 2]), int(params[h + 3])


@jit
def _support(params: NDArray, part: int, start: int, x: float, y: float, z: float) -> int:
    """Index of a vertex of the part farthest along (x, y, z): from ``start``, on to a better
    neighbour while there is one. On a convex polytope a vertex no neighbour of which is
    farther is a farthest one (the simplex method's argument), and a good start (the last
    support) is a few steps away."""
    h = 1 + _HEADER * part
    v_off, a_off = int(params[h]), int(params[h + 8])
    i = start
    j = v_off + 3 * i
    best = params[j] * x + params[j + 1] * y + params[j + 2] * z
    moved = True
    while moved:
        moved = False
        for e in range(int(params[a_off + i]), int(params[a_off + i + 1])):
            k = int(params[e])
            j = v_off + 3 * k
            s = params[j] * x + params[j + 1] * y + params[j + 2] * z
            if s > best:
                best, i, moved = s, k, True
    return i


@jit
def _dot(w: NDArray, i: int, j: int, k: int) -> float:
    """(w[j] − w[i]) · (−w[k])."""
    return -((w[j, 0] - w[i, 0]) * w[k, 0] + (w[j, 1] - w[i, 1]) * w[k, 1] + (w[j, 2] - w[i, 2]) * w[k, 2])


@jit
def _on_edge(w: NDArray, a: int, b: int) -> float:
    """The parameter s in [0, 1] of the point of edge w[a]–w[b] nearest the origin."""
    ex, ey, ez = w[b, 0] - w[a, 0], w[b, 1] - w[a, 1], w[b, 2] - w[a, 2]
    ee = ex * ex + ey * ey + ez * ez
    if ee <= 0.0:
        return 0.0
    return min(max(-(w[a, 0] * ex + w[a, 1] * ey + w[a, 2] * ez) / ee, 0.0), 1.0)


@jit
def _closest_on_triangle(w: NDArray, a: int, b: int, c: int, lam: NDArray) -> None:
    """Barycentric weights (lam[0..2] for a, b, c) of the point of triangle w[a] w[b] w[c]
    nearest the origin, from the Voronoi region holding the origin (a vertex, an edge or
    the face); a flat triangle: its nearest edge."""
    d1, d2 = _dot(w, a, b, a), _dot(w, a, c, a)
    lam[0], lam[1], lam[2] = 1.0, 0.0, 0.0
    if d1 <= 0.0 and d2 <= 0.0:
        return
    d3, d4 = _dot(w, a, b, b), _dot(w, a, c, b)
    if d3 >= 0.0 and d4 <= d3:
        lam[0], lam[1] = 0.0, 1.0
        return
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        s = d1 / (d1 - d3)
        lam[0], lam[1] = 1.0 - s, s
        return
    d5, d6 = _dot(w, a, b, c), _dot(w, a, c, c)
    if d6 >= 0.0 and d5 <= d6:
        lam[0], lam[2] = 0.0, 1.0
        return
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        s = d2 / (d2 - d6)
        lam[0], lam[2] = 1.0 - s, s
        return
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        s = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        lam[0], lam[1], lam[2] = 0.0, 1.0 - s, s
        return
    total = va + vb + vc
    if total <= 1e-300:  # flat: the nearest of its edges
        best = np.inf
        for e in range(3):
            i, j = (a, b) if e == 0 else (b, c) if e == 1 else (a, c)
            s = _on_edge(w, i, j)
            x = (1 - s) * w[i, 0] + s * w[j, 0]
            y = (1 - s) * w[i, 1] + s * w[j, 1]
            z = (1 - s) * w[i, 2] + s * w[j, 2]
            if x * x + y * y + z * z < best:
                best = x * x + y * y + z * z
                lam[0] = 1 - s if e != 1 else 0.0
                lam[1] = s if e == 0 else 1 - s if e == 1 else 0.0
                lam[2] = 0.0 if e == 0 else s
        return
    lam[0], lam[1], lam[2] = va / total, vb / total, vc / total


@jit
def _beyond(w: NDArray, a: int, b: int, c: int, o: int) -> bool:
    """Whether the origin lies beyond the face a b c of the tetrahedron (opposite vertex o),
    or the tetrahedron is flat (then every face counts)."""
    ux, uy, uz = w[b, 0] - w[a, 0], w[b, 1] - w[a, 1], w[b, 2] - w[a, 2]
    vx, vy, vz = w[c, 0] - w[a, 0], w[c, 1] - w[a, 1], w[c, 2] - w[a, 2]
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    to_origin = -(nx * w[a, 0] + ny * w[a, 1] + nz * w[a, 2])
    to_other = nx * (w[o, 0] - w[a, 0]) + ny * (w[o, 1] - w[a, 1]) + nz * (w[o, 2] - w[a, 2])
    size = (ux * ux + uy * uy + uz * uz) * np.sqrt(vx * vx + vy * vy + vz * vz)
    if abs(to_other) <= 1e-12 * size:
        return True
    return to_origin * to_other < 0.0


@jit
def _reduce(w: NDArray, ia: NDArray, ib: NDArray, n: int, lam: NDArray, tmp: NDArray) -> tuple[int, bool]:
    """Replace the simplex w[:n] by the smallest face holding its point nearest the origin, with
    its barycentric weights in lam; (new size, whether the origin is inside a tetrahedron)."""
    if n == 1:
        lam[0] = 1.0
        return 1, False
    if n == 2:
        s = _on_edge(w, 0, 1)
        lam[0], lam[1] = 1.0 - s, s
    elif n == 3:
        _closest_on_triangle(w, 0, 1, 2, lam)
    else:
        best, inside = np.inf, True
        for f in range(4):
            a, b, c = (0, 1, 2) if f == 0 else (0, 1, 3) if f == 1 else (0, 2, 3) if f == 2 else (1, 2, 3)
            if _beyond(w, a, b, c, 6 - a - b - c):
                inside = False
                _closest_on_triangle(w, a, b, c, tmp)
                x = tmp[0] * w[a, 0] + tmp[1] * w[b, 0] + tmp[2] * w[c, 0]
                y = tmp[0] * w[a, 1] + tmp[1] * w[b, 1] + tmp[2] * w[c, 1]
                z = tmp[0] * w[a, 2] + tmp[1] * w[b, 2] + tmp[2] * w[c, 2]
                if x * x + y * y + z * z < best:
                    best = x * x + y * y + z * z
                    lam[0], lam[1], lam[2], lam[3] = 0.0, 0.0, 0.0, 0.0
                    lam[a], lam[b], lam[c] = tmp[0], tmp[1], tmp[2]
        if inside:
            return 4, True
    k = 0
    for i in range(n):  # keep the vertices with weight
        if lam[i] > 0.0:
            w[k, 0], w[k, 1], w[k, 2] = w[i, 0], w[i, 1], w[i, 2]
            ia[k], ib[k], lam[k] = ia[i], ib[i], lam[i]
            k += 1
    return k, False


@jit
def _farthest(other: NDArray, x: float, y: float, z: float) -> int:
    """Index of a row of ``other`` farthest along (x, y, z)."""
    j, top = 0, -np.inf
    for r in range(other.shape[0]):
        s = other[r, 0] * x + other[r, 1] * y + other[r, 2] * z
        if s > top:
            j, top = r, s
    return j


@jit
def _gjk(params: NDArray, part: int, other: NDArray, work: NDArray) -> tuple[int, bool]:
    """GJK between a part's vertices and the points ``other`` (m, 3). ``work`` (WORK values):
    the final simplex is left in it (``_simplex``), its size returned; True if they touch.
    It starts from the pair facing each other across the centres."""
    w, ia, ib, lam, tmp = _simplex(work)
    h = 1 + _HEADER * part
    v_off = int(params[h])
    mx, my, mz = 0.0, 0.0, 0.0
    for r in range(other.shape[0]):
        mx, my, mz = mx + other[r, 0], my + other[r, 1], mz + other[r, 2]
    m = float(other.shape[0])
    ux, uy, uz = mx / m - params[h + 4], my / m - params[h + 5], mz / m - params[h + 6]
    i, j = _support(params, part, 0, ux, uy, uz), _farthest(other, -ux, -uy, -uz)
    for k in range(3):
        w[0, k] = params[v_off + 3 * i + k] - other[j, k]
    ia[0], ib[0], lam[0], n = i, j, 1.0, 1
    vx, vy, vz = w[0, 0], w[0, 1], w[0, 2]
    for _ in range(_MAX_ITER):
        vv = vx * vx + vy * vy + vz * vz
        if vv <= _TOUCH_MM2:
            return n, True
        i = _support(params, part, i, -vx, -vy, -vz)
        j = _farthest(other, vx, vy, vz)
        px = params[v_off + 3 * i] - other[j, 0]
        py = params[v_off + 3 * i + 1] - other[j, 1]
        pz = params[v_off + 3 * i + 2] - other[j, 2]
        if vv - (vx * px + vy * py + vz * pz) <= _REL * vv:
            return n, False
        for k in range(n):
            if ia[k] == i and ib[k] == j:
                return n, False
        w[n, 0], w[n, 1], w[n, 2], ia[n], ib[n] = px, py, pz, i, j
        n, inside = _reduce(w, ia, ib, n + 1, lam, tmp)
        if inside:
            return n, True
        vx, vy, vz = 0.0, 0.0, 0.0
        for k in range(n):
            vx += lam[k] * w[k, 0]
            vy += lam[k] * w[k, 1]
            vz += lam[k] * w[k, 2]
    return n, False


@jit
def _simplex(work: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
    """Views of ``work``: the simplex (4, 3), its vertices' indices in each set (stored as
    floats), its weights and scratch (4 each); the closest points follow (``_closest``)."""
    return work[8:20].reshape((4, 3)), work[20:24], work[24:28], work[28:32], work[32:36]


@jit
def _closest(params: NDArray, part: int, other: NDArray, work: NDArray, n: int) -> float:
    """The closest points of the part and ``other`` from GJK's simplex (into work[36:39] and
    work[39:42]) and their distance."""
    w, ia, ib, lam, _ = _simplex(work)
    v_off = int(params[1 + _HEADER * part])
    gap = 0.0
    for r in range(3):
        a, b = 0.0, 0.0
        for k in range(n):
            a += lam[k] * params[v_off + 3 * int(ia[k]) + r]
            b += lam[k] * other[int(ib[k]), r]
        work[36 + r], work[39 + r] = a, b
        gap += (a - b) * (a - b)
    return np.sqrt(gap)


@jit
def convex_distance(params: NDArray, part: int, other: NDArray) -> tuple[float, NDArray, NDArray, bool]:
    """GJK distance (mm) between a part and the convex hull of the points ``other`` (m, 3),
    the closest points of each (3,) and whether they touch or overlap (then distance 0)."""
    work = np.zeros(WORK)
    n, touching = _gjk(params, part, other, work)
    dist = _closest(params, part, other, work, n)
    return (0.0 if touching else dist), work[36:39].copy(), work[39:42].copy(), touching


@jit
def _plane_depth(params: NDArray, part: int, x: float, y: float, z: float) -> tuple[float, int]:
    """Largest signed plane distance of the point (≤ 0 inside the part) and its face."""
    _, _, p_off, n_p = _part(params, part)
    best, arg = -np.inf, 0
    for f in range(n_p):
        j = p_off + 4 * f
        s = params[j] * x + params[j + 1] * y + params[j + 2] * z - params[j + 3]
        if s > best:
            best, arg = s, f
    return best, arg


@jit
def _depth_along(params: NDArray, part: int, p0: NDArray, d: NDArray, t: float) -> tuple[float, float]:
    """The plane depth at p0 + t·d and its slope in t (the face attaining it)."""
    depth, f = _plane_depth(params, part, p0[0] + t * d[0], p0[1] + t * d[1], p0[2] + t * d[2])
    j = int(params[1 + _HEADER * part + 2]) + 4 * f
    return depth, params[j] * d[0] + params[j + 1] * d[1] + params[j + 2] * d[2]


@jit
def _deepest_on_segment(params: NDArray, part: int, p0: NDArray, d: NDArray) -> tuple[float, float]:
    """The least plane depth along p0 + t·d, t in [0, 1], and its t. The depth is the upper
    envelope of one line per face (convex, piecewise linear): cutting planes, i.e. the two
    lines active at the ends of the bracket meet at the next trial t, until the envelope is
    that low there (a breakpoint: exact in as many steps as breakpoints passed)."""
    lo, hi = 0.0, 1.0
    f_lo, g_lo = _depth_along(params, part, p0, d, lo)
    f_hi, g_hi = _depth_along(params, part, p0, d, hi)
    for _ in range(100):
        if g_lo >= 0.0:
            return f_lo, lo
        if g_hi <= 0.0:
            return f_hi, hi
        t = min(max((f_hi - f_lo + g_lo * lo - g_hi * hi) / (g_lo - g_hi), lo), hi)
        f_t, g_t = _depth_along(params, part, p0, d, t)
        if f_t <= f_lo + g_lo * (t - lo) + 1e-12 * (1.0 + abs(f_t)) or hi - lo <= 1e-15:
            return f_t, t
        if g_t > 0.0:
            hi, f_hi, g_hi = t, f_t, g_t
        else:
            lo, f_lo, g_lo = t, f_t, g_t
    return (f_lo, lo) if f_lo <= f_hi else (f_hi, hi)


@jit
def _flat_middle(params: NDArray, part: int, p0: NDArray, d: NDArray, t: float, work: NDArray, dist: float) -> float:
    """A segment parallel to the part's nearest feature is nearest along a stretch: the t in
    its middle (so that t does not depend on how the segment runs along it). On the stretch
    the nearest points are the segment's points less the gap (work[39:42] − work[36:39], the
    closest points), inside every face plane."""
    nx, ny, nz = work[39] - work[36], work[40] - work[37], work[41] - work[38]
    if abs(nx * d[0] + ny * d[1] + nz * d[2]) > _FLAT_MM * dist:
        return t
    _, _, p_off, n_p = _part(params, part)
    lo, hi = 0.0, 1.0
    bx, by, bz = p0[0] - nx, p0[1] - ny, p0[2] - nz
    for f in range(n_p):
        j = p_off + 4 * f
        slope = params[j] * d[0] + params[j + 1] * d[1] + params[j + 2] * d[2]
        level = params[j + 3] + _ON_PLANE_MM - (params[j] * bx + params[j + 1] * by + params[j + 2] * bz)
        if slope > 1e-15:
            hi = min(hi, level / slope)
        elif slope < -1e-15:
            lo = max(lo, level / slope)
    if lo <= t <= hi:
        return 0.5 * (lo + hi)
    return t


@jit
def _sphere_gap(params: NDArray, part: int, p0: NDArray, d: NDArray, dd: float) -> float:
    """Distance of the segment p0 + t·d to the part's bounding sphere's centre, less its radius:
    a lower bound of the distance to the part."""
    h = 1 + _HEADER * part
    cx, cy, cz = params[h + 4] - p0[0], params[h + 5] - p0[1], params[h + 6] - p0[2]
    s = 0.0 if dd <= 0.0 else min(max((cx * d[0] + cy * d[1] + cz * d[2]) / dd, 0.0), 1.0)
    gx, gy, gz = s * d[0] - cx, s * d[1] - cy, s * d[2] - cz
    return np.sqrt(gx * gx + gy * gy + gz * gz) - params[h + 7]


@jit
def segment_parts(p0: NDArray, d: NDArray, params: NDArray, work: NDArray) -> tuple[float, float]:
    """Signed distance (mm) from the segment p0 + t·d, t in [0, 1] (own frame) to the union of
    parts and the t attaining it; crossing a part: minus the deepest penetration of a point
    of the segment in it. ``work``: WORK values of scratch space."""
    seg = work[0:6].reshape((2, 3))
    for r in range(3):
        seg[0, r], seg[1, r] = p0[r], p0[r] + d[r]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    best, best_t = np.inf, 0.0
    for k in range(int(params[0])):
        if _sphere_gap(params, k, p0, d, dd) >= best:
            continue  # its bounding sphere is farther than the best so far
        n, touching = _gjk(params, k, seg, work)
        dist = _closest(params, k, seg, work, n)
        if touching:
            dist, t = _deepest_on_segment(params, k, p0, d)
            dist = min(dist, 0.0)
        else:
            qx, qy, qz = work[39] - p0[0], work[40] - p0[1], work[41] - p0[2]
            t = 0.0 if dd <= 0.0 else min(max((qx * d[0] + qy * d[1] + qz * d[2]) / dd, 0.0), 1.0)
            t = _flat_middle(params, k, p0, d, t, work, dist)
        if dist < best:
            best, best_t = dist, t
    return best, best_t


@jit
def segment_parts_gap(p0: NDArray, d: NDArray, params: NDArray, work: NDArray, cutoff: float = np.inf) -> float:
    """:func:`segment_parts`'s signed distance alone (its t is not sought): the parts taken
    nearest bounding sphere first, and none once the next sphere's gap is no smaller than the
    best distance found or than ``cutoff`` (mm). The same number to the last bit wherever it
    is below ``cutoff``: each part's distance does not depend on the order the parts are taken
    in, and a part left out lies no nearer than its sphere (the sphere's gap bounds its
    distance, or minus its depth, from below); elsewhere a number at least ``cutoff``."""
    seg = work[0:6].reshape((2, 3))
    for r in range(3):
        seg[0, r], seg[1, r] = p0[r], p0[r] + d[r]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    n_parts = int(params[0])
    gaps = np.empty(n_parts)
    for k in range(n_parts):
        gaps[k] = _sphere_gap(params, k, p0, d, dd)
    best = np.inf
    for k in np.argsort(gaps):
        if gaps[k] >= min(best, cutoff):
            break
        n, touching = _gjk(params, k, seg, work)
        if touching:
            dist = min(_deepest_on_segment(params, k, p0, d)[0], 0.0)
        else:
            dist = _closest(params, k, seg, work, n)
        if dist < best:
            best = dist
    return best


@jit
def point_parts(x: NDArray, params: NDArray) -> tuple[float, NDArray, NDArray]:
    """Signed distance (mm) of the point x to the union of parts, the nearest surface point and
    the inward unit normal there: outside, from x toward that point (a face's normal where it
    lies inside a face); inside (or within 1e-6 mm), the nearest face's of the part in which
    x is deepest."""
    work = np.zeros(WORK)
    one = work[0:3].reshape((1, 3))
    one[0, 0], one[0, 1], one[0, 2] = x[0], x[1], x[2]
    best, near, normal = np.inf, x.copy(), np.zeros(3)
    for k in range(int(params[0])):
        if _sphere_gap(params, k, x, np.zeros(3), 0.0) >= best:
            continue
        n, touching = _gjk(params, k, one, work)
        dist = _closest(params, k, one, work, n)
        if touching or dist <= 1e-6:
            depth, f = _plane_depth(params, k, x[0], x[1], x[2])
            dist = min(depth, 0.0) if touching else dist
            if dist < best:
                j = int(params[1 + _HEADER * k + 2]) + 4 * f
                n_out = params[j : j + 3]
                best, near, normal = dist, x - depth * n_out, -n_out
        elif dist < best:
            a = work[36:39].copy()
            best, near, normal = dist, a, (a - x) / dist
    return best, near, normal


@jit
def points_gap(points: NDArray, params: NDArray) -> NDArray:
    """(k,) distance (mm, 0 inside) of points (k, 3) to the union of parts."""
    out = np.empty(points.shape[0])
    for i in range(points.shape[0]):
        out[i] = max(point_parts(points[i], params)[0], 0.0)
    return out
