"""The hand as capsules and boxes: forward kinematics and exact distances (compiled, mm).

The shipped hand is a palm box and one capsule per finger link (docs/hand.md). The
kinematic closure asks, at every posture it tries, how far each link is from the box and
from the hand links it may run into; the closed forms here answer for all of them at once
on the exact shapes (the box has no collision margin, so contact points lie on its
surface). They are compiled with numba, cached with the shapes' queries they call
(``synergrasp.simulation.shapes.compiled``): a posture costs a few microseconds instead of
the milliseconds of a collision library's per-pair queries. Signed distances: negative =
overlap (a capsule crossing the object or a palm box: minus the deepest penetration found;
the closure only needs the sign there). The queries of a segment against each shape, the
palm's boxes included, are ``synergrasp.simulation.shapes.kernels``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.checks import closure_shape_problems
from synergrasp.simulation.shapes.compiled import jit
from synergrasp.simulation.shapes.kernels import segment_box, segment_object, segment_object_gap
from synergrasp.simulation.shapes.polytope import WORK

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = [
    "HandCapsules",
    "segment_segment_distance",
    "capsule_object",
    "capsule_object_gap",
    "pair_gaps",
    "nearest_per_link",
    "posture_gaps",
]

_EPS = 1e-12


@jit
def _dot(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> float:
    return a0 * b0 + a1 * b1 + a2 * b2


@jit
def _seg_seg(p0: NDArray, p1: NDArray, q0: NDArray, q1: NDArray) -> float:
    """Distance (mm) between segments p0–p1 and q0–q1: the clamped closed form."""
    d10, d11, d12 = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    d20, d21, d22 = q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]
    r0, r1, r2 = p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2]
    a, e = _dot(d10, d11, d12, d10, d11, d12), _dot(d20, d21, d22, d20, d21, d22)
    f, c = _dot(d20, d21, d22, r0, r1, r2), _dot(d10, d11, d12, r0, r1, r2)
    b = _dot(d10, d11, d12, d20, d21, d22)
    denom = a * e - b * b
    s = 0.0
    if denom > _EPS * max(a * e, 1.0):
        s = min(max((b * f - c * e) / denom, 0.0), 1.0)
    t = (b * s + f) / e if e > _EPS else 0.0
    if t < 0.0:
        t = 0.0
        s = min(max(-c / a, 0.0), 1.0) if a > _EPS else 0.0
    elif t > 1.0:
        t = 1.0
        s = min(max((b - c) / a, 0.0), 1.0) if a > _EPS else 0.0
    g0, g1, g2 = r0 + s * d10 - t * d20, r1 + s * d11 - t * d21, r2 + s * d12 - t * d22
    return np.sqrt(_dot(g0, g1, g2, g0, g1, g2))


@jit
def segment_segment_distance(p0: NDArray, p1: NDArray, q0: NDArray, q1: NDArray) -> NDArray:
    """(k,) distances (mm) between the segments p0–p1 and q0–q1 ((k, 3) each)."""
    out = np.empty(p0.shape[0])
    for i in range(p0.shape[0]):
        out[i] = _seg_seg(p0[i], p1[i], q0[i], q1[i])
    return out


@jit
def _frames(q: NDArray, parent: NDArray, offset: NDArray, axis: NDArray, joint: NDArray, scale: NDArray) -> NDArray:
    """(n_frames, 4, 4) frame transforms at q (the same chain as ``hand.frame_transforms``)."""
    n = parent.shape[0]
    out = np.empty((n, 4, 4))
    rot, local = np.empty((3, 3)), np.empty((4, 4))
    # Element loops, not slice assignments: numba compiles a slice assignment's shape-mismatch
    # message (string formatting), seconds of the closure's first compile.
    for i in range(4):
        for j in range(4):
            out[0, i, j] = 1.0 if i == j else 0.0
    for f in range(1, n):
        angle = scale[f] * q[joint[f]]
        c, s = np.cos(angle), np.sin(angle)
        x, y, z = axis[f, 0], axis[f, 1], axis[f, 2]
        v = 1.0 - c
        rot[0, 0], rot[0, 1], rot[0, 2] = c + x * x * v, x * y * v - z * s, x * z * v + y * s
        rot[1, 0], rot[1, 1], rot[1, 2] = y * x * v + z * s, c + y * y * v, y * z * v - x * s
        rot[2, 0], rot[2, 1], rot[2, 2] = z * x * v - y * s, z * y * v + x * s, c + z * z * v
        for i in range(4):
            local[i, 3] = offset[f, i, 3]
            local[3, i] = offset[f, 3, i]
        for i in range(3):
            for j in range(3):
                local[i, j] = offset[f, i, 0] * rot[0, j] + offset[f, i, 1] * rot[1, j] + offset[f, i, 2] * rot[2, j]
        top = out[parent[f]]
        for i in range(4):
            for j in range(4):
                out[f, i, j] = (
                    top[i, 0] * local[0, j] + top[i, 1] * local[1, j] + top[i, 2] * local[2, j] + top[i, 3] * local[3, j]
                )
    return out


@jit
def _segments(frames: NDArray, cap_frame: NDArray, ends: NDArray) -> tuple[NDArray, NDArray]:
    c = cap_frame.shape[0]
    p0, p1 = np.empty((c, 3)), np.empty((c, 3))
    for i in range(c):
        f = frames[cap_frame[i]]
        for r in range(3):
            p0[i, r] = f[r, 0] * ends[i, 0, 0] + f[r, 1] * ends[i, 0, 1] + f[r, 2] * ends[i, 0, 2] + f[r, 3]
            p1[i, r] = f[r, 0] * ends[i, 1, 0] + f[r, 1] * ends[i, 1, 1] + f[r, 2] * ends[i, 1, 2] + f[r, 3]
    return p0, p1


@jit
def _to_box(p: NDArray, rotation: NDArray, centre: NDArray, out: NDArray) -> None:
    """p (palm frame) in the frame of a box at (rotation, centre): out = rotationᵀ (p − centre)."""
    for j in range(3):
        out[j] = (p[0] - centre[0]) * rotation[0, j] + (p[1] - centre[1]) * rotation[1, j] + (p[2] - centre[2]) * rotation[2, j]


@jit
def _capsule_to_box(
    p0: NDArray, p1: NDArray, rotation: NDArray, centre: NDArray, half: NDArray, work: NDArray
) -> tuple[float, float]:
    """Signed distance of the axis p0–p1 (palm frame) to a box at (rotation, centre) and its
    parameter; ``work`` (4, 8) is scratch space."""
    _to_box(p0, rotation, centre, work[0])
    _to_box(p1, rotation, centre, work[1])
    for i in range(3):
        work[1, i] -= work[0, i]
    return segment_box(work[0, :3], work[1, :3], half, work[2])


@jit
def _capsule_to_object(
    p0: NDArray, p1: NDArray, rotation: NDArray, centre: NDArray, code: int, params: NDArray, work: NDArray
) -> tuple[float, float]:
    """Signed distance of the axis p0–p1 (palm frame) to an object at (rotation, centre) and
    its parameter; ``work`` (3, WORK) is scratch space."""
    _to_box(p0, rotation, centre, work[0])
    _to_box(p1, rotation, centre, work[1])
    for i in range(3):
        work[1, i] -= work[0, i]
    return segment_object(work[0, :3], work[1, :3], code, params, work[2])


@jit
def _capsule_gap_to_object(
    p0: NDArray,
    p1: NDArray,
    rotation: NDArray,
    centre: NDArray,
    code: int,
    params: NDArray,
    work: NDArray,
    cutoff: float = np.inf,
) -> float:
    """:func:`_capsule_to_object`'s signed distance alone, the same where it is below ``cutoff``
    (mm; ``kernels.segment_object_gap``)."""
    _to_box(p0, rotation, centre, work[0])
    _to_box(p1, rotation, centre, work[1])
    for i in range(3):
        work[1, i] -= work[0, i]
    return segment_object_gap(work[0, :3], work[1, :3], code, params, work[2], cutoff)


@jit
def capsule_object(
    p0: NDArray, p1: NDArray, radius: NDArray, rotation: NDArray, centre: NDArray, code: int, params: NDArray
) -> tuple[NDArray, NDArray]:
    """Signed distance (c,) of every capsule to the object (shape ``code``, ``params``; palm
    frame pose) and the parameter of the closest point of its axis."""
    c = p0.shape[0]
    dist, t = np.empty(c), np.empty(c)
    work = np.empty((3, WORK))
    for i in range(c):
        d, ti = _capsule_to_object(p0[i], p1[i], rotation, centre, code, params, work)
        dist[i], t[i] = d - radius[i], ti
    return dist, t


@jit
def capsule_object_gap(
    p0: NDArray, p1: NDArray, radius: NDArray, rotation: NDArray, centre: NDArray, code: int, params: NDArray
) -> NDArray:
    """:func:`capsule_object`'s signed distances (c,) alone, the same to the last bit, without
    seeking the closest points (what a question of gaps only needs)."""
    c = p0.shape[0]
    dist = np.empty(c)
    work = np.empty((3, WORK))
    for i in range(c):
        dist[i] = _capsule_gap_to_object(p0[i], p1[i], rotation, centre, code, params, work) - radius[i]
    return dist


@jit
def pair_gaps(
    p0: NDArray,
    p1: NDArray,
    radius: NDArray,
    first: NDArray,
    second: NDArray,
    palm_rotation: NDArray,
    palm_centre: NDArray,
    palm_half: NDArray,
) -> NDArray:
    """Signed distance (p,) of pairs of capsules (rows ``first``, ``second``); ``second`` = -1:
    the capsule against the palm boxes (b, ...) instead."""
    out = np.empty(first.shape[0])
    work = np.empty((3, 8))
    for k in range(first.shape[0]):
        i, j = first[k], second[k]
        if j >= 0:
            out[k] = _seg_seg(p0[i], p1[i], p0[j], p1[j]) - radius[i] - radius[j]
        else:
            best = np.inf
            for b in range(palm_half.shape[0]):
                d, _ = _capsule_to_box(p0[i], p1[i], palm_rotation[b], palm_centre[b], palm_half[b], work)
                best = min(best, d - radius[i])
            out[k] = best
    return out


@jit
def nearest_per_link(gaps: NDArray, ends: NDArray, n_links: int) -> tuple[NDArray, NDArray]:
    """Per link, the smallest gap (mm) of the pairs ``ends`` (p, 2) it belongs to and the other
    link of that pair: (n_links,) distances (+inf where none) and partners (-1 where none)."""
    d = np.full(n_links, np.inf)
    partner = np.full(n_links, -1)
    for k in range(gaps.shape[0]):
        for side in range(2):
            link = ends[k, side]
            if gaps[k] < d[link]:
                d[link], partner[link] = gaps[k], ends[k, 1 - side]
    return d, partner


#: Slack (mm) of the bound below which a capsule's distance to the object is computed
#: (``_beyond``): far above the bound's round-off (~1e-13 mm), so a skipped capsule is surely
#: beyond the margin.
_BOUND_SLACK_MM = 1e-6


@jit
def _beyond(p0: NDArray, p1: NDArray, radius: float, centre: NDArray, bound_mm: float, margin_mm: float) -> bool:
    """Whether the capsule p0–p1 (palm frame) of ``radius`` is surely farther than
    ``margin_mm`` from an object held in the ball of radius ``bound_mm`` about ``centre``:
    its axis's distance to the centre, less both radii, exceeds the margin (a lower bound of
    the signed distance; inside, it is at most 0)."""
    dx, dy, dz = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    wx, wy, wz = centre[0] - p0[0], centre[1] - p0[1], centre[2] - p0[2]
    dd = dx * dx + dy * dy + dz * dz
    t = 0.0 if dd <= _EPS else min(max((wx * dx + wy * dy + wz * dz) / dd, 0.0), 1.0)
    ex, ey, ez = wx - t * dx, wy - t * dy, wz - t * dz
    return np.sqrt(ex * ex + ey * ey + ez * ez) - bound_mm - radius > margin_mm + _BOUND_SLACK_MM


@jit
def posture_gaps(
    q: NDArray,
    parent: NDArray,
    offset: NDArray,
    axis: NDArray,
    joint: NDArray,
    scale: NDArray,
    cap_frame: NDArray,
    ends: NDArray,
    radius: NDArray,
    cap_link: NDArray,
    palm_gap: float,
    object_rotation: NDArray,
    object_centre: NDArray,
    code: int,
    params: NDArray,
    bound_mm: float,
    first: NDArray,
    second: NDArray,
    pair_ends: NDArray,
    palm_rotation: NDArray,
    palm_centre: NDArray,
    palm_half: NDArray,
    n_links: int,
    moving_links: NDArray,
    margin_mm: float,
) -> tuple[NDArray, NDArray, NDArray]:
    """Everything the closure asks at one posture q (rad), in one call: per link the signed
    distance to the object (the palm's, ``palm_gap``, does not change with q), the distance to
    the nearest link it is paired with and that link (mm; see ``pair_gaps``).

    Only what the closure reads is computed: a link that does not move (``moving_links``
    False) or that is surely farther than ``margin_mm`` from the object (``_beyond``, the
    object in the ball of radius ``bound_mm`` about its centre) gets +inf, as the closure's
    mask would give it; every other distance within the margin is ``capsule_object``'s to the
    last bit, and one beyond it (the closure masks it) is at least the margin."""
    p0, p1 = _segments(_frames(q, parent, offset, axis, joint, scale), cap_frame, ends)
    d_obj = np.full(n_links, np.inf)
    d_obj[0] = palm_gap
    work = np.empty((3, WORK))
    for i in range(cap_link.shape[0]):
        if not moving_links[cap_link[i]] or _beyond(p0[i], p1[i], radius[i], object_centre, bound_mm, margin_mm):
            continue
        # beyond margin + radius the closure masks the gap: a convex part surely that far is not measured
        cutoff = margin_mm + radius[i] + _BOUND_SLACK_MM
        d_obj[cap_link[i]] = (
            _capsule_gap_to_object(p0[i], p1[i], object_rotation, object_centre, code, params, work, cutoff) - radius[i]
        )
    gaps = pair_gaps(p0, p1, radius, first, second, palm_rotation, palm_centre, palm_half)
    d_self, partner = nearest_per_link(gaps, pair_ends, n_links)
    return d_obj, d_self, partner


@dataclass(frozen=True)
class HandCapsules:
    """The hand as capsules (one per finger link) and the palm's boxes, with its frame tree.

    ``links`` (c,) link index of each capsule; ``frame`` (c,) the frame it is attached to;
    ``ends`` (c, 2, 3) its axis end points in that frame (mm); ``radius`` (c,) mm.
    ``palm_rotation`` (b, 3, 3), ``palm_centre`` (b, 3), ``palm_half`` (b, 3): the palm's
    boxes in the palm frame (mm).
    """

    hand: Hand
    links: NDArray[np.int64]
    frame: NDArray[np.int64]
    ends: NDArray[np.float64]
    radius: NDArray[np.float64]
    palm_rotation: NDArray[np.float64]
    palm_centre: NDArray[np.float64]
    palm_half: NDArray[np.float64]

    @classmethod
    def of(cls, hand: Hand) -> HandCapsules:
        """The shapes of ``hand``; ValueError naming the hand file and the field unless every
        finger link is one capsule and the palm is made of boxes
        (``synergrasp.hand.checks.closure_shape_problems``)."""
        problems = closure_shape_problems(hand)
        if problems:
            raise ValueError(f"{hand.source}: {problems[0]}")
        links, ends, radius = [], [], []
        for link in range(1, hand.n_links):
            if not hand.link_shapes[link]:  # a link that only carries a joint (hand.shapeless_links)
                continue
            shape = hand.link_shapes[link][0]
            axis = 0.5 * shape.length * shape.pose[:3, 2]
            links.append(link)
            ends.append([shape.pose[:3, 3] - axis, shape.pose[:3, 3] + axis])
            radius.append(shape.radius)
        palm = hand.link_shapes[0]
        links_arr = np.asarray(links, dtype=np.int64)
        return cls(
            hand,
            links_arr,
            np.asarray(hand.link_frame, dtype=np.int64)[links_arr],
            np.asarray(ends),
            np.asarray(radius),
            np.stack([s.pose[:3, :3] for s in palm]),
            np.stack([s.pose[:3, 3] for s in palm]),
            np.stack([0.5 * s.size for s in palm]),
        )

    @property
    def tree(self) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        """The hand's frame tree as arrays (parent, offset, axis, joint, scale) for ``_frames``."""
        h = self.hand
        return (
            np.asarray(h.frame_parent, dtype=np.int64),
            np.ascontiguousarray(h.frame_offset),
            np.ascontiguousarray(h.frame_axis),
            np.asarray(h.frame_joint, dtype=np.int64),
            np.ascontiguousarray(h.frame_scale),
        )

    def segments(self, q: NDArray) -> tuple[NDArray, NDArray]:
        """Axis end points (c, 3) and (c, 3) of every capsule in the palm frame at q (rad)."""
        # a fresh writeable copy: a read-only or strided q (a table's row) would compile another specialisation
        return _segments(_frames(np.array(q, dtype=float), *self.tree), self.frame, self.ends)

    def encloses(self, q: NDArray, point_mm: NDArray) -> bool:
        """Whether ``point_mm`` (palm frame) lies inside the hand at q (rad): within the convex
        hull of the hand's volume, the capsules (each axis end point widened by its radius in
        14 directions, a polyhedron inside the sphere) and the palm boxes' corners. The hull's
        facets, not a triangulation of its inside: 0.3 ms against ~100 ms for the ~540 points."""
        from scipy.spatial import ConvexHull

        p0, p1 = self.segments(q)
        cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        directions = np.vstack([np.eye(3), -np.eye(3), cube / np.sqrt(3.0)])
        widened = (
            np.vstack([p0, p1])[:, None, :] + np.concatenate([self.radius, self.radius])[:, None, None] * directions[None]
        ).reshape(-1, 3)
        corners = [c + (cube * h) @ r.T for r, c, h in zip(self.palm_rotation, self.palm_centre, self.palm_half)]
        facets = ConvexHull(np.vstack([widened, *corners])).equations  # rows (outward n, offset): n·x + offset ≤ 0 inside
        return bool(np.max(facets[:, :3] @ np.asarray(point_mm, dtype=float) + facets[:, 3]) <= 1e-9)
