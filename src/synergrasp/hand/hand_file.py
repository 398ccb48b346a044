"""Hand files (docs/hand.md): reading and checking.

:func:`read_hand_file` reads the YAML (one loader for the project, duplicate keys refused);
:func:`check_hand_doc` checks its content field by field and returns a :class:`HandSpec`,
the file's values in the units of the model (mm, rad, unit axes, 4 × 4 poses), from which
``synergrasp.hand.kinematics`` builds the frame tree. Every error names the field
(``fingers.index.joints[1].limits_deg``); :func:`load_hand` adds the file. Values far from a
human hand's dimensions are not errors: :func:`size_warnings` lists them, for a hand of any
format (the front door ``synergrasp.hand.description.hand_spec`` puts them in
``HandSpec.warnings``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.geometry import SHAPE_KINDS, Shape, pose_matrix, z_to
from synergrasp.yaml_io import read_yaml

__all__ = [
    "FINGERS",
    "JOINT_NAMES",
    "PALM_NORMAL",
    "HandSpec",
    "FingerSpec",
    "JointSpec",
    "default_hand_path",
    "read_hand_file",
    "check_hand_doc",
    "size_warnings",
]

FINGERS: tuple[str, ...] = ("thumb", "index", "middle", "ring", "little")

JOINT_NAMES: tuple[str, ...] = (
    "thumb_abd",
    "thumb_flex1",
    "thumb_flex2",
    "index_abd",
    "index_mcp",
    "index_pip",
    "index_dip",
    "middle_abd",
    "middle_mcp",
    "middle_pip",
    "middle_dip",
    "ring_abd",
    "ring_mcp",
    "ring_pip",
    "ring_dip",
    "little_abd",
    "little_mcp",
    "little_pip",
    "little_dip",
)

PALM_NORMAL: NDArray[np.float64] = np.array([1.0, 0.0, 0.0])
"""Unit vector (palm frame) the palm faces: the side toward which every finger flexes."""

#: A human hand is about 190 mm from wrist crease to fingertip and 85 mm wide; a length of a
#: hand above ``_LONGEST_MM`` (more than a whole hand), a fingertip farther than ``_REACH_MM``
#: from the palm frame's origin (about two hands), or a hand whose every length is below
#: ``_SHORTEST_MM`` (a file in the wrong unit?), is far from a hand: warned, not refused.
_LONGEST_MM = 250.0
_REACH_MM = 400.0
_SHORTEST_MM = 5.0
#: More lengths than this above ``_LONGEST_MM``: one line for the whole hand (a unit mistake).
_MANY = 3


@dataclass(frozen=True)
class JointSpec:
    """One joint of a finger as checked: ``offset`` (4 × 4, mm) places its (first) axis in
    the previous link's frame (the knuckle pose folded into a finger's first joint)."""

    name: str
    axis: NDArray[np.float64]  # unit
    offset: NDArray[np.float64]
    rolling_gap_mm: float
    lower_rad: float
    upper_rad: float
    link: str
    shapes: tuple[Shape, ...]
    #: the axis turns by ``scale`` × q (a plain joint; a reversed joint: −1); with ``follows``
    #: (the name of an earlier joint of its finger) the joint has no coordinate of its own
    #: and turns by ``scale`` × that joint's q (a coupled joint, e.g. a tendon-coupled distal)
    scale: float = 1.0
    follows: str = ""


@dataclass(frozen=True)
class FingerSpec:
    name: str
    tip_mm: NDArray[np.float64]
    joints: tuple[JointSpec, ...]


@dataclass(frozen=True)
class HandSpec:
    """A checked hand file: name, palm normal, palm shapes, fingers in FINGERS order, and
    the warnings on dimensions far from a human hand's (one line each, naming the field)."""

    name: str
    palm_normal: NDArray[np.float64]
    palm_shapes: tuple[Shape, ...]
    fingers: tuple[FingerSpec, ...]
    warnings: tuple[str, ...] = ()
    #: whether a finger link may have no shape (a body that only carries a joint, read from
    #: MJCF; a YAML hand file gives every link its capsule)
    shapeless_links: bool = False
    #: pairs of link names that are not self-contacts besides parent/child pairs (an MJCF
    #: model's contact exclusions)
    ignored_pairs: tuple[tuple[str, str], ...] = ()


