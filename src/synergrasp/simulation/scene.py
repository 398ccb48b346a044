"""One pybullet scene: the hand and one box, queried for distances and contacts.

mm and the palm frame throughout (every pybullet call goes through
``synergrasp.simulation.bullet``, which converts to metres). The scene is never stepped:
postures are set and the collision pipeline is queried. Any closure model can use it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation import bullet
from synergrasp.simulation.placement import ObjectPose

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = ["HandScene"]


class HandScene:
    """A headless pybullet client holding ``hand`` (fixed palm at the origin) and at most one box."""

    def __init__(self, hand: Hand) -> None:
        self.hand = hand
        self.client = bullet.connect()
        self.body = bullet.load_hand_body(self.client, hand)
        self.box: int | None = None
        self.box_size: NDArray | None = None
        self.placed: ObjectPose | None = None

    def close(self) -> None:
        """Disconnect the pybullet client."""
        bullet.disconnect(self.client)

    def __enter__(self) -> HandScene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def set_posture(self, q: NDArray) -> None:
        """Put the hand at joint angles q (rad)."""
        bullet.set_posture(self.client, self.body, q)

    def place_box(self, size_mm: NDArray, placed: ObjectPose) -> None:
        """Put a box of edge lengths ``size_mm`` at ``placed`` (the body is reused while the size stays)."""
        size = np.asarray(size_mm, dtype=float)
        if self.box is None or self.box_size is None or not np.array_equal(size, self.box_size):
            if self.box is not None:
                bullet.remove_body(self.client, self.box)
            self.box = bullet.load_box(self.client, size, placed.center_mm, placed.rotation)
            self.box_size = size
        else:
            bullet.move_body(self.client, self.box, placed.center_mm, placed.rotation)
        self.placed = placed

    def object_distance(self, margin_mm: float) -> NDArray:
        """(n_links,) distance of each hand link to the box at the current posture
        (mm, negative = overlap; +inf beyond ``margin_mm``)."""
        pts = bullet.closest_points(self.client, self.box, self.body, margin_mm)
        d = np.full(self.hand.n_links, np.inf)
        if len(pts):
            np.minimum.at(d, pts.link_b, pts.distance)
        return d

    def self_distance(self, pairs: tuple[tuple[int, int], ...], margin_mm: float) -> tuple[NDArray, NDArray]:
        """Per link, the distance (mm, negative = overlap; +inf beyond ``margin_mm``) to the
        nearest link it is paired with in ``pairs`` at the current posture, and that link
        (-1 where none): two (n_links,) arrays."""
        d = np.full(self.hand.n_links, np.inf)
        partner = np.full(self.hand.n_links, -1)
        if pairs:
            pts = bullet.self_closest_points(self.client, self.body, margin_mm, pairs)
            for a, b, dist in zip(pts.link_a, pts.link_b, pts.distance):
                if dist < d[a]:
                    d[a], partner[a] = dist, b
                if dist < d[b]:
                    d[b], partner[b] = dist, a
        return d, partner

    def pair_distances(self, pairs: tuple[tuple[int, int], ...], margin_mm: float) -> dict[tuple[int, int], float]:
        """Distance (mm) of each pair of hand links of ``pairs`` closer than ``margin_mm``."""
        out: dict[tuple[int, int], float] = {}
        if pairs:
            pts = bullet.self_closest_points(self.client, self.body, margin_mm, pairs)
            for a, b, d in zip(pts.link_a, pts.link_b, pts.distance):
                key = (int(min(a, b)), int(max(a, b)))
                out[key] = min(out.get(key, np.inf), float(d))
        return out

    def object_contacts(self, q: NDArray, contact_distance_mm: float) -> tuple[NDArray, NDArray, NDArray, float]:
        """One contact per hand link within ``contact_distance_mm`` of the box at posture q:
        (links (m,), points on the exact box surface (m, 3) mm, the box's inward unit normals
        (m, 3), deepest penetration mm (0 if none))."""
        assert self.placed is not None, "place_box first"
        self.set_posture(q)
        pts = bullet.closest_points(self.client, self.box, self.body, contact_distance_mm)
        links, points, normals, depth = [], [], [], 0.0
        for link in sorted(set(int(v) for v in pts.link_b)):
            if link < 0:
                continue
            rows = np.flatnonzero(pts.link_b == link)
            k = rows[np.argmin(pts.distance[rows])]
            point, normal = self.placed.surface_point(pts.point_b[k])
            links.append(link)
            points.append(point)
            normals.append(normal)
            depth = max(depth, -float(pts.distance[k]))
        return (np.asarray(links, dtype=np.int64), np.asarray(points).reshape(-1, 3),
                np.asarray(normals).reshape(-1, 3), depth)
