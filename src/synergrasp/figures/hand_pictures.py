"""Shaded pictures of the hand and of an object, ray-cast from the bodies the simulation uses.

The hand is what the closure collides (``synergrasp.simulation.capsules``): a capsule per
phalanx (axis end points and radius at the posture) and the palm box; the object is its
exact shape (``Shape.ray_hits``). Every pixel of an orthographic camera casts a ray and the
nearest exact intersection with a capsule or shape gives its depth, surface normal and link
(a z-buffer). The picture is then shaded (ambient + diffuse + a little specular light from
the upper left of the viewer), outlined (dark lines wherever the link seen changes, so every
phalanx stays distinct), the object is see-through (hand parts behind it show through, parts
in front cover it; its outline where the face seen changes), an
optional reference posture is a pale silhouette behind the hand, and everything is
computed at ``supersample`` times the size and averaged down (smooth edges). Pure numpy:
deterministic, no renderer, no display. Positions in the palm frame, mm.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["Camera", "ShapeInPicture", "HandShapes", "Picture", "hand_shapes", "render", "SKIN", "TOUCHING", "BOX", "PALM_CAMERA"]

#: Colours (r, g, b in [0, 1]): the hand, a link touching the object, the object.
SKIN = (0.96, 0.80, 0.67)
TOUCHING = (0.93, 0.40, 0.06)
BOX = (0.33, 0.52, 0.85)
_BACKGROUND = 1.0
_GHOST = 0.87  # grey of the reference silhouette
_OUTLINE = 0.15  # grey of the outlines
_BOX_OPACITY = 0.42  # share of the object's own colour where it covers something
_NO_LINK = -1
_FAR = 1e9


@dataclass(frozen=True)
class Camera:
    """An orthographic camera looking along ``direction`` (from the viewer into the scene),
    ``up`` toward the image top, the image centred on ``center_mm`` and ``width_mm`` wide."""

    direction: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    center_mm: tuple[float, float, float] = (20.0, -5.0, 85.0)
    width_mm: float = 200.0

    def fitted(self, points_mm: NDArray, radii_mm: NDArray | None = None, margin_mm: float = 4.0) -> Camera:
        """The same view, centred on and just wide enough for spheres at ``points_mm`` (n, 3)
        of ``radii_mm`` (n,; 0 if None) plus ``margin_mm`` on every side."""
        basis = self.basis()
        pts = np.asarray(points_mm, dtype=float).reshape(-1, 3)
        r = np.zeros(len(pts)) if radii_mm is None else np.asarray(radii_mm, dtype=float)
        uv = pts @ basis[:2].T
        lo, hi = (uv - r[:, None]).min(axis=0), (uv + r[:, None]).max(axis=0)
        mid = 0.5 * (lo + hi)
        center = mid[0] * basis[0] + mid[1] * basis[1] + float(np.mean(pts @ basis[2])) * basis[2]
        return Camera(self.direction, self.up, tuple(center), float(max(hi - lo)) + 2.0 * margin_mm)

    def basis(self) -> NDArray:
        """Rows: image right, image up, viewing direction (unit vectors, palm frame)."""
        forward = np.asarray(self.direction, dtype=float)
        forward = forward / np.linalg.norm(forward)
        right = np.cross(forward, np.asarray(self.up, dtype=float))
        right = right / np.linalg.norm(right)
        return np.array([right, np.cross(right, forward), forward])


#: The palm seen from in front, a little from the little-finger side and from below, fingers
#: up: a right hand with its thumb to the image right, as one sees one's own right hand held
#: up with the palm toward the face. Flexing fingers come toward the viewer. The figures fit
#: its centre and width to what they show (``Camera.fitted``).
PALM_CAMERA = Camera(direction=(-1.0, 0.32, 0.22), center_mm=(10.0, -2.0, 92.0), width_mm=205.0)
#: From above the fingertips with the palm at the bottom and the palm normal up: the tips and
#: the thumb are seen on the object side by side, and which way each pushes it.
ABOVE_CAMERA = Camera(direction=(-0.45, 0.3, -1.0), up=(1.0, 0.0, 0.0))


@dataclass(frozen=True)
class ShapeInPicture:
    """A shape (``synergrasp.simulation.shapes``) at its centre (mm, palm frame) and 3 × 3
    rotation (own frame to palm frame)."""

    shape: Any
    center_mm: NDArray
    rotation: NDArray

    def extent(self) -> tuple[NDArray, NDArray]:
        """Points (k, 3) and radii (k,) whose spheres cover it (``Shape.extent``)."""
        return self.shape.extent(np.asarray(self.rotation, dtype=float), np.asarray(self.center_mm, dtype=float))


@dataclass(frozen=True)
class HandShapes:
    """The hand's shapes at a posture, palm frame, mm: ``ends`` (n, 2, 3) capsule axis end
    points, ``radius`` (n,), ``link`` (n,) hand link of each capsule, ``boxes`` the palm's
    boxes (hand link 0)."""

    ends: NDArray
    radius: NDArray
    link: NDArray
    boxes: tuple[ShapeInPicture, ...]

    def extent(self) -> tuple[NDArray, NDArray]:
        """Points (k, 3) and radii (k,) whose spheres cover every shape (for ``Camera.fitted``)."""
        parts = [b.extent() for b in self.boxes]
        points = np.vstack([self.ends.reshape(-1, 3), *[p for p, _ in parts]])
        radii = np.concatenate([np.repeat(self.radius, 2), *[r for _, r in parts]])
        return points, radii


def hand_shapes(hand: Any, q: NDArray) -> HandShapes:
    """The shapes the closure collides (``synergrasp.simulation.capsules.HandCapsules``) at
    joint angles q (rad)."""
    from synergrasp.simulation.capsules import HandCapsules
    from synergrasp.simulation.shapes import Box

    capsules = HandCapsules.of(hand)
    start, end = capsules.segments(np.asarray(q, dtype=float))
    boxes = tuple(
        ShapeInPicture(Box(tuple(2.0 * half)), centre, rotation)
        for rotation, centre, half in zip(capsules.palm_rotation, capsules.palm_centre, capsules.palm_half)
    )
    return HandShapes(
        np.stack([start, end], axis=1),
        np.asarray(capsules.radius, dtype=float),
        np.asarray(capsules.links, dtype=np.int64),
        boxes,
    )


# ------------------------------------------------------------------------------ ray casting


class _Rays:
    """The camera's rays at every (supersampled) pixel: origins on a plane behind the scene."""

    def __init__(self, camera: Camera, width: int, height: int) -> None:
        self.basis = camera.basis()
        self.scale = camera.width_mm / width  # mm per pixel
        self.center = np.asarray(camera.center_mm, dtype=float)
        self.width, self.height = width, height
        self.depth = np.full((height, width), _FAR)
        self.normal = np.zeros((height, width, 3))
        self.label = np.full((height, width), _NO_LINK, dtype=np.int64)

    def to_image(self, points: NDArray) -> NDArray:
        """(n, 2) pixel coordinates (column, row) of palm-frame points."""
        rel = (np.asarray(points, dtype=float).reshape(-1, 3) - self.center) @ self.basis[:2].T / self.scale
        return np.c_[rel[:, 0] + self.width / 2.0, self.height / 2.0 - rel[:, 1]]

    def depth_of(self, points: NDArray) -> NDArray:
        return (np.asarray(points, dtype=float).reshape(-1, 3) - self.center) @ self.basis[2] + 1e4

    def window(self, lo: NDArray, hi: NDArray) -> tuple[slice, slice, NDArray] | None:
        """Pixels whose centres fall in the image rectangle lo..hi (columns, rows), their ray origins."""
        c0, c1 = max(int(np.floor(lo[0])), 0), min(int(np.ceil(hi[0])) + 1, self.width)
        r0, r1 = max(int(np.floor(lo[1])), 0), min(int(np.ceil(hi[1])) + 1, self.height)
        if c0 >= c1 or r0 >= r1:
            return None
        u = (np.arange(c0, c1) + 0.5 - self.width / 2.0) * self.scale
        v = (self.height / 2.0 - np.arange(r0, r1) - 0.5) * self.scale
        origins = self.center - 1e4 * self.basis[2] + u[None, :, None] * self.basis[0] + v[:, None, None] * self.basis[1]
        return slice(r0, r1), slice(c0, c1), origins

    def keep(self, rows: slice, cols: slice, t: NDArray, normal: NDArray, label: int) -> None:
        nearer = t < self.depth[rows, cols]
        self.depth[rows, cols][nearer] = t[nearer]
        self.normal[rows, cols][nearer] = normal[nearer]
        self.label[rows, cols][nearer] = label