# --------------------------------------------------------------------------- reading


def default_hand_path() -> Path:
    """Path of the shipped SoftHand-like model."""
    return Path(str(resources.files("synergrasp") / "data" / "hand.yaml"))


def read_hand_file(path: str | Path) -> Any:
    """The parsed content of a hand file; ValueError naming the file if it cannot be read,
    is not valid YAML, repeats a key or is empty."""
    doc = read_yaml(path, "hand file")
    if doc is None:
        raise ValueError(f"hand file '{path}': is empty; the format is in docs/hand.md")
    return doc


# --------------------------------------------------------------------------- checking


def _err(field: str, message: str) -> ValueError:
    return ValueError(f"hand file: {field}: {message}")


class _Checker:
    """Checks a parsed hand file field by field, collecting warnings on its way."""

    #: The keys allowed at each level of a hand file (a misspelt optional key is an error).
    KEYS: dict[str, tuple[str, ...]] = {
        "<top level>": ("name", "palm_normal", "palm", "fingers"),
        "palm": ("shapes",),
        "finger": ("knuckle", "tip_mm", "joints"),
        "knuckle": ("xyz_mm", "rpy_rad"),
        "joint": ("name", "offset_mm", "rpy_rad", "axis", "rolling_gap_mm", "limits_deg", "link", "shapes"),
        "capsule": ("from_mm", "to_mm", "radius_mm"),
        "box": ("center_mm", "size_mm", "rpy_rad"),
    }

    def vector(self, node: dict, key: str, field: str, n: int = 3) -> NDArray[np.float64]:
        if key not in node:
            raise _err(f"{field}.{key}", f"missing (a list of {n} numbers)")
        value = node[key]
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise _err(f"{field}.{key}", f"must be a list of {n} numbers, got {value!r}") from None
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise _err(f"{field}.{key}", f"must be a list of {n} finite numbers, got {value!r}")
        return arr

    def number(self, node: dict, key: str, field: str, minimum: float | None = None) -> float:
        if key not in node:
            raise _err(f"{field}.{key}", "missing (a number)")
        value = node[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _err(f"{field}.{key}", f"must be a finite number, got {value!r}")
        if minimum is not None and value < minimum:
            raise _err(f"{field}.{key}", f"must be >= {minimum}, got {value!r}")
        return float(value)

    def mapping(self, node: Any, field: str, kind: str | None = None) -> dict:
        if not isinstance(node, dict):
            raise _err(field, f"must be a mapping, got {type(node).__name__}")
        allowed = self.KEYS.get(kind or "", None)
        unknown = [k for k in node if k not in allowed] if allowed else []
        if unknown:
            raise _err(field, f"unknown key(s) {unknown}; allowed keys: {list(allowed)}")
        return node

    def shape(self, node: Any, field: str) -> Shape:
        node = self.mapping(node, field)
        if len(node) != 1 or next(iter(node)) not in SHAPE_KINDS:
            raise _err(field, f"must be a single key, one of {SHAPE_KINDS}, got {list(node)}")
        kind = next(iter(node))
        f = f"{field}.{kind}"
        spec = self.mapping(node[kind], f, kind)
        if kind == "capsule":
            a, b = self.vector(spec, "from_mm", f), self.vector(spec, "to_mm", f)
            radius = self.number(spec, "radius_mm", f, minimum=1e-6)
            pose = np.eye(4)
            pose[:3, 3] = 0.5 * (a + b)
            length = float(np.linalg.norm(b - a))
            if length > 0:
                pose[:3, :3] = z_to(b - a)
            return Shape("capsule", pose, radius=radius, length=length)
        size = self.vector(spec, "size_mm", f)
        if np.any(size <= 0):
            raise _err(f"{f}.size_mm", f"must be positive, got {size.tolist()}")
        center = self.vector(spec, "center_mm", f)
        rpy = self.vector(spec, "rpy_rad", f) if "rpy_rad" in spec else np.zeros(3)
        return Shape("box", pose_matrix(center, rpy), size=size)

    def shapes(self, node: dict, field: str) -> tuple[Shape, ...]:
        shapes = node.get("shapes", [])
        if not isinstance(shapes, list):
            raise _err(f"{field}.shapes", "must be a list of {capsule: ...} or {box: ...}")
        return tuple(self.shape(s, f"{field}.shapes[{i}]") for i, s in enumerate(shapes))

    def joint(self, node: Any, field: str, finger: str, index: int, links: set[str], knuckle: NDArray) -> JointSpec:
        jnode = self.mapping(node, field, "joint")
        name = jnode.get("name")
        if index >= len(JOINT_NAMES) or name != JOINT_NAMES[index]:
            expected = JOINT_NAMES[index] if index < len(JOINT_NAMES) else "(no more joints: 19 in all)"
            raise _err(f"{field}.name", f"must be {expected!r} (joint order of docs/design.md), got {name!r}")
        axis = self.vector(jnode, "axis", field)
        if np.linalg.norm(axis) < 1e-9:
            raise _err(f"{field}.axis", "must be a non-zero vector")
        rpy = self.vector(jnode, "rpy_rad", field) if "rpy_rad" in jnode else np.zeros(3)
        offset = knuckle @ pose_matrix(self.vector(jnode, "offset_mm", field), rpy)
        gap = self.number(jnode, "rolling_gap_mm", field, minimum=0.0) if "rolling_gap_mm" in jnode else 0.0
        lim = jnode.get("limits_deg")
        if (
            not isinstance(lim, list)
            or len(lim) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in lim)
            or not lim[0] < lim[1]
        ):
            raise _err(f"{field}.limits_deg", f"must be [lower, upper] in degrees with lower < upper, got {lim!r}")
        link = jnode.get("link")
        if not isinstance(link, str) or not link.startswith(f"{finger}_") or link in links:
            raise _err(f"{field}.link", f"must be a new link name starting with '{finger}_', got {link!r}")
        links.add(link)
        return JointSpec(
            name,
            axis / np.linalg.norm(axis),
            offset,
            gap,
            math.radians(lim[0]),
            math.radians(lim[1]),
            link,
            self.shapes(jnode, field),
        )

    def finger(self, node: Any, finger: str, first_joint: int, links: set[str]) -> FingerSpec:
        ff = f"fingers.{finger}"
        fnode = self.mapping(node, ff, "finger")
        knuckle = self.mapping(fnode.get("knuckle"), f"{ff}.knuckle", "knuckle")
        knuckle_pose = pose_matrix(
            self.vector(knuckle, "xyz_mm", f"{ff}.knuckle"), self.vector(knuckle, "rpy_rad", f"{ff}.knuckle")
        )
        tip = self.vector(fnode, "tip_mm", ff)
        joints = fnode.get("joints")
        if not isinstance(joints, list) or not joints:
            raise _err(f"{ff}.joints", "must be a non-empty list of joints")
        out = []
        for i, jnode in enumerate(joints):  # the knuckle pose is folded into the first joint's offset
            out.append(
                self.joint(jnode, f"{ff}.joints[{i}]", finger, first_joint + i, links, knuckle_pose if i == 0 else np.eye(4))
            )
        return FingerSpec(finger, tip, tuple(out))


