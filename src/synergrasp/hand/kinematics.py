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

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.geometry import (  # noqa: F401  (the model's geometry, re-exported)
    SHAPE_KINDS,
    Shape,
    axis_rotation,
    matrix_rpy,
    pose_matrix,
    rpy_matrix,
)
from synergrasp.hand.hand_file import (  # noqa: F401  (the file format, re-exported)
    FINGERS,
    JOINT_NAMES,
    PALM_NORMAL,
    HandSpec,
    check_hand_doc,
    default_hand_path,
    read_hand_file,
)
from synergrasp.hand.description import hand_spec  # noqa: F401  (re-exported)

FINGERTIP_LINKS: tuple[str, ...] = (
    "thumb_distal",
    "index_distal",
    "middle_distal",
    "ring_distal",
    "little_distal",
)
"""Last link of each finger chain, in FINGERS order (shipped model)."""


@dataclass(frozen=True)
class Hand:
    """A hand model (see the module docstring for the frame tree).

    Joints follow ``JOINT_NAMES``; links are ``palm`` then ``<finger>_<segment>``.
    """

    name: str
    joint_names: tuple[str, ...]
    lower: NDArray[np.float64]  # (19,) rad
    upper: NDArray[np.float64]  # (19,) rad
    link_names: tuple[str, ...]
    link_finger: tuple[str, ...]  # finger of each link, 'palm' for the palm
    link_frame: NDArray[np.int64]  # frame each link is attached to
    link_parent: NDArray[np.int64]  # parent link, -1 for the palm
    link_parent_joint: NDArray[np.int64]  # joint (q index) moving the link, -1 for the palm
    link_shapes: tuple[tuple[Shape, ...], ...]
    frame_names: tuple[str, ...]  # frame 0 'palm'; hand links keep their names
    frame_parent: NDArray[np.int64]  # -1 for frame 0
    frame_offset: NDArray[np.float64]  # (n_frames, 4, 4) parent frame -> axis frame, mm
    frame_axis: NDArray[np.float64]  # (n_frames, 3) unit axis in the frame
    frame_joint: NDArray[np.int64]  # q index driving the frame, -1 for the palm
    frame_scale: NDArray[np.float64]  # angle of the axis per unit q (1, or 1/2 for a rolling half)
    frame_joint_names: tuple[str, ...]  # name of the elementary axis ('' for the palm)
    finger_joints: tuple[tuple[int, ...], ...]  # q indices per finger, FINGERS order
    finger_links: tuple[tuple[int, ...], ...]  # link indices per finger, proximal to distal
    fingertip_link: NDArray[np.int64]  # (5,) distal link of each finger
    fingertip_point: NDArray[np.float64]  # (5, 3) fingertip point in its distal link frame, mm
    ignored_link_pairs: tuple[tuple[int, int], ...]  # self-collision pairs to skip (touching by design)
    palm_normal: NDArray[np.float64]
    source: str = "the shipped hand"  # where the model was read from (for messages)
    shapeless_links: tuple[int, ...] = ()  # finger links without a shape (a body carrying only a joint)

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


# --------------------------------------------------------------------------- loading: read, check, build


def load_hand(path: str | Path | None = None) -> Hand:
    """Load a hand model from a YAML file (None: the shipped SoftHand-like model): read and
    check it (``description.hand_spec``), then build it (:func:`build_hand`).

    The file format is documented in docs/hand.md and in the header of data/hand.yaml.
    Raises ValueError naming the file and the offending field.
    """
    return build_hand(*hand_spec(path))