def _cast_capsule(rays: _Rays, a: NDArray, b: NDArray, r: float, label: int) -> None:
    """Nearest hit of every ray with the capsule (segment a–b, radius r): the union of a
    finite cylinder and two spheres, so its first hit is the nearest of the pieces' hits."""
    ends = rays.to_image(np.array([a, b]))
    reach = r / rays.scale + 1.0
    win = rays.window(ends.min(axis=0) - reach, ends.max(axis=0) + reach)
    if win is None:
        return
    rows, cols, o = win
    d = rays.basis[2]
    t = np.full(o.shape[:2], _FAR)
    for c in (a, b):  # spheres: |o + t d - c| = r, first root
        oc = o - c
        half_b = oc @ d
        disc = half_b**2 - (np.einsum("ijk,ijk->ij", oc, oc) - r * r)
        hit = disc >= 0.0
        t = np.where(hit, np.minimum(t, -half_b - np.sqrt(np.where(hit, disc, 0.0))), t)
    ba = b - a
    baba, bard = ba @ ba, ba @ d
    oa = o - a
    baoa, rdoa = oa @ ba, oa @ d
    qa = baba - bard * bard
    if qa > 1e-12:  # the cylinder's side (not a ray along its axis)
        qb = baba * rdoa - baoa * bard
        qc = baba * np.einsum("ijk,ijk->ij", oa, oa) - baoa * baoa - r * r * baba
        disc = qb * qb - qa * qc
        hit = disc >= 0.0
        tc = (-qb - np.sqrt(np.where(hit, disc, 0.0))) / qa
        y = baoa + tc * bard
        side = hit & (y > 0.0) & (y < baba)
        t = np.where(side, np.minimum(t, tc), t)
    p = o + t[..., None] * d
    s = np.clip(((p - a) @ ba) / max(baba, 1e-12), 0.0, 1.0)
    normal = (p - (a + s[..., None] * ba)) / r
    rays.keep(rows, cols, t, normal, label)


