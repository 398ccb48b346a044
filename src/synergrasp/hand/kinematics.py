"""The 19-joint anthropomorphic hand: model, forward kinematics, point Jacobians, URDF.

The shipped model (``data/hand.yaml``) has the kinematics of the Pisa/IIT SoftHand with all
19 joints independent (docs/hand.md). Everything here is pure numpy: lengths in mm, angles
in rad, every geometric quantity in the palm frame (docs/design.md).

Kinematic tree. Each joint of the hand is made of one or two elementary revolute axes
("frames"): an abduction joint is one axis, a rolling flexion joint is two parallel axes
``rolling_gap_mm`` apart, each turning by half of the joint angle. Frame 0 is the palm; frame
``f`` sits on its axis, at ``T[parent[f]] @ offset[f] @ Rot(axis[f], scale[f] * q[joint[f]])``.
A hand link (``palm``, ``index_proximal``, ...) is rigidly attached to one frame: the last
axis of the joint that moves it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

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

FINGERTIP_LINKS: tuple[str, ...] = (
    "thumb_distal", "index_distal", "middle_distal", "ring_distal", "little_distal",
)
"""Last link of each finger chain, in FINGERS order (shipped model)."""

SHAPE_KINDS = ("capsule", "box")


@dataclass(frozen=True)
class Shape:
    """One collision shape of a link.

    ``pose`` (4 × 4, mm) places the shape in its link frame. A capsule lies along the
    pose's local z axis: ``length`` mm between the centres of its two end spheres of
    ``radius`` mm. A box is centred on the pose with full edge lengths ``size`` (mm).
    """

    kind: str
    pose: NDArray[np.float64]
    radius: float = 0.0
    length: float = 0.0
    size: NDArray[np.float64] | None = None


@dataclass(frozen=True)
class Hand:
    """A hand model (see the module docstring for the frame tree).

    Joints follow ``JOINT_NAMES``; links are ``palm`` then ``<finger>_<segment>``.
    """

    name: str
    joint_names: tuple[str, ...]
    lower: NDArray[np.float64]            # (19,) rad
    upper: NDArray[np.float64]            # (19,) rad
    link_names: tuple[str, ...]
    link_finger: tuple[str, ...]          # finger of each link, 'palm' for the palm
    link_frame: NDArray[np.int64]         # frame each link is attached to
    link_parent: NDArray[np.int64]        # parent link, -1 for the palm
    link_parent_joint: NDArray[np.int64]  # joint (q index) moving the link, -1 for the palm
    link_shapes: tuple[tuple[Shape, ...], ...]
    frame_names: tuple[str, ...]          # frame 0 'palm'; hand links keep their names
    frame_parent: NDArray[np.int64]       # -1 for frame 0
    frame_offset: NDArray[np.float64]     # (n_frames, 4, 4) parent frame -> axis frame, mm
    frame_axis: NDArray[np.float64]       # (n_frames, 3) unit axis in the frame
    frame_joint: NDArray[np.int64]        # q index driving the frame, -1 for the palm
    frame_scale: NDArray[np.float64]      # angle of the axis per unit q (1, or 1/2 for a rolling half)
    frame_joint_names: tuple[str, ...]    # name of the elementary axis ('' for the palm)
    finger_joints: tuple[tuple[int, ...], ...]  # q indices per finger, FINGERS order
    finger_links: tuple[tuple[int, ...], ...]   # link indices per finger, proximal to distal
    fingertip_link: NDArray[np.int64]     # (5,) distal link of each finger
    fingertip_point: NDArray[np.float64]  # (5, 3) fingertip point in its distal link frame, mm
    ignored_link_pairs: tuple[tuple[int, int], ...]  # self-collision pairs to skip (touching by design)
    palm_normal: NDArray[np.float64]

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    @property
    def n_links(self) -> int:
        return len(self.link_names)

    @property
    def flexion_joints(self) -> NDArray[np.bool_]:
        """(n_joints,) True for flexion joints (every joint but the abductions ``*_abd``)."""
        return np.array([not name.endswith("_abd") for name in self.joint_names])

    def link_index(self, name: str) -> int:
        """Index of a link by name; ValueError names the allowed values."""
        try:
            return self.link_names.index(name)
        except ValueError:
            raise ValueError(f"link must be one of {self.link_names}, got {name!r}") from None


# --------------------------------------------------------------------------- geometry helpers


def rpy_matrix(rpy: NDArray | tuple[float, float, float]) -> NDArray[np.float64]:
    """Rotation matrix of URDF roll-pitch-yaw angles (rad): Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def matrix_rpy(rotation: NDArray) -> NDArray[np.float64]:
    """URDF roll-pitch-yaw angles (rad) of a rotation matrix (inverse of ``rpy_matrix``)."""
    m = np.asarray(rotation, dtype=float)
    pitch = math.asin(-max(-1.0, min(1.0, m[2, 0])))
    if abs(m[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(m[2, 1], m[2, 2])
        yaw = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = math.atan2(-m[0, 1], m[1, 1])
    return np.array([roll, pitch, yaw])


def pose_matrix(xyz: NDArray | tuple[float, ...], rpy: NDArray | tuple[float, ...] = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """4 × 4 homogeneous transform from a translation (mm) and URDF rpy (rad)."""
    t = np.eye(4)
    t[:3, :3] = rpy_matrix(rpy)
    t[:3, 3] = np.asarray(xyz, dtype=float)
    return t


def axis_rotation(axis: NDArray, angle: float) -> NDArray[np.float64]:
    """Rotation matrix of ``angle`` rad about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    return np.array([
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ])


def _z_to(direction: NDArray) -> NDArray[np.float64]:
    """A rotation taking the z axis onto the unit vector ``direction`` (shortest arc)."""
    d = direction / np.linalg.norm(direction)
    z = np.array([0.0, 0.0, 1.0])
    c = float(d @ z)
    if c > 1.0 - 1e-12:
        return np.eye(3)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    k = np.cross(z, d)
    return axis_rotation(k / np.linalg.norm(k), math.acos(c))


# --------------------------------------------------------------------------- loading


def _err(field: str, message: str) -> ValueError:
    return ValueError(f"hand file: {field}: {message}")


def _vector(node: dict, key: str, field: str, n: int = 3) -> NDArray[np.float64]:
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


def _number(node: dict, key: str, field: str, minimum: float | None = None) -> float:
    if key not in node:
        raise _err(f"{field}.{key}", "missing (a number)")
    value = node[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _err(f"{field}.{key}", f"must be a finite number, got {value!r}")
    if minimum is not None and value < minimum:
        raise _err(f"{field}.{key}", f"must be >= {minimum}, got {value!r}")
    return float(value)


#: The keys allowed at each level of a hand file (a misspelt optional key is an error).
_HAND_KEYS: dict[str, tuple[str, ...]] = {
    "<top level>": ("name", "palm_normal", "palm", "fingers"),
    "palm": ("shapes",),
    "finger": ("knuckle", "tip_mm", "joints"),
    "knuckle": ("xyz_mm", "rpy_rad"),
    "joint": ("name", "offset_mm", "rpy_rad", "axis", "rolling_gap_mm", "limits_deg", "link", "shapes"),
    "capsule": ("from_mm", "to_mm", "radius_mm"),
    "box": ("center_mm", "size_mm", "rpy_rad"),
}


def _mapping(node: Any, field: str, kind: str | None = None) -> dict:
    if not isinstance(node, dict):
        raise _err(field, f"must be a mapping, got {type(node).__name__}")
    allowed = _HAND_KEYS.get(kind or "", None)
    unknown = [k for k in node if k not in allowed] if allowed else []
    if unknown:
        raise _err(field, f"unknown key(s) {unknown}; allowed keys: {list(allowed)}")
    return node


def _shape(node: Any, field: str) -> Shape:
    node = _mapping(node, field)
    if len(node) != 1 or next(iter(node)) not in SHAPE_KINDS:
        raise _err(field, f"must be a single key, one of {SHAPE_KINDS}, got {list(node)}")
    kind = next(iter(node))
    spec = _mapping(node[kind], f"{field}.{kind}", kind)
    f = f"{field}.{kind}"
    if kind == "capsule":
        a = _vector(spec, "from_mm", f)
        b = _vector(spec, "to_mm", f)
        radius = _number(spec, "radius_mm", f, minimum=1e-6)
        pose = np.eye(4)
        pose[:3, 3] = 0.5 * (a + b)
        length = float(np.linalg.norm(b - a))
        if length > 0:
            pose[:3, :3] = _z_to(b - a)
        return Shape("capsule", pose, radius=radius, length=length)
    size = _vector(spec, "size_mm", f)
    if np.any(size <= 0):
        raise _err(f"{f}.size_mm", f"must be positive, got {size.tolist()}")
    center = _vector(spec, "center_mm", f)
    rpy = _vector(spec, "rpy_rad", f) if "rpy_rad" in spec else np.zeros(3)
    return Shape("box", pose_matrix(center, rpy), size=size)


def _shapes(node: dict, field: str) -> tuple[Shape, ...]:
    shapes = node.get("shapes", [])
    if not isinstance(shapes, list):
        raise _err(f"{field}.shapes", "must be a list of {capsule: ...} or {box: ...}")
    return tuple(_shape(s, f"{field}.shapes[{i}]") for i, s in enumerate(shapes))


def default_hand_path() -> Path:
    """Path of the shipped SoftHand-like model."""
    return Path(str(resources.files("synergrasp") / "data" / "hand.yaml"))


def load_hand(path: str | Path | None = None) -> Hand:
    """Load a hand model from a YAML file (None: the shipped SoftHand-like model).

    The file format is documented in docs/hand.md and in the header of data/hand.yaml.
    Raises ValueError naming the offending field.
    """
    path = default_hand_path() if path is None else Path(path)
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc).splitlines()[0]
        raise ValueError(f"hand file '{path}': not a readable YAML file ({reason})") from None
    if doc is None:
        raise ValueError(f"hand file '{path}': is empty; the format is in docs/hand.md")
    try:
        return hand_from_dict(doc)
    except ValueError as exc:
        raise ValueError(str(exc).replace("hand file:", f"hand file '{path}':", 1)) from None


def hand_from_dict(doc: Any) -> Hand:
    """Build a Hand from the parsed content of a hand file (see ``load_hand``)."""
    doc = _mapping(doc, "<top level>", "<top level>")
    for key in ("palm", "fingers"):
        if key not in doc:
            raise _err(key, "missing")
    name = str(doc.get("name", "hand"))
    palm_normal = _vector(doc, "palm_normal", "<top level>") if "palm_normal" in doc else PALM_NORMAL.copy()
    if not np.isclose(np.linalg.norm(palm_normal), 1.0, atol=1e-6):
        raise _err("palm_normal", f"must be a unit vector, got {palm_normal.tolist()}")
    fingers = _mapping(doc["fingers"], "fingers")
    if sorted(fingers) != sorted(FINGERS):
        raise _err("fingers", f"must have exactly the keys {FINGERS}, got {tuple(fingers)}")

    frame_names = ["palm"]
    frame_parent = [-1]
    frame_offset = [np.eye(4)]
    frame_axis = [np.zeros(3)]
    frame_joint = [-1]
    frame_scale = [0.0]
    frame_joint_names = [""]
    link_names = ["palm"]
    link_finger = ["palm"]
    link_frame = [0]
    link_parent = [-1]
    link_parent_joint = [-1]
    link_shapes = [_shapes(_mapping(doc["palm"], "palm", "palm"), "palm")]
    joint_names: list[str] = []
    lower: list[float] = []
    upper: list[float] = []
    finger_joints: list[tuple[int, ...]] = []
    finger_links: list[tuple[int, ...]] = []
    tips: list[NDArray] = []
    ignored: list[tuple[int, int]] = []

    def add_frame(fname: str, parent: int, offset: NDArray, axis: NDArray, joint: int, scale: float, jname: str) -> int:
        frame_names.append(fname)
        frame_parent.append(parent)
        frame_offset.append(offset)
        frame_axis.append(axis)
        frame_joint.append(joint)
        frame_scale.append(scale)
        frame_joint_names.append(jname)
        return len(frame_names) - 1

    for finger in FINGERS:
        ff = f"fingers.{finger}"
        fnode = _mapping(fingers[finger], ff, "finger")
        knuckle = _mapping(fnode.get("knuckle"), f"{ff}.knuckle", "knuckle")
        knuckle_pose = pose_matrix(_vector(knuckle, "xyz_mm", f"{ff}.knuckle"), _vector(knuckle, "rpy_rad", f"{ff}.knuckle"))
        tips.append(_vector(fnode, "tip_mm", ff))
        joints = fnode.get("joints")
        if not isinstance(joints, list) or not joints:
            raise _err(f"{ff}.joints", "must be a non-empty list of joints")
        parent_frame, parent_link = 0, 0
        pending = knuckle_pose  # the knuckle pose is folded into the first joint's offset
        fj: list[int] = []
        fl: list[int] = []
        for i, jnode in enumerate(joints):
            jf = f"{ff}.joints[{i}]"
            jnode = _mapping(jnode, jf, "joint")
            jname = jnode.get("name")
            k = len(joint_names)
            if k >= len(JOINT_NAMES) or jname != JOINT_NAMES[k]:
                expected = JOINT_NAMES[k] if k < len(JOINT_NAMES) else "(no more joints: 19 in all)"
                raise _err(f"{jf}.name", f"must be {expected!r} (joint order of docs/design.md), got {jname!r}")
            axis = _vector(jnode, "axis", jf)
            if np.linalg.norm(axis) < 1e-9:
                raise _err(f"{jf}.axis", "must be a non-zero vector")
            axis = axis / np.linalg.norm(axis)
            offset = pending @ pose_matrix(_vector(jnode, "offset_mm", jf),
                                           _vector(jnode, "rpy_rad", jf) if "rpy_rad" in jnode else np.zeros(3))
            pending = np.eye(4)
            gap = _number(jnode, "rolling_gap_mm", jf, minimum=0.0) if "rolling_gap_mm" in jnode else 0.0
            lim = jnode.get("limits_deg")
            if (not isinstance(lim, list) or len(lim) != 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in lim)
                    or not lim[0] < lim[1]):
                raise _err(f"{jf}.limits_deg", f"must be [lower, upper] in degrees with lower < upper, got {lim!r}")
            link = jnode.get("link")
            if not isinstance(link, str) or not link.startswith(f"{finger}_") or link in link_names:
                raise _err(f"{jf}.link", f"must be a new link name starting with '{finger}_', got {link!r}")
            if gap > 0:
                first = add_frame(f"{jname}_half", parent_frame, offset, axis, k, 0.5, f"{jname}_a")
                last = add_frame(link, first, pose_matrix([gap, 0.0, 0.0]), axis, k, 0.5, f"{jname}_b")
            else:
                last = add_frame(link, parent_frame, offset, axis, k, 1.0, jname)
            joint_names.append(jname)
            lower.append(math.radians(lim[0]))
            upper.append(math.radians(lim[1]))
            link_names.append(link)
            link_finger.append(finger)
            link_frame.append(last)
            link_parent.append(parent_link)
            link_parent_joint.append(k)
            link_shapes.append(_shapes(jnode, jf))
            li = len(link_names) - 1
            # a link touches its parent at the joint by design (rolling surfaces, knuckle in the palm)
            ignored.append((parent_link, li))
            fj.append(k)
            fl.append(li)
            parent_frame, parent_link = last, li
        finger_joints.append(tuple(fj))
        finger_links.append(tuple(fl))
    if tuple(joint_names) != JOINT_NAMES:
        raise _err("fingers", f"joints must be exactly {JOINT_NAMES}, got {tuple(joint_names)}")
    ignored_set = set(ignored)
    # the knuckles sit in the palm: none of them may be tested against it
    ignored_set.update((0, fl[0]) for fl in finger_links)
    return Hand(
        name=name,
        joint_names=tuple(joint_names),
        lower=np.array(lower),
        upper=np.array(upper),
        link_names=tuple(link_names),
        link_finger=tuple(link_finger),
        link_frame=np.array(link_frame),
        link_parent=np.array(link_parent),
        link_parent_joint=np.array(link_parent_joint),
        link_shapes=tuple(link_shapes),
        frame_names=tuple(frame_names),
        frame_parent=np.array(frame_parent),
        frame_offset=np.array(frame_offset),
        frame_axis=np.array(frame_axis),
        frame_joint=np.array(frame_joint),
        frame_scale=np.array(frame_scale),
        frame_joint_names=tuple(frame_joint_names),
        finger_joints=tuple(finger_joints),
        finger_links=tuple(finger_links),
        fingertip_link=np.array([fl[-1] for fl in finger_links]),
        fingertip_point=np.array(tips),
        ignored_link_pairs=tuple(sorted(ignored_set)),
        palm_normal=palm_normal,
    )


# --------------------------------------------------------------------------- kinematics


def _check_q(hand: Hand, q: NDArray) -> NDArray[np.float64]:
    q = np.asarray(q, dtype=float)
    if q.shape != (hand.n_joints,):
        raise ValueError(f"q must have shape ({hand.n_joints},) (joints {hand.joint_names[0]} ... "
                         f"{hand.joint_names[-1]}), got {q.shape}")
    return q


def frame_transforms(hand: Hand, q: NDArray) -> NDArray[np.float64]:
    """(n_frames, 4, 4) transforms of every elementary axis frame in the palm frame, mm."""
    q = _check_q(hand, q)
    # all axis rotations at once (Rodrigues), then the chain in tree order (parents first)
    angle = hand.frame_scale[1:] * q[hand.frame_joint[1:]]
    axis = hand.frame_axis[1:]
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    cross = np.zeros((len(angle), 3, 3))
    cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    cross -= cross.transpose(0, 2, 1)
    local = hand.frame_offset[1:].copy()
    local[:, :3, :3] = local[:, :3, :3] @ (c * np.eye(3) + s * cross + (1 - c) * axis[:, :, None] * axis[:, None, :])
    t = np.empty((len(hand.frame_names), 4, 4))
    t[0] = np.eye(4)
    parent = hand.frame_parent
    for f in range(1, len(t)):
        t[f] = t[parent[f]] @ local[f - 1]
    return t


def forward_kinematics(hand: Hand, q: NDArray) -> NDArray[np.float64]:
    """(n_links, 4, 4) link frames in the palm frame at joint angles q (rad), translations in mm."""
    return frame_transforms(hand, q)[hand.link_frame]


def fingertip_positions(hand: Hand, q: NDArray) -> NDArray[np.float64]:
    """(5, 3) fingertip points (FINGERS order) in the palm frame, mm."""
    links = forward_kinematics(hand, q)[hand.fingertip_link]
    return np.einsum("kij,kj->ki", links[:, :3, :3], hand.fingertip_point) + links[:, :3, 3]


def _chain(hand: Hand, link: int) -> NDArray[np.int64]:
    """Frames from the link's own frame down to (excluding) the palm."""
    chain = []
    f = int(hand.link_frame[link])
    while f > 0:
        chain.append(f)
        f = int(hand.frame_parent[f])
    return np.array(chain, dtype=np.int64)


def _jacobian_rows(hand: Hand, frames: NDArray, link: int, point: NDArray) -> NDArray[np.float64]:
    jac = np.zeros((3, hand.n_joints))
    chain = _chain(hand, link)
    if len(chain) == 0:
        return jac
    axes = np.einsum("fij,fj->fi", frames[chain, :3, :3], hand.frame_axis[chain])
    cols = hand.frame_scale[chain, None] * np.cross(axes, point - frames[chain, :3, 3])
    # the two halves of a rolling joint add into one column
    np.add.at(jac.T, hand.frame_joint[chain], cols)
    return jac


def _check_link(hand: Hand, link: int | str) -> int:
    if isinstance(link, str):
        return hand.link_index(link)
    if not isinstance(link, (int, np.integer)) or not 0 <= int(link) < hand.n_links:
        raise ValueError(f"link must be an index 0 ... {hand.n_links - 1} or a name of hand.link_names, got {link!r}")
    return int(link)


def point_jacobian(hand: Hand, q: NDArray, link: int | str, point_mm: NDArray) -> NDArray[np.float64]:
    """(3, 19) translational Jacobian (mm/rad, palm frame) of a point fixed to ``link``.

    ``point_mm`` is the point's current position in the palm frame (mm). A rolling joint's
    column is the sum of its two half axes, each weighted 1/2. Zero for the palm.
    """
    link = _check_link(hand, link)
    point = np.asarray(point_mm, dtype=float)
    if point.shape != (3,):
        raise ValueError(f"point_mm must have shape (3,), got {point.shape}")
    return _jacobian_rows(hand, frame_transforms(hand, q), link, point)


def contact_jacobian(hand: Hand, q: NDArray, links: NDArray, points_mm: NDArray) -> NDArray[np.float64]:
    """(3m, 19) stacked point Jacobians (mm/rad, palm frame) for m contacts.

    ``links`` (m,) link indices, ``points_mm`` (m, 3) contact points in the palm frame, mm.
    Rows 3i … 3i+2 belong to contact i; palm contacts give zero rows.
    """
    links = np.asarray(links).reshape(-1)
    points = np.asarray(points_mm, dtype=float).reshape(-1, 3) if np.size(points_mm) else np.zeros((0, 3))
    if points.shape[0] != links.shape[0]:
        raise ValueError(f"points_mm must have shape ({links.shape[0]}, 3) to match links, got {np.shape(points_mm)}")
    frames = frame_transforms(hand, q)
    jac = np.zeros((3 * len(links), hand.n_joints))
    for i, (link, point) in enumerate(zip(links, points)):
        jac[3 * i:3 * i + 3] = _jacobian_rows(hand, frames, _check_link(hand, int(link)), point)
    return jac


# --------------------------------------------------------------------------- URDF


def _fmt(values: NDArray | list[float]) -> str:
    # fixed rounding keeps the text deterministic and free of -0
    return " ".join(f"{(round(float(v), 9) + 0.0):.9g}" for v in values)


def _origin(pose: NDArray) -> str:
    return f'<origin xyz="{_fmt(pose[:3, 3] / 1000.0)}" rpy="{_fmt(matrix_rpy(pose[:3, :3]))}"/>'


def _geometry(shape: Shape, visual: bool) -> str:
    if shape.kind == "capsule":
        # pybullet reads a capsule's height as 'length' in URDF for both visuals and collisions
        return f'<capsule radius="{shape.radius / 1000.0:.9g}" length="{shape.length / 1000.0:.9g}"/>'
    return f'<box size="{_fmt(np.asarray(shape.size) / 1000.0)}"/>'


def urdf_text(hand: Hand, mass_kg: float = 0.01) -> str:
    """URDF of the hand in metres: one link per elementary axis frame, simple collision shapes,
    inertial frames equal to the link frames (pybullet's calculateJacobian then takes link-frame
    points). Rolling joints appear as two revolute joints ``<joint>_a`` and ``<joint>_b``,
    each limited to half of the joint's range."""
    lines = ['<?xml version="1.0"?>', f'<robot name="{hand.name}">']
    shapes_of_frame = {int(f): hand.link_shapes[i] for i, f in enumerate(hand.link_frame)}
    finger_colour = {"palm": "0.55 0.55 0.6 1", "thumb": "0.85 0.45 0.3 1", "index": "0.3 0.6 0.85 1",
                     "middle": "0.4 0.75 0.4 1", "ring": "0.85 0.75 0.3 1", "little": "0.7 0.45 0.8 1"}
    for f, fname in enumerate(hand.frame_names):
        finger = "palm" if f == 0 else hand.joint_names[hand.frame_joint[f]].split("_")[0]
        lines.append(f'  <link name="{fname}">')
        lines.append('    <inertial><origin xyz="0 0 0" rpy="0 0 0"/>'
                     f'<mass value="{mass_kg:.9g}"/>'
                     '<inertia ixx="1e-06" ixy="0" ixz="0" iyy="1e-06" iyz="0" izz="1e-06"/></inertial>')
        for shape in shapes_of_frame.get(f, ()):
            lines.append(f'    <visual>{_origin(shape.pose)}<geometry>{_geometry(shape, True)}</geometry>'
                         f'<material name="{finger}"><color rgba="{finger_colour[finger]}"/></material></visual>')
            lines.append(f'    <collision>{_origin(shape.pose)}<geometry>{_geometry(shape, False)}</geometry></collision>')
        lines.append('  </link>')
    for f in range(1, len(hand.frame_names)):
        k = int(hand.frame_joint[f])
        s = float(hand.frame_scale[f])
        lines.append(f'  <joint name="{hand.frame_joint_names[f]}" type="revolute">')
        lines.append(f'    <parent link="{hand.frame_names[hand.frame_parent[f]]}"/>'
                     f'<child link="{hand.frame_names[f]}"/>')
        lines.append(f'    {_origin(hand.frame_offset[f])}<axis xyz="{_fmt(hand.frame_axis[f])}"/>')
        lines.append(f'    <limit lower="{s * hand.lower[k]:.9g}" upper="{s * hand.upper[k]:.9g}" '
                     'effort="10" velocity="10"/>')
        lines.append('  </joint>')
    lines.append('</robot>')
    return "\n".join(lines) + "\n"


def write_urdf(hand: Hand, path: str | Path) -> None:
    """Write the hand's URDF (metres; see ``urdf_text``) to ``path``."""
    Path(path).write_text(urdf_text(hand), encoding="utf-8")
