"""One scene of the hand and one box, queried for distances and contacts (mm, palm frame).

Postures and distances are the hand's own forward kinematics and the exact closed forms
of ``synergrasp.simulation.capsules`` on its capsules and boxes and on the exact box (no
collision margin: contact points lie on the box surface). Nothing is simulated: the
scene is a geometric query. Any closure model can use it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.capsules import (
    HandCapsules,
    capsule_box,
    nearest_per_link,
    pair_gaps,
    posture_gaps,
    segment_box_distance,
)
from synergrasp.simulation.placement import ObjectPose

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = ["HandScene"]

_MAX_APPROACH_STEPS = 500
#: The 12 edges of a box as pairs of corner sign vectors.
_CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
_EDGES = np.array([(a, b) for a in range(8) for b in range(a + 1, 8)
                   if np.count_nonzero(_CORNERS[a] != _CORNERS[b]) == 1])


def _box_edges(pose: NDArray, half: NDArray) -> tuple[NDArray, NDArray]:
    """End points (12, 3), (12, 3) of a box's edges (pose 4 × 4 in the palm frame, half extents)."""
    corners = (_CORNERS * half) @ pose[:3, :3].T + pose[:3, 3]
    return corners[_EDGES[:, 0]], corners[_EDGES[:, 1]]