def _cast_shape(rays: _Rays, obj: ShapeInPicture, label: int) -> NDArray | None:
    """Nearest hit of every ray with a shape (``Shape.ray_hits``); returns the face index hit
    at each pixel of the window (-1: missed), or None when the shape is out of the image."""
    points, radii = obj.extent()
    px, reach = rays.to_image(points), radii[:, None] / rays.scale + 1.0
    win = rays.window((px - reach).min(axis=0), (px + reach).max(axis=0))
    if win is None:
        return None
    rows, cols, o = win
    rot = np.asarray(obj.rotation, dtype=float)
    t, normal, face = obj.shape.ray_hits((o - obj.center_mm) @ rot, rays.basis[2] @ rot)  # in its own frame
    rays.keep(rows, cols, np.where(face >= 0, t, _FAR), normal @ rot.T, label)
    full = np.full((rays.height, rays.width), -1, dtype=np.int64)
    full[rows, cols] = face
    return full


def _cast_hand(rays: _Rays, caps: HandShapes) -> None:
    for box in caps.boxes:
        _cast_shape(rays, box, 0)
    for (a, b), r, link in zip(caps.ends, caps.radius, caps.link):
        _cast_capsule(rays, a, b, float(r), int(link))


# ------------------------------------------------------------------------------ shading


def _shade(colour: NDArray, normal: NDArray, basis: NDArray) -> NDArray:
    """Ambient + diffuse + specular light from the viewer's upper left (colour (..., 3))."""
    light = -basis[2] + 0.55 * basis[1] - 0.35 * basis[0]
    light = light / np.linalg.norm(light)
    halfway = light - basis[2]
    halfway = halfway / np.linalg.norm(halfway)
    diffuse = np.clip(normal @ light, 0.0, 1.0)[..., None]
    specular = np.clip(normal @ halfway, 0.0, 1.0)[..., None] ** 24
    return np.clip(colour * (0.50 + 0.55 * diffuse) + 0.18 * specular, 0.0, 1.0)


