"""Exact distances between the hand's capsules and boxes (numpy, mm).

The shipped hand is a palm box and one capsule per finger link (docs/hand.md). The
kinematic closure asks, at every posture it tries, how far each link is from the box and
from the hand links it may run into; these closed forms answer for all pairs at once, on
the exact shapes (pybullet's box has rounded edges; here the box is exact, so contact
points lie on the box surface). Signed distances: negative = overlap (for a capsule
crossing a box, minus its deepest penetration, estimated at nine points of its axis).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = ["HandCapsules", "segment_segment_distance", "segment_box_distance"]

_EPS = 1e-12


def segment_segment_distance(p0: NDArray, p1: NDArray, q0: NDArray, q1: NDArray) -> NDArray:
    """(k,) distances (mm) between the segments p0–p1 and q0–q1 ((k, 3) each): the
    clamped closed form (parameters s, t in [0, 1] of the closest points)."""
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = np.einsum("ij,ij->i", d1, r)
    b = np.einsum("ij,ij->i", d1, d2)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > _EPS * np.maximum(a * e, 1.0), np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = np.where(e > _EPS, (b * s + f) / e, 0.0)
        s_lo = np.where(a > _EPS, np.clip(-c / a, 0.0, 1.0), 0.0)
        s_hi = np.where(a > _EPS, np.clip((b - c) / a, 0.0, 1.0), 0.0)
    s = np.where(t < 0.0, s_lo, np.where(t > 1.0, s_hi, s))
    t = np.clip(t, 0.0, 1.0)
    gap = (p0 + s[:, None] * d1) - (q0 + t[:, None] * d2)
    return np.sqrt(np.einsum("ij,ij->i", gap, gap))


def segment_box_distance(p0: NDArray, p1: NDArray, half: NDArray) -> tuple[NDArray, NDArray]:
    """Signed distance (mm) from the segments p0–p1 ((k, 3), in each box's own frame) to the
    boxes centred at the origin with half extents ``half`` ((k, 3) or (3,)), and the
    parameter t in [0, 1] of the segment point that attains it.

    Outside: the exact distance. The squared distance along the segment is convex and
    piecewise quadratic, with breaks where a coordinate crosses ±half; its minimum is at a
    break, an end, or the vertex of one piece. Crossing the box: minus the deepest
    penetration among the breaks, the pieces' middles and nine points of the segment
    (the closure only needs the sign there).
    """
    d = p1 - p0
    half = np.broadcast_to(half, p0.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        brk = np.concatenate([(half - p0) / d, (-half - p0) / d], axis=1)
    brk = np.where(np.isfinite(brk), np.clip(brk, 0.0, 1.0), 0.0)
    knots = np.sort(np.concatenate([np.zeros((len(p0), 1)), np.ones((len(p0), 1)), brk], axis=1), axis=1)
    mid = 0.5 * (knots[:, :-1] + knots[:, 1:])
    x_mid = p0[:, None, :] + mid[..., None] * d[:, None, :]
    side = np.where(x_mid > half[:, None, :], 1.0, np.where(x_mid < -half[:, None, :], -1.0, 0.0))
    a = (p0[:, None, :] - side * half[:, None, :]) * (side != 0)
    dd = d[:, None, :] * (side != 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = -np.sum(a * dd, axis=2) / np.sum(dd * dd, axis=2)
    vertex = np.clip(np.where(np.isfinite(vertex), vertex, mid), knots[:, :-1], knots[:, 1:])
    cand = np.concatenate([knots, vertex], axis=1)
    x = p0[:, None, :] + cand[..., None] * d[:, None, :]
    excess = np.maximum(np.abs(x) - half[:, None, :], 0.0)
    sq = np.sum(excess * excess, axis=2)
    best = np.argmin(sq, axis=1)
    rows = np.arange(len(p0))
    dist, t = np.sqrt(sq[rows, best]), cand[rows, best]
    inside = dist <= 0.0
    if np.any(inside):
        ts = np.concatenate([np.broadcast_to(np.linspace(0.0, 1.0, 9), (int(inside.sum()), 9)),
                             knots[inside], mid[inside]], axis=1)
        xs = p0[inside, None, :] + ts[..., None] * d[inside, None, :]
        depth = np.min(half[inside, None, :] - np.abs(xs), axis=2)
        k = np.argmax(depth, axis=1)
        rows_in = np.arange(len(k))
        dist[inside] = -np.maximum(depth[rows_in, k], 0.0)
        t[inside] = ts[rows_in, k]
    return dist, t


@dataclass(frozen=True)
class HandCapsules:
    """The hand as capsules (one per finger link) and the palm's boxes, in link frames.

    ``links`` (c,) link index of each capsule; ``ends`` (c, 2, 3) its axis end points in
    its link frame (mm); ``radius`` (c,) mm. ``palm_boxes`` (b, 4, 4) box poses in the palm
    frame and ``palm_half`` (b, 3) half extents (mm).
    """

    links: NDArray[np.int64]
    ends: NDArray[np.float64]
    radius: NDArray[np.float64]
    palm_boxes: NDArray[np.float64]
    palm_half: NDArray[np.float64]

    @classmethod
    def of(cls, hand: Hand) -> HandCapsules:
        """The shapes of ``hand``; ValueError unless every finger link is one capsule and the
        palm is made of boxes (the shipped hand)."""
        links, ends, radius = [], [], []
        for link in range(1, hand.n_links):
            shapes = hand.link_shapes[link]
            if len(shapes) != 1 or shapes[0].kind != "capsule":
                raise ValueError(f"the kinematic closure needs one capsule per finger link; link "
                                 f"{hand.link_names[link]!r} has {[s.kind for s in shapes]}")
            shape = shapes[0]
            axis = 0.5 * shape.length * shape.pose[:3, 2]
            links.append(link)
            ends.append([shape.pose[:3, 3] - axis, shape.pose[:3, 3] + axis])
            radius.append(shape.radius)
        palm = hand.link_shapes[0]
        if not palm or any(s.kind != "box" for s in palm):
            raise ValueError("the kinematic closure needs a palm made of boxes")
        return cls(np.asarray(links, dtype=np.int64), np.asarray(ends), np.asarray(radius),
                   np.stack([s.pose for s in palm]), np.stack([0.5 * s.size for s in palm]))

    def segments(self, frames: NDArray) -> tuple[NDArray, NDArray]:
        """Axis end points (c, 3) and (c, 3) of every capsule in the palm frame, given the
        (n_links, 4, 4) link frames."""
        f = frames[self.links]
        world = np.einsum("cij,ckj->cki", f[:, :3, :3], self.ends) + f[:, None, :3, 3]
        return world[:, 0], world[:, 1]
