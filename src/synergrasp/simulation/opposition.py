"""Which opposition a grasp makes, from its contacts alone (docs/opposition.md).

Iberall's opposition space, on which Cutkosky's and Feix's grasp taxonomies rest, names
the pairs of hand surfaces that squeeze an object between them. A grasp is classified by
the first of these that its contacts make (the rule, with its angle, is written down in
docs/opposition.md and tested on hand-made grasps in tests/test_opposition.py):

``palm``  palm opposition (a power grasp): a contact on the palm side of the hand (the
          palm, or the links of a long finger below its middle phalanx) pushes the object
          off the palm, within ``angle_deg`` of the palm normal, **and** a contact on a
          finger or the thumb pushes it back toward the palm, within ``angle_deg`` of the
          palm normal's reverse.
``pad``   pad opposition (a precision grip): no contact on the palm; the thumb's distal
          link and the distal link of a long finger push within ``angle_deg`` of opposite
          directions.
``side``  side opposition (a lateral pinch): no contact on the palm; the thumb's distal link
          and a non-distal link of the index push within ``angle_deg`` of opposite
          directions, the index's push running across the palm (within ``angle_deg`` of the
          lateral axis).
``none``  no two contact groups push against each other by these rules.

A contact's push is the object's inward unit normal at it (the direction a pushing contact
moves the object). The hand's axes: the palm normal p (``Hand.palm_normal``), the finger
axis u (from the palm's centre toward the long fingers' first joints, made normal to p)
and the lateral axis v = p × u. Pure numpy: nothing is simulated here.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = [
    "OPPOSITIONS",
    "GRASP_TYPES",
    "LINK_KINDS",
    "FACE_CLASSES",
    "SURFACE_FEATURES",
    "OppositionRule",
    "HandAxes",
    "classify_grasp",
    "contacts_oppositions",
    "edge_contacts",
    "of_grasp_type",
    "face_classes",
    "surface_features",
]

#: The classes, in the order the rule tries them.
OPPOSITIONS: tuple[str, ...] = ("palm", "pad", "side", "none")
#: An object's grasp type (config ``objects.<name>.grasp_type``) and the oppositions that are
#: of that type: Cutkosky's power grasps hold the object against the palm, his precision
#: grips between the thumb's and the fingers' pads; ``any`` accepts every opposition.
GRASP_TYPES: dict[str, tuple[str, ...]] = {"power": ("palm",), "precision": ("pad",), "any": ("palm", "pad", "side")}
#: What a hand link is for the rule (HandAxes.link_kind).
LINK_KINDS: tuple[str, ...] = ("palm", "palm_side", "finger_middle", "finger_pad", "thumb_pad", "thumb_base")
#: The box face a contact pushes on, by the dominant axis of its push: the face toward the palm
#: (push along +p), the outer face (push along -p), a side face (push across the palm, along
#: ±v), an end face (push along the fingers, ±u).
FACE_CLASSES: tuple[str, ...] = ("palm_face", "outer_face", "side_face", "end_face")
#: Where on the object's surface a contact sits: on one face, on an edge (two faces within
#: reach), on a corner (three or more).
SURFACE_FEATURES: tuple[str, ...] = ("face", "edge", "corner")


@dataclass(frozen=True)
class OppositionRule:
    """The rule's one number (config ``opposition``): two pushes oppose when they lie within
    ``angle_deg`` of opposite directions; a push is along an axis when within ``angle_deg`` of
    it (deg, 0 < angle < 90). ``reach_mm``: faces within this distance of a contact point
    count at it (edges and corners; mm)."""

    angle_deg: float
    reach_mm: float

    def __post_init__(self) -> None:
        if not 0.0 < float(self.angle_deg) < 90.0:
            raise ValueError(f"opposition.angle_deg must lie in (0, 90), got {self.angle_deg!r}")
        if not float(self.reach_mm) >= 0.0:
            raise ValueError(f"opposition.reach_mm must be >= 0, got {self.reach_mm!r}")

    @property
    def cos(self) -> float:
        return math.cos(math.radians(float(self.angle_deg)))

    @classmethod
    def from_config(cls, config: Mapping[str, Any]) -> OppositionRule:
        """From a configuration (defaults: the schema's) or a step's part of it."""
        spec = config["opposition"]
        return cls(float(spec["angle_deg"]), float(spec["reach_mm"]))


@dataclass(frozen=True)
class HandAxes:
    """The hand's axes (unit, palm frame) and each link's kind for the rule (LINK_KINDS)."""

    palm_normal: NDArray[np.float64]
    finger_axis: NDArray[np.float64]
    lateral_axis: NDArray[np.float64]
    link_kind: tuple[str, ...]
    index_links: frozenset[int]

    @classmethod
    def from_hand(cls, hand: Hand) -> HandAxes:
        """From a hand model: a long finger's last link is its pad, the link before it its
        middle phalanx, every earlier one palm side; the thumb's last link is its pad."""
        from synergrasp.hand.kinematics import forward_kinematics

        p = np.asarray(hand.palm_normal, dtype=float)
        p = p / np.linalg.norm(p)
        frames = forward_kinematics(hand, np.zeros(hand.n_joints))
        names = [hand.link_finger[chain[0]] for chain in hand.finger_links]
        kind = ["palm"] * hand.n_links
        bases = []
        for name, chain in zip(names, hand.finger_links):
            for k, link in enumerate(chain):
                last = k == len(chain) - 1
                if name == "thumb":
                    kind[link] = "thumb_pad" if last else "thumb_base"
                else:
                    kind[link] = "finger_pad" if last else "finger_middle" if k == len(chain) - 2 else "palm_side"
            if name != "thumb":
                bases.append(frames[chain[0], :3, 3])
        palm = np.mean([s.pose[:3, 3] for s in hand.link_shapes[0]], axis=0) if hand.link_shapes[0] else np.zeros(3)
        u = np.mean(bases, axis=0) - palm
        u = u - (u @ p) * p
        u = u / np.linalg.norm(u)
        index = frozenset(int(i) for name, chain in zip(names, hand.finger_links) if name == "index" for i in chain)
        return cls(p, u, np.cross(p, u), tuple(kind), index)


def _kinds(axes: HandAxes, links: Sequence[int]) -> list[str]:
    return [axes.link_kind[int(i)] for i in links]


def _opposed(a: NDArray, b: NDArray, cos: float) -> bool:
    """Some push of ``a`` (k, 3) and some push of ``b`` (l, 3) within the angle of opposite."""
    return bool(len(a) and len(b) and (a @ b.T <= -cos + 1e-12).any())


def classify_grasp(links: Sequence[int], normals: NDArray, axes: HandAxes, rule: OppositionRule) -> str:
    """The opposition (OPPOSITIONS) of one grasp: its contacts' hand links and the object's
    inward unit normals at them ((m, 3), palm frame)."""
    n = np.asarray(normals, dtype=float).reshape(-1, 3)
    kinds = np.array(_kinds(axes, links), dtype=object)
    if len(kinds) < 2:
        return "none"
    c = rule.cos - 1e-12
    along_p = n @ axes.palm_normal
    palm_side = np.isin(kinds, ("palm", "palm_side"))
    if (palm_side & (along_p >= c)).any() and (~(kinds == "palm") & (along_p <= -c)).any():
        return "palm"
    if (kinds == "palm").any():
        return "none"
    thumb = n[kinds == "thumb_pad"]
    if _opposed(thumb, n[kinds == "finger_pad"], rule.cos):
        return "pad"
    side = np.array([int(i) in axes.index_links for i in links]) & (kinds != "finger_pad")
    side &= np.abs(n @ axes.lateral_axis) >= c
    if _opposed(thumb, n[side], rule.cos):
        return "side"
    return "none"


def contacts_oppositions(contacts: Any, axes: HandAxes, rule: OppositionRule) -> list[str]:
    """The opposition of every row of a contacts table (``table_contracts.CONTACTS``: contact_link,
    contact_normal); a row that is no grasp (status other than ``grasp``) makes none."""
    out = []
    for status, links, normals in zip(contacts["status"], contacts["contact_link"], contacts["contact_normal"]):
        out.append(classify_grasp(links, np.asarray(normals), axes, rule) if status == "grasp" else "none")
    return out


def edge_contacts(contacts: Any, shape: Any, rule: OppositionRule) -> list[int]:
    """Per row of a contacts table, how many of its contacts sit on an edge or a corner of
    the placed shape (``surface_features``)."""
    out = []
    for m, points, rotation, center in zip(
        contacts["n_contacts"], contacts["contact_point"], contacts["object_rotation"], contacts["object_center"]
    ):
        if int(m) == 0:
            out.append(0)
            continue
        features = surface_features(np.asarray(points), shape, np.asarray(rotation), np.asarray(center), rule)
        out.append(sum(f != "face" for f in features))
    return out


def of_grasp_type(opposition: str, grasp_type: str) -> bool:
    """Whether an opposition is of an object's grasp type (GRASP_TYPES)."""
    if grasp_type not in GRASP_TYPES:
        raise ValueError(f"grasp_type must be one of {sorted(GRASP_TYPES)}, got {grasp_type!r}")
    return opposition in GRASP_TYPES[grasp_type]


def face_classes(normals: NDArray, axes: HandAxes) -> list[str]:
    """Per contact, the face it pushes on (FACE_CLASSES) by the dominant axis of its push."""
    n = np.asarray(normals, dtype=float).reshape(-1, 3)
    parts = np.abs(np.stack([n @ axes.palm_normal, n @ axes.lateral_axis, n @ axes.finger_axis], axis=1))
    dominant = np.argmax(parts, axis=1)
    out = []
    for k, d in enumerate(dominant):
        if d == 0:
            out.append("palm_face" if n[k] @ axes.palm_normal > 0 else "outer_face")
        else:
            out.append("side_face" if d == 1 else "end_face")
    return out


def surface_features(points: NDArray, shape: Any, rotation: NDArray, center: NDArray, rule: OppositionRule) -> list[str]:
    """Per contact point ((m, 3) mm, palm frame) on a placed shape, where it sits
    (SURFACE_FEATURES): how many of the shape's faces lie within ``rule.reach_mm``."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    R, c = np.asarray(rotation, dtype=float).reshape(3, 3), np.asarray(center, dtype=float)
    count = [len(shape.normals_near(p, R, c, rule.reach_mm)) for p in pts]
    return [SURFACE_FEATURES[min(max(k, 1), 3) - 1] for k in count]