def _edges(labels: NDArray) -> NDArray:
    """Pixels whose label differs from a 4-neighbour's."""
    edge = np.zeros(labels.shape, dtype=bool)
    dx = labels[:, 1:] != labels[:, :-1]
    dy = labels[1:, :] != labels[:-1, :]
    edge[:, 1:] |= dx
    edge[:, :-1] |= dx
    edge[1:, :] |= dy
    edge[:-1, :] |= dy
    return edge


def _downsample(image: NDArray, k: int) -> NDArray:
    h, w = image.shape[0] // k, image.shape[1] // k
    return image.reshape(h, k, w, k, -1).mean(axis=(1, 3))


@dataclass(frozen=True)
class Picture:
    """A rendered picture: ``rgb`` (h, w, 3) in [0, 1]; ``link`` (h, w) the hand link seen at
    each pixel's centre in front of everything but the see-through object (-1: none)."""

    rgb: NDArray
    link: NDArray
    _rays: Any
    _k: int

    def pixels(self, points_mm: NDArray) -> NDArray:
        """(n, 2) image coordinates (column, row; 0 at the top-left corner) of palm-frame points (mm)."""
        return self._rays.to_image(points_mm) / self._k

    def hidden(self, points_mm: NDArray, tolerance_mm: float = 1.5) -> NDArray:
        """(n,) True where a point lies more than ``tolerance_mm`` behind the hand surface seen there."""
        px = np.floor(self._rays.to_image(points_mm)).astype(int)
        h, w = self._rays.depth.shape
        inside = (px[:, 0] >= 0) & (px[:, 0] < w) & (px[:, 1] >= 0) & (px[:, 1] < h)
        seen = np.full(len(px), _FAR)
        seen[inside] = self._rays.depth[px[inside, 1], px[inside, 0]]
        return self._rays.depth_of(points_mm) > seen + tolerance_mm


def render(
    hand: Any,
    q: NDArray,
    camera: Camera,
    size_px: tuple[int, int] = (360, 360),
    shape: ShapeInPicture | None = None,
    touching: Sequence[int] = (),
    ghost_q: NDArray | None = None,
    supersample: int = 2,
) -> Picture:
    """The hand at joint angles q (rad) seen by ``camera``; ``size_px`` = (width, height).

    ``shape`` (the object) is drawn see-through; hand links in ``touching`` (hand link indices) get the
    highlight colour ``TOUCHING``; ``ghost_q`` (rad) is a pale silhouette behind the hand.
    """
    w, h, k = int(size_px[0]) * supersample, int(size_px[1]) * supersample, int(supersample)
    rays = _Rays(camera, w, h)
    _cast_hand(rays, hand_shapes(hand, q))
    basis = rays.basis
    palette = np.tile(np.asarray(SKIN), (hand.n_links, 1))
    for link in touching:
        palette[int(link)] = TOUCHING
    on_hand = rays.label >= 0
    rgb = np.full((h, w, 3), _BACKGROUND)
    rgb[on_hand] = _shade(palette[rays.label[on_hand]], rays.normal[on_hand], basis)
    if ghost_q is not None:
        ghost = _Rays(camera, w, h)
        _cast_hand(ghost, hand_shapes(hand, ghost_q))
        pale = (ghost.label >= 0) & ~on_hand
        rgb[pale] = _GHOST
        rgb[_edges(ghost.label >= 0) & ~on_hand] = 0.72
    rgb[_edges(rays.label)] = _OUTLINE
    if shape is not None:
        cover = _Rays(camera, w, h)
        face = _cast_shape(cover, shape, 0)
        if face is not None:
            front = (face >= 0) & (cover.depth < rays.depth)
            own = _shade(np.asarray(BOX), cover.normal[front], basis)
            rgb[front] = _BOX_OPACITY * own + (1.0 - _BOX_OPACITY) * rgb[front]
            rgb[_edges(face) & ((face >= 0) | (rays.label < 0)) & (cover.depth <= rays.depth)] = (0.12, 0.25, 0.50)
    link = np.where(on_hand, rays.label, _NO_LINK)[k // 2 :: k, k // 2 :: k]
    return Picture(_downsample(rgb, k), link, rays, k)