class _Tree:
    """The frame tree and the links of a hand, filled joint by joint."""

    def __init__(self, palm_shapes: tuple[Shape, ...]) -> None:
        self.frames: list[tuple[str, int, NDArray, NDArray, int, float, str]] = [
            ("palm", -1, np.eye(4), np.zeros(3), -1, 0.0, "")
        ]
        self.links: list[tuple[str, str, int, int, int, tuple[Shape, ...]]] = [("palm", "palm", 0, -1, -1, palm_shapes)]

    def frame(self, name: str, parent: int, offset: NDArray, axis: NDArray, joint: int, scale: float, jname: str) -> int:
        self.frames.append((name, parent, offset, axis, joint, scale, jname))
        return len(self.frames) - 1

    def column(self, items: list, i: int, **kwargs: Any) -> NDArray:
        return np.array([item[i] for item in items], **kwargs)


def build_hand(spec: HandSpec, source: str = "the shipped hand") -> Hand:
    """The Hand (frame tree, links, limits) of a checked hand file (``check_hand_doc``)."""
    tree = _Tree(spec.palm_shapes)
    joint_names: list[str] = []
    lower: list[float] = []
    upper: list[float] = []
    finger_joints: list[tuple[int, ...]] = []
    finger_links: list[tuple[int, ...]] = []
    ignored: set[tuple[int, int]] = set()
    shapeless: list[int] = []
    for finger in spec.fingers:
        parent_frame, parent_link, shaped_parent, fj, fl = 0, 0, 0, [], []
        for joint in finger.joints:
            k = len(joint_names)
            if joint.follows:  # a coupled joint: a frame turned by the joint it follows
                k = joint_names.index(joint.follows)
                last = tree.frame(joint.link, parent_frame, joint.offset, joint.axis, k, joint.scale, joint.name)
            elif joint.rolling_gap_mm > 0:
                first = tree.frame(f"{joint.name}_half", parent_frame, joint.offset, joint.axis, k, 0.5, f"{joint.name}_a")
                last = tree.frame(
                    joint.link, first, pose_matrix([joint.rolling_gap_mm, 0.0, 0.0]), joint.axis, k, 0.5, f"{joint.name}_b"
                )
            else:
                last = tree.frame(joint.link, parent_frame, joint.offset, joint.axis, k, joint.scale, joint.name)
            if not joint.follows:
                joint_names.append(joint.name)
                lower.append(joint.lower_rad)
                upper.append(joint.upper_rad)
            tree.links.append((joint.link, finger.name, last, parent_link, k, joint.shapes))
            li = len(tree.links) - 1
            # a link touches its parent at the joint by design (rolling surfaces, knuckle in the palm);
            # past a link without shape, the nearest one with shapes
            ignored.add((parent_link, li))
            if parent_link in shapeless:
                ignored.add((shaped_parent, li))
            if joint.shapes:
                shaped_parent = li
            else:
                shapeless.append(li)
            fj.append(k)
            fl.append(li)
            parent_frame, parent_link = last, li
        finger_joints.append(tuple(fj))
        finger_links.append(tuple(fl))
    # the knuckles sit in the palm: none of them may be tested against it
    ignored.update((0, fl[0]) for fl in finger_links)
    frames, links = tree.frames, tree.links
    names = [link[0] for link in links]
    ignored.update(tuple(sorted((names.index(a), names.index(b)))) for a, b in spec.ignored_pairs)
    return Hand(
        name=spec.name,
        joint_names=tuple(joint_names),
        lower=np.array(lower),
        upper=np.array(upper),
        link_names=tuple(link[0] for link in links),
        link_finger=tuple(link[1] for link in links),
        link_frame=tree.column(links, 2),
        link_parent=tree.column(links, 3),
        link_parent_joint=tree.column(links, 4),
        link_shapes=tuple(link[5] for link in links),
        frame_names=tuple(f[0] for f in frames),
        frame_parent=tree.column(frames, 1),
        frame_offset=tree.column(frames, 2),
        frame_axis=tree.column(frames, 3),
        frame_joint=tree.column(frames, 4),
        frame_scale=tree.column(frames, 5, dtype=float),
        frame_joint_names=tuple(f[6] for f in frames),
        finger_joints=tuple(finger_joints),
        finger_links=tuple(finger_links),
        fingertip_link=np.array([fl[-1] for fl in finger_links]),
        fingertip_point=np.array([f.tip_mm for f in spec.fingers]),
        ignored_link_pairs=tuple(sorted(ignored)),
        palm_normal=spec.palm_normal,
        source=source,
        shapeless_links=tuple(shapeless) if spec.shapeless_links else (),
    )


