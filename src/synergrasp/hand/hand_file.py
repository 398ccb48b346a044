"""Hand files (docs/hand.md): reading and checking.

:func:`read_hand_file` reads the YAML (one loader for the project, duplicate keys refused);
:func:`check_hand_doc` checks its content field by field and returns a :class:`HandSpec`,
the file's values in the units of the model (mm, rad, unit axes, 4 × 4 poses), from which
``synergrasp.hand.kinematics`` builds the frame tree. Every error names the field
(``fingers.index.joints[1].limits_deg``); :func:`load_hand` adds the file. Values far from a
human hand's dimensions are not errors: they are listed in ``HandSpec.warnings``.
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

__all__ = ["FINGERS", "JOINT_NAMES", "PALM_NORMAL", "HandSpec", "FingerSpec", "JointSpec",
           "default_hand_path", "read_hand_file", "check_hand_doc"]

FINGERS: tuple[str, ...] = ("thumb", "index", "middle", "ring", "little")

JOINT_NAMES: tuple[str, ...] = (
    "thumb_abd", "thumb_flex1", "thumb_flex2",
    "index_abd", "index_mcp", "index_pip", "index_dip",
    "middle_abd", "middle_mcp", "middle_pip", "middle_dip",
    "ring_abd", "ring_mcp", "ring_pip", "ring_dip",
    "little_abd", "little_mcp", "little_pip", "little_dip",
)

PALM_NORMAL: NDArray[np.float64] = np.array([1.0, 0.0, 0.0])
"""Unit vector (palm frame) the palm faces: the side toward which every finger flexes."""

#: A human hand is about 190 mm from wrist crease to fingertip and 85 mm wide; a length in a
#: hand file above ``_LONGEST_MM`` (more than a whole hand), or a hand whose every length is
#: below ``_SHORTEST_MM`` (a file in metres?), is far from a hand: warned, not refused.
_LONGEST_MM = 250.0
_SHORTEST_MM = 5.0


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

    def __init__(self) -> None:
        self.warnings: list[str] = []
        self.lengths: list[float] = []  # every length of the file (mm), for the scale check

    def length(self, field: str, value_mm: float) -> None:
        self.lengths.append(value_mm)
        if value_mm > _LONGEST_MM:
            self.warnings.append(f"{field}: {value_mm:.6g} mm is far from a human hand's dimensions "
                                 f"(a hand is about 190 mm long; lengths are in mm)")

    def vector(self, node: dict, key: str, field: str, n: int = 3, mm: bool = False) -> NDArray[np.float64]:
        if key not in node:
            raise _err(f"{field}.{key}", f"missing (a list of {n} numbers)")
        value = node[key]
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise _err(f"{field}.{key}", f"must be a list of {n} numbers, got {value!r}") from None
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise _err(f"{field}.{key}", f"must be a list of {n} finite numbers, got {value!r}")
        if mm:
            self.length(f"{field}.{key}", float(np.max(np.abs(arr))))
        return arr

    def number(self, node: dict, key: str, field: str, minimum: float | None = None, mm: bool = False) -> float:
        if key not in node:
            raise _err(f"{field}.{key}", "missing (a number)")
        value = node[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _err(f"{field}.{key}", f"must be a finite number, got {value!r}")
        if minimum is not None and value < minimum:
            raise _err(f"{field}.{key}", f"must be >= {minimum}, got {value!r}")
        if mm:
            self.length(f"{field}.{key}", abs(float(value)))
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
            a, b = self.vector(spec, "from_mm", f, mm=True), self.vector(spec, "to_mm", f, mm=True)
            radius = self.number(spec, "radius_mm", f, minimum=1e-6, mm=True)
            pose = np.eye(4)
            pose[:3, 3] = 0.5 * (a + b)
            length = float(np.linalg.norm(b - a))
            if length > 0:
                pose[:3, :3] = z_to(b - a)
            return Shape("capsule", pose, radius=radius, length=length)
        size = self.vector(spec, "size_mm", f, mm=True)
        if np.any(size <= 0):
            raise _err(f"{f}.size_mm", f"must be positive, got {size.tolist()}")
        center = self.vector(spec, "center_mm", f, mm=True)
        rpy = self.vector(spec, "rpy_rad", f) if "rpy_rad" in spec else np.zeros(3)
        return Shape("box", pose_matrix(center, rpy), size=size)

    def shapes(self, node: dict, field: str) -> tuple[Shape, ...]:
        shapes = node.get("shapes", [])
        if not isinstance(shapes, list):
            raise _err(f"{field}.shapes", "must be a list of {capsule: ...} or {box: ...}")
        return tuple(self.shape(s, f"{field}.shapes[{i}]") for i, s in enumerate(shapes))

    def joint(self, node: Any, field: str, finger: str, index: int, links: set[str],
              knuckle: NDArray) -> JointSpec:
        jnode = self.mapping(node, field, "joint")
        name = jnode.get("name")
        if index >= len(JOINT_NAMES) or name != JOINT_NAMES[index]:
            expected = JOINT_NAMES[index] if index < len(JOINT_NAMES) else "(no more joints: 19 in all)"
            raise _err(f"{field}.name", f"must be {expected!r} (joint order of docs/design.md), got {name!r}")
        axis = self.vector(jnode, "axis", field)
        if np.linalg.norm(axis) < 1e-9:
            raise _err(f"{field}.axis", "must be a non-zero vector")
        rpy = self.vector(jnode, "rpy_rad", field) if "rpy_rad" in jnode else np.zeros(3)
        offset = knuckle @ pose_matrix(self.vector(jnode, "offset_mm", field, mm=True), rpy)
        gap = (self.number(jnode, "rolling_gap_mm", field, minimum=0.0, mm=True)
               if "rolling_gap_mm" in jnode else 0.0)
        lim = jnode.get("limits_deg")
        if (not isinstance(lim, list) or len(lim) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in lim)
                or not lim[0] < lim[1]):
            raise _err(f"{field}.limits_deg", f"must be [lower, upper] in degrees with lower < upper, got {lim!r}")
        link = jnode.get("link")
        if not isinstance(link, str) or not link.startswith(f"{finger}_") or link in links:
            raise _err(f"{field}.link", f"must be a new link name starting with '{finger}_', got {link!r}")
        links.add(link)
        return JointSpec(name, axis / np.linalg.norm(axis), offset, gap, math.radians(lim[0]),
                         math.radians(lim[1]), link, self.shapes(jnode, field))

    def finger(self, node: Any, finger: str, first_joint: int, links: set[str]) -> FingerSpec:
        ff = f"fingers.{finger}"
        fnode = self.mapping(node, ff, "finger")
        knuckle = self.mapping(fnode.get("knuckle"), f"{ff}.knuckle", "knuckle")
        knuckle_pose = pose_matrix(self.vector(knuckle, "xyz_mm", f"{ff}.knuckle", mm=True),
                                   self.vector(knuckle, "rpy_rad", f"{ff}.knuckle"))
        tip = self.vector(fnode, "tip_mm", ff, mm=True)
        joints = fnode.get("joints")
        if not isinstance(joints, list) or not joints:
            raise _err(f"{ff}.joints", "must be a non-empty list of joints")
        out = []
        for i, jnode in enumerate(joints):  # the knuckle pose is folded into the first joint's offset
            out.append(self.joint(jnode, f"{ff}.joints[{i}]", finger, first_joint + i, links,
                                  knuckle_pose if i == 0 else np.eye(4)))
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
    if check.lengths and max(check.lengths) < _SHORTEST_MM:
        check.warnings.append(f"<top level>: no length of the hand exceeds {max(check.lengths):.3g} mm, far "
                              "from a human hand's dimensions (about 190 mm long); lengths are in mm, not m")
    return HandSpec(str(doc.get("name", "hand")), palm_normal, palm_shapes, tuple(specs), tuple(check.warnings))
