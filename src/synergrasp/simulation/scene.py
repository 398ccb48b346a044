"""One scene of the hand and one object, queried for distances and contacts (mm, palm frame).

Postures and distances are the hand's own forward kinematics and the exact closed forms
of ``synergrasp.simulation.capsules`` on its capsules and boxes and on the object's exact
shape (``synergrasp.simulation.shapes``; no collision margin: contact points lie on its
surface). Nothing is simulated: the scene is a geometric query. Any closure model can use it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.capsules import HandCapsules, capsule_object, capsule_object_gap, pair_gaps
from synergrasp.simulation.placement import ObjectPose
from synergrasp.simulation.shapes.box import box_gap, box_samples

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.simulation.shapes import Shape

__all__ = ["HandScene"]

_MAX_APPROACH_STEPS = 500


class HandScene:
    """The hand (palm fixed at the origin) at a posture, and at most one object."""

    def __init__(self, hand: Hand) -> None:
        self.hand = hand
        self.capsules = HandCapsules.of(hand)
        self._row = np.full(hand.n_links, -1)  # capsule row of each link (-1: the palm)
        self._row[self.capsules.links] = np.arange(len(self.capsules.links))
        self._tree = self.capsules.tree
        self._pair_cache: dict[tuple[tuple[int, int], ...], tuple[NDArray, NDArray, NDArray]] = {}
        self._boxes: list[tuple[NDArray, NDArray]] | None = None
        self.placed: ObjectPose | None = None
        self._palm_gap = (np.inf, np.zeros(3))  # palm–object distance (mm) and a closest point
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

    def place_object(self, placed: ObjectPose) -> None:
        """Put the object ``placed`` (its shape at its pose) in the scene."""
        self.placed = placed
        best = (np.inf, np.zeros(3))
        for pose, half in self._palm_boxes():
            d, point = placed.shape.box_gap(placed.rotation, placed.center_mm, pose, half)
            if d < best[0]:
                best = (d, point)
        self._palm_gap = best

    def _palm_boxes(self) -> list[tuple[NDArray, NDArray]]:
        """The palm's boxes: (4 × 4 pose, half extents mm) each, made once per scene."""
        if self._boxes is None:
            self._boxes = []
            for rotation, centre, half in zip(self.capsules.palm_rotation, self.capsules.palm_centre, self.capsules.palm_half):
                pose = np.eye(4)
                pose[:3, :3], pose[:3, 3] = rotation, centre
                pose.setflags(write=False)
                self._boxes.append((pose, half))
        return self._boxes

    def _palm_patch_centre(self, contact_distance_mm: float) -> NDArray:
        """The middle of the palm–object contact patch: the mean of the sample points (of a
        box: corners, edge middles, face centres; ``Shape.samples``) of the palm boxes and
        of the object within the gap + ``contact_distance_mm`` of the other; when no sample
        is that close (an edge across an edge or a face), the closest point of the two."""
        placed = self.placed
        shape, R, c = placed.shape, placed.rotation, placed.center_mm
        reach = max(self._palm_gap[0], 0.0) + contact_distance_mm
        near = []
        for pose, half in self._palm_boxes():
            palm = box_samples(pose, half)
            near.append(palm[shape.gap(palm, R, c) <= reach])
            own = shape.samples(R, c)
            near.append(own[box_gap(own, pose, half) <= reach])
        near = np.concatenate(near)
        return near.mean(axis=0) if len(near) else self._palm_gap[1]

    def _palm_face_normal(self, point: NDArray, reach_mm: float, otherwise: NDArray) -> NDArray:
        """The object's inward normal at a palm contact at ``point``: the outward normal of
        the palm face within ``reach_mm`` of it if there is exactly one (the object lies on
        that face, with a face, an edge or a corner); else (the contact is at a palm edge) the
        mean inward normal of the object's faces within reach (``Shape.normals_near``),
        normalised; ``otherwise`` if none. Faces are found by distance, never by the order of
        the axes, so the normal is the same for every orientation that fills the same region."""
        palm = []
        for pose, half in self._palm_boxes():
            local = pose[:3, :3].T @ (np.asarray(point) - pose[:3, 3])
            palm += [np.sign(local[k]) * pose[:3, k] for k in range(3) if abs(abs(local[k]) - half[k]) <= reach_mm]
        if len(palm) == 1:
            return palm[0]
        placed = self.placed
        faces = placed.shape.normals_near(point, placed.rotation, placed.center_mm, reach_mm)
        if not faces:
            return otherwise
        mean = np.sum(faces, axis=0)
        return mean / np.linalg.norm(mean)

    def _capsule_query(self) -> tuple:
        """The capsules at the current posture and the placed object, as the compiled queries
        (``capsule_object``, ``capsule_object_gap``) take them."""
        placed = self.placed
        return (
            self._p0,
            self._p1,
            self.capsules.radius,
            placed.rotation,
            placed.center_mm,
            placed.shape.kernel_code,
            placed.shape.kernel_params,
        )

    def _capsule_object(self) -> tuple[NDArray, NDArray]:
        """Signed distance (c,) of every capsule to the object (mm) and the closest axis points (c, 3)."""
        d, t = capsule_object(*self._capsule_query())
        return d, self._p0 + t[:, None] * (self._p1 - self._p0)

    def object_distance(self, margin_mm: float = np.inf) -> NDArray:
        """(n_links,) signed distance of each hand link to the object at the current posture
        (mm, negative = overlap; +inf beyond ``margin_mm``): with the open hand's posture,
        below zero where the object intersects the open hand."""
        d = np.full(self.hand.n_links, np.inf)
        d[self.capsules.links] = capsule_object_gap(*self._capsule_query())
        d[0] = self._palm_gap[0]
        d[d > margin_mm] = np.inf
        return d

    def bring_object(
        self,
        shape: Shape,
        rotation: NDArray,
        point_mm: NDArray,
        direction: NDArray,
        q: NDArray,
        clearance_mm: float = 0.0,
        tolerance_mm: float = 0.01,
        stop_at_point: bool = False,
    ) -> ObjectPose:
        """Bring an object (``shape``, orientation ``rotation``) from far along the line
        point + t·direction (mm; ``direction`` a unit vector pointing away from the hand)
        toward the hand at posture q, until its gap to the hand is ``clearance_mm`` (to
        within ``tolerance_mm``), or, with ``stop_at_point``, until its centre reaches the
        point (t = 0) if that comes first. The object is left there; returns its pose.

        Conservative advancement: a translation by δ changes every distance by at most δ, so
        stepping by the current excess gap never passes the first touch; a last step to
        t = 0 shorter than the excess gap cannot pass it either.
        """
        point, direction = np.asarray(point_mm, dtype=float), np.asarray(direction, dtype=float)
        self.set_posture(q)

        def excess(t: float) -> tuple[ObjectPose, float]:
            placed = ObjectPose(point + t * direction, rotation, shape)
            self.place_object(placed)
            return placed, float(np.min(self.object_distance())) - clearance_mm

        t = 2.0 * shape.bounding_radius_mm + 100.0
        placed, gap = excess(t)
        while gap <= tolerance_mm:  # start clear of the hand
            t *= 2.0
            placed, gap = excess(t)
        for _ in range(_MAX_APPROACH_STEPS):
            if gap <= tolerance_mm:
                break
            if stop_at_point and t - gap <= 0.0:
                return excess(0.0)[0]  # the centre reaches the point before the object touches
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

    def query_args(self) -> tuple:
        """The arguments of ``capsules.posture_gaps`` (per link the gaps to the object and to the
        monitored hand links at a posture q: the kinematic closure's query, made by
        ``closure_march.march``) after q and before the pairs: the hand's frame tree and
        capsules, the palm's gap to the object (mm) and the placed object with the radius of a
        ball about its centre that holds it (mm)."""
        c, placed = self.capsules, self.placed
        return (
            *self._tree,
            c.frame,
            c.ends,
            c.radius,
            c.links,
            float(self._palm_gap[0]),
            placed.rotation,
            placed.center_mm,
            placed.shape.kernel_code,
            placed.shape.kernel_params,
            float(placed.shape.bounding_radius_mm),
        )

    def pair_args(self, pairs: tuple[tuple[int, int], ...]) -> tuple:
        """The arguments of ``capsules.posture_gaps`` from the pairs on: the monitored pairs'
        rows, the palm's boxes and the number of links."""
        ends, first, second = self._pair_rows(pairs)
        c = self.capsules
        return first, second, ends, c.palm_rotation, c.palm_centre, c.palm_half, self.hand.n_links

    def object_contacts(self, q: NDArray, contact_distance_mm: float) -> tuple[NDArray, NDArray, NDArray, float]:
        """One contact per hand link within ``contact_distance_mm`` of the object at posture q:
        (links (m,), points on its exact surface (m, 3) mm, its inward unit normals (m, 3),
        deepest penetration mm (0 if none))."""
        assert self.placed is not None, "place_object first"
        self.set_posture(q)
        d_caps, axis_points = self._capsule_object()
        links, points, normals, depth = [], [], [], 0.0
        candidates = [(0, self._palm_gap[0], self._palm_patch_centre(contact_distance_mm))] + [
            (int(link), float(dc), p) for link, dc, p in zip(self.capsules.links, d_caps, axis_points)
        ]
        for link, dist, near in sorted(candidates, key=lambda c: c[0]):
            if dist > contact_distance_mm:
                continue
            point, normal = self.placed.surface_point(near)
            if link == 0:  # on a palm face, the contact normal is that face's (an edge of the object may lie on it)
                normal = self._palm_face_normal(near, max(self._palm_gap[0], 0.0) + contact_distance_mm, normal)
            links.append(link)
            points.append(point)
            normals.append(normal)
            depth = max(depth, -dist)
        return (np.asarray(links, dtype=np.int64), np.asarray(points).reshape(-1, 3), np.asarray(normals).reshape(-1, 3), depth)