# --------------------------------------------------------------------------- kinematics


def _check_q(hand: Hand, q: NDArray) -> NDArray[np.float64]:
    q = np.asarray(q, dtype=float)
    if q.shape != (hand.n_joints,):
        raise ValueError(
            f"q must have shape ({hand.n_joints},) (joints {hand.joint_names[0]} ... {hand.joint_names[-1]}), got {q.shape}"
        )
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


def cross_rows(a: NDArray, b: NDArray) -> NDArray:
    """Row-wise a x b of (m, 3) arrays: the products and differences of np.cross, in its
    order (the same bits), without its axis handling (which costs more than the arithmetic
    for a few rows)."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _jacobian_rows(hand: Hand, frames: NDArray, link: int, point: NDArray) -> NDArray[np.float64]:
    jac = np.zeros((3, hand.n_joints))
    chain = _chain(hand, link)
    if len(chain) == 0:
        return jac
    axes = np.einsum("fij,fj->fi", frames[chain, :3, :3], hand.frame_axis[chain])
    cols = hand.frame_scale[chain, None] * cross_rows(axes, point - frames[chain, :3, 3])
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
        jac[3 * i : 3 * i + 3] = _jacobian_rows(hand, frames, _check_link(hand, int(link)), point)
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
    finger_colour = {
        "palm": "0.55 0.55 0.6 1",
        "thumb": "0.85 0.45 0.3 1",
        "index": "0.3 0.6 0.85 1",
        "middle": "0.4 0.75 0.4 1",
        "ring": "0.85 0.75 0.3 1",
        "little": "0.7 0.45 0.8 1",
    }
    for f, fname in enumerate(hand.frame_names):
        finger = "palm" if f == 0 else hand.joint_names[hand.frame_joint[f]].split("_")[0]
        lines.append(f'  <link name="{fname}">')
        lines.append(
            '    <inertial><origin xyz="0 0 0" rpy="0 0 0"/>'
            f'<mass value="{mass_kg:.9g}"/>'
            '<inertia ixx="1e-06" ixy="0" ixz="0" iyy="1e-06" iyz="0" izz="1e-06"/></inertial>'
        )
        for shape in shapes_of_frame.get(f, ()):
            lines.append(
                f"    <visual>{_origin(shape.pose)}<geometry>{_geometry(shape, True)}</geometry>"
                f'<material name="{finger}"><color rgba="{finger_colour[finger]}"/></material></visual>'
            )
            lines.append(f"    <collision>{_origin(shape.pose)}<geometry>{_geometry(shape, False)}</geometry></collision>")
        lines.append("  </link>")
    for f in range(1, len(hand.frame_names)):
        k = int(hand.frame_joint[f])
        s = float(hand.frame_scale[f])
        lines.append(f'  <joint name="{hand.frame_joint_names[f]}" type="revolute">')
        lines.append(f'    <parent link="{hand.frame_names[hand.frame_parent[f]]}"/><child link="{hand.frame_names[f]}"/>')
        lines.append(f'    {_origin(hand.frame_offset[f])}<axis xyz="{_fmt(hand.frame_axis[f])}"/>')
        lines.append(f'    <limit lower="{s * hand.lower[k]:.9g}" upper="{s * hand.upper[k]:.9g}" effort="10" velocity="10"/>')
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def write_urdf(hand: Hand, path: str | Path) -> None:
    """Write the hand's URDF (metres; see ``urdf_text``) to ``path``."""
    Path(path).write_text(urdf_text(hand), encoding="utf-8")