def check_hand_doc(doc: Any) -> HandSpec:
    """The checked content of a hand file (see docs/hand.md); ValueError naming the field
    (``hand file: <field>: <what is wrong>``) at the first problem."""
    check = _Checker()
    doc = check.mapping(doc, "<top level>", "<top level>")
    for key in ("palm", "fingers"):
        if key not in doc:
            raise _err(key, "missing")
    palm_normal = check.vector(doc, "palm_normal", "<top level>") if "palm_normal" in doc else PALM_NORMAL.copy()
    if not np.isclose(np.linalg.norm(palm_normal), 1.0, atol=1e-6):
        raise _err("palm_normal", f"must be a unit vector, got {palm_normal.tolist()}")
    fingers = check.mapping(doc["fingers"], "fingers")
    if sorted(fingers) != sorted(FINGERS):
        raise _err("fingers", f"must have exactly the keys {FINGERS}, got {tuple(fingers)}")
    palm_shapes = check.shapes(check.mapping(doc["palm"], "palm", "palm"), "palm")
    specs: list[FingerSpec] = []
    links: set[str] = {"palm"}
    for finger in FINGERS:
        specs.append(check.finger(fingers[finger], finger, sum(len(f.joints) for f in specs), links))
    names = tuple(j.name for f in specs for j in f.joints)
    if names != JOINT_NAMES:
        raise _err("fingers", f"joints must be exactly {JOINT_NAMES}, got {names}")
    return HandSpec(str(doc.get("name", "hand")), palm_normal, palm_shapes, tuple(specs))