class HandScene:
    """The hand (palm fixed at the origin) at a posture, and at most one box."""

    def __init__(self, hand: Hand) -> None:
        self.hand = hand
        self.capsules = HandCapsules.of(hand)
        self._row = np.full(hand.n_links, -1)  # capsule row of each link (-1: the palm)
        self._row[self.capsules.links] = np.arange(len(self.capsules.links))
        self._tree = self.capsules.tree
        self._pair_cache: dict[tuple[tuple[int, int], ...], tuple[NDArray, NDArray, NDArray]] = {}
        self.placed: ObjectPose | None = None
        self._palm_gap = (np.inf, np.zeros(3))  # palm–box distance (mm) and the palm point
        self.set_posture(np.clip(np.zeros(hand.n_joints), hand.lower, hand.upper))

    def close(self) -> None:
        """Nothing to release (kept so that a scene is used like a closure model)."""

    def __enter__(self) -> HandScene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def set_posture(self, q: NDArray) -> None:
        """Put the hand at joint angles q (rad)."""
        self._p0, self._p1 = self.capsules.segments(q)

    def place_box(self, size_mm: NDArray, placed: ObjectPose) -> None:
        """Put a box of edge lengths ``size_mm`` (mm) at ``placed``."""
        if not np.allclose(2.0 * placed.half_extents_mm, size_mm):
            raise ValueError(f"size_mm {size_mm} does not match the placed box {2.0 * placed.half_extents_mm}")
        self.placed = placed
        best = (np.inf, np.zeros(3))
        box_pose, box_half = _pose(placed), placed.half_extents_mm
        b0, b1 = _box_edges(box_pose, box_half)
        for pose, half in self._palm_boxes():
            # two convex boxes: the closest points lie on an edge of one of them
            a0, a1 = _box_edges(pose, half)
            d_ab, t_ab = segment_box_distance(*_to_local(a0, a1, box_pose), np.tile(box_half, (12, 1)))
            d_ba, t_ba = segment_box_distance(*_to_local(b0, b1, pose), np.tile(half, (12, 1)))
            d = min(float(d_ab.min()), float(d_ba.min()))
            if d < best[0]:
                # every edge at that distance (ties are common: parallel edges and faces), so
                # that the point does not depend on the order of the edges
                ends = np.concatenate([a0 + t_ab[:, None] * (a1 - a0), b0 + t_ba[:, None] * (b1 - b0)])
                tied = np.concatenate([d_ab, d_ba]) <= d + 1e-6
                best = (d, ends[tied].mean(axis=0))
        self._palm_gap = best

    def _palm_boxes(self) -> list[tuple[NDArray, NDArray]]:
        poses = []
        for rotation, centre, half in zip(self.capsules.palm_rotation, self.capsules.palm_centre, self.capsules.palm_half):
            pose = np.eye(4)
            pose[:3, :3], pose[:3, 3] = rotation, centre
            poses.append((pose, half))
        return poses

    def _palm_patch_centre(self, contact_distance_mm: float) -> NDArray:
        """The middle of the palm–box contact patch: the mean of the sample points (corners,
        edge middles, face centres) of either box within the gap + ``contact_distance_mm`` of
        the other; when no sample is that close (an edge across an edge or a face), the mean
        of the closest points of the closest edges."""
        box_pose, box_half = _pose(self.placed), self.placed.half_extents_mm
        reach = max(self._palm_gap[0], 0.0) + contact_distance_mm
        near = []
        for pose, half in self._palm_boxes():
            for points, other, other_half in ((_box_samples(pose, half), box_pose, box_half),
                                              (_box_samples(box_pose, box_half), pose, half)):
                near.append(points[_box_gap(points, other, other_half) <= reach])
        near = np.concatenate(near)
        return near.mean(axis=0) if len(near) else self._palm_gap[1]

    def _palm_face_normal(self, point: NDArray, reach_mm: float, otherwise: NDArray) -> NDArray:
        """The object's inward normal at a palm contact at ``point``: the outward normal of
        the palm face within ``reach_mm`` of it if there is exactly one (the box lies on that
        face, with a face, an edge or a corner); else (the contact is at a palm edge) the
        mean inward normal of the box faces within reach, normalised; ``otherwise`` if none.
        Faces are found by distance, never by the order of the axes, so the normal is the
        same for every orientation of the box that fills the same region."""
        palm = []
        for pose, half in self._palm_boxes():
            local = pose[:3, :3].T @ (np.asarray(point) - pose[:3, 3])
            palm += [np.sign(local[k]) * pose[:3, k] for k in range(3) if abs(abs(local[k]) - half[k]) <= reach_mm]
        if len(palm) == 1:
            return palm[0]
        R, half = self.placed.rotation, self.placed.half_extents_mm
        local = R.T @ (np.asarray(point) - self.placed.center_mm)
        box = [-np.sign(local[k]) * R[:, k] for k in range(3) if abs(abs(local[k]) - half[k]) <= reach_mm]
        if not box:
            return otherwise
        mean = np.sum(box, axis=0)
        return mean / np.linalg.norm(mean)

    def _capsule_box(self) -> tuple[NDArray, NDArray]:
        """Signed distance (c,) of every capsule to the box (mm) and the closest axis points (c, 3)."""
        placed = self.placed
        d, t = capsule_box(self._p0, self._p1, self.capsules.radius, placed.rotation, placed.center_mm,
                           placed.half_extents_mm)
        return d, self._p0 + t[:, None] * (self._p1 - self._p0)

    def object_distance(self, margin_mm: float = np.inf) -> NDArray:
        """(n_links,) signed distance of each hand link to the box at the current posture
        (mm, negative = overlap; +inf beyond ``margin_mm``)."""
        d = np.full(self.hand.n_links, np.inf)
        d[self.capsules.links] = self._capsule_box()[0]
        d[0] = self._palm_gap[0]
        d[d > margin_mm] = np.inf
        return d

    def bring_box(self, size_mm: NDArray, rotation: NDArray, point_mm: NDArray, direction: NDArray,
                  q: NDArray, clearance_mm: float = 0.0, tolerance_mm: float = 0.01,
                  stop_at_point: bool = False) -> ObjectPose:
        """Bring a box (edge lengths ``size_mm``, orientation ``rotation``) from far along the
        line point + t·direction (mm; ``direction`` a unit vector pointing away from the hand)
        toward the hand at posture q, until its gap to the hand is ``clearance_mm`` (to
        within ``tolerance_mm``), or, with ``stop_at_point``, until its centre reaches the
        point (t = 0) if that comes first. The box is left there; returns its pose.

        Conservative advancement: a translation by δ changes every distance by at most δ, so
        stepping by the current excess gap never passes the first touch; a last step to
        t = 0 shorter than the excess gap cannot pass it either.
        """
        size = np.asarray(size_mm, dtype=float)
        point, direction = np.asarray(point_mm, dtype=float), np.asarray(direction, dtype=float)
        self.set_posture(q)

        def excess(t: float) -> tuple[ObjectPose, float]:
            placed = ObjectPose(point + t * direction, rotation, size / 2.0)
            self.place_box(size, placed)
            return placed, float(np.min(self.object_distance())) - clearance_mm

        t = float(np.linalg.norm(size)) + 100.0
        placed, gap = excess(t)
        while gap <= tolerance_mm:  # start clear of the hand
            t *= 2.0
            placed, gap = excess(t)
        for _ in range(_MAX_APPROACH_STEPS):
            if gap <= tolerance_mm:
                break
            if stop_at_point and t - gap <= 0.0:
                return excess(0.0)[0]  # the centre reaches the point before the box touches
            t -= gap
            placed, gap = excess(t)
        return placed

    def _pair_rows(self, pairs: tuple[tuple[int, int], ...]) -> tuple[NDArray, NDArray, NDArray]:
        """(ends (p, 2), first capsule row, second capsule row or -1 for the palm), cached per pairs."""
        rows = self._pair_cache.get(pairs)
        if rows is None:
            ends = np.ascontiguousarray(np.asarray(pairs, dtype=np.int64).reshape(-1, 2))
            first = self._row[np.where(ends[:, 0] == 0, ends[:, 1], ends[:, 0])]
            second = np.where((ends[:, 0] == 0) | (ends[:, 1] == 0), -1, self._row[ends[:, 1]])
            rows = self._pair_cache[pairs] = (ends, first, second)
        return rows

    def pair_distances(self, pairs: tuple[tuple[int, int], ...]) -> NDArray:
        """(p,) signed distance (mm) of each pair of hand links at the current posture: capsule
        against capsule, or capsule against the palm (link 0)."""
        if not pairs:
            return np.zeros(0)
        _, first, second = self._pair_rows(pairs)
        c = self.capsules
        return pair_gaps(self._p0, self._p1, c.radius, first, second, c.palm_rotation, c.palm_centre, c.palm_half)

    def posture_gaps(self, q: NDArray, pairs: tuple[tuple[int, int], ...]) -> tuple[NDArray, NDArray, NDArray]:
        """At posture q (rad), in one compiled call: per link the signed distance to the box,
        to the nearest link it is paired with in ``pairs`` and that link (-1 where none), mm.
        (The same numbers as ``object_distance`` and ``self_distance``; the posture is not kept.)"""
        ends, first, second = self._pair_rows(pairs)
        c, placed = self.capsules, self.placed
        return posture_gaps(np.asarray(q, dtype=float), *self._tree, c.frame, c.ends, c.radius, c.links,
                            float(self._palm_gap[0]), placed.rotation, placed.center_mm, placed.half_extents_mm,
                            first, second, ends, c.palm_rotation, c.palm_centre, c.palm_half, self.hand.n_links)

    def self_distance(self, pairs: tuple[tuple[int, int], ...], margin_mm: float = np.inf) -> tuple[NDArray, NDArray]:
        """Per link, the distance (mm, negative = overlap; +inf beyond ``margin_mm``) to the
        nearest link it is paired with in ``pairs`` at the current posture, and that link
        (-1 where none): two (n_links,) arrays."""
        if not pairs:
            return np.full(self.hand.n_links, np.inf), np.full(self.hand.n_links, -1)
        ends, _, _ = self._pair_rows(pairs)
        d, partner = nearest_per_link(self.pair_distances(pairs), ends, self.hand.n_links)
        d[d > margin_mm] = np.inf
        return d, partner

    def object_contacts(self, q: NDArray, contact_distance_mm: float) -> tuple[NDArray, NDArray, NDArray, float]:
        """One contact per hand link within ``contact_distance_mm`` of the box at posture q:
        (links (m,), points on the exact box surface (m, 3) mm, the box's inward unit normals
        (m, 3), deepest penetration mm (0 if none))."""
        assert self.placed is not None, "place_box first"
        self.set_posture(q)
        d_caps, axis_points = self._capsule_box()
        links, points, normals, depth = [], [], [], 0.0
        candidates = [(0, self._palm_gap[0], self._palm_patch_centre(contact_distance_mm))] + [
            (int(link), float(dc), p) for link, dc, p in zip(self.capsules.links, d_caps, axis_points)]
        for link, dist, near in sorted(candidates, key=lambda c: c[0]):
            if dist > contact_distance_mm:
                continue
            point, normal = self.placed.surface_point(near)
            if link == 0:  # on a palm face, the contact normal is that face's (an edge of the box may lie on it)
                normal = self._palm_face_normal(near, max(self._palm_gap[0], 0.0) + contact_distance_mm, normal)
            links.append(link)
            points.append(point)
            normals.append(normal)
            depth = max(depth, -dist)
        return (np.asarray(links, dtype=np.int64), np.asarray(points).reshape(-1, 3),
                np.asarray(normals).reshape(-1, 3), depth)


def _box_samples(pose: NDArray, half: NDArray) -> NDArray:
    """(27, 3) corners, edge middles, face centres and centre of a box, palm frame."""
    grid = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)], dtype=float)
    return (grid * half) @ pose[:3, :3].T + pose[:3, 3]


def _box_gap(points: NDArray, pose: NDArray, half: NDArray) -> NDArray:
    """(k,) distance (mm, 0 inside) of points (palm frame) to a box."""
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    return np.linalg.norm(np.maximum(np.abs(local) - half, 0.0), axis=1)


def _pose(placed: ObjectPose) -> NDArray:
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = placed.rotation, placed.center_mm
    return pose


def _to_local(p0: NDArray, p1: NDArray, pose: NDArray) -> tuple[NDArray, NDArray]:
    R, c = pose[:3, :3], pose[:3, 3]
    return (p0 - c) @ R, (p1 - c) @ R