# --------------------------------------------------------------------------- sizes


def _shape_mm(shape: Shape) -> float:
    """A shape's largest dimension or distance from its link frame's origin (mm)."""
    extent = 2.0 * shape.radius + shape.length if shape.kind == "capsule" else float(np.max(shape.size))
    return max(extent, float(np.linalg.norm(shape.pose[:3, 3])))


def _lengths(spec: HandSpec) -> list[tuple[str, float]]:
    """(field, mm) of every length of a hand: its shapes, each joint's offset from the previous
    joint (the first's from the palm frame) and each fingertip, named by the description's fields."""
    out = [(f"palm.shapes[{k}]", _shape_mm(shape)) for k, shape in enumerate(spec.palm_shapes)]
    for finger in spec.fingers:
        for i, joint in enumerate(finger.joints):
            field = f"fingers.{finger.name}.joints[{i}]"
            out.append((f"{field} ({joint.name}) offset", float(np.linalg.norm(joint.offset[:3, 3]))))
            out += [(f"{field}.shapes[{k}]", _shape_mm(shape)) for k, shape in enumerate(joint.shapes)]
        out.append((f"fingers.{finger.name} tip", float(np.linalg.norm(finger.tip_mm))))
    return out


def _reach_mm(finger: FingerSpec) -> float:
    """Distance (mm) of a fingertip from the palm frame's origin with every joint at zero."""
    pose = np.eye(4)
    for joint in finger.joints:
        pose = pose @ joint.offset
    return float(np.linalg.norm(pose[:3, :3] @ finger.tip_mm + pose[:3, 3]))


def size_warnings(spec: HandSpec, unit: str = "mm") -> tuple[str, ...]:
    """The warnings on a hand's dimensions far from a human hand's (about 190 mm long), one
    line each naming the field, the same for every format: each length above 250 mm (more
    than three: one line for the whole hand), else a fingertip farther than 400 mm from the
    palm frame's origin at the zero posture; or no length above 5 mm. ``unit``: the unit the
    hand's source gives lengths in (``mm``: a hand file; ``m``: an MJCF or URDF model), named
    in the advice."""
    lengths = _lengths(spec)
    other = {"mm": "m", "m": "mm"}[unit]
    advice = f"lengths are in {unit}, not {other}"
    big = [(field, value) for field, value in lengths if value > _LONGEST_MM]
    far = "far from a human hand's dimensions (a hand is about 190 mm long)"
    if len(big) > _MANY:
        field, value = max(big, key=lambda item: item[1])
        return (
            f"<top level>: {len(big)} of the hand's {len(lengths)} lengths exceed {_LONGEST_MM:g} mm, up to "
            f"{value:.6g} mm ({field}), {far}; {advice}",
        )
    if big:
        return tuple(f"{field}: {value:.6g} mm is {far}; lengths are in {unit}" for field, value in big)
    reach = [(f"fingers.{f.name}", _reach_mm(f)) for f in spec.fingers]
    field, value = max(reach, key=lambda item: item[1])
    if value > _REACH_MM:
        return (f"{field}: the fingertip lies {value:.6g} mm from the palm frame's origin at the zero posture, {far}; {advice}",)
    longest = max(value for _, value in lengths)
    if longest < _SHORTEST_MM:
        return (f"<top level>: no length of the hand exceeds {longest:.3g} mm, {far}; {advice}",)
    return ()
