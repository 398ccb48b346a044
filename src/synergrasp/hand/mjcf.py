"""Hands read from MJCF through MuJoCo's own compiler (docs/hand.md, "Hands from MJCF").

A hand description (YAML) names an MJCF model and says what the format does not: which body
is the palm, which joints make each finger's chain (with the project's joint and link
names), the palm normal and the finger direction, the joints held fixed, the coupled joints
and the collision geoms to leave out. :func:`mjcf_hand_spec` compiles the model with MuJoCo
(``mujoco.MjModel``: its bodies, hinge joints, axes, ranges and collision geoms after the
compiler resolved includes, defaults and ``fromto``), checks every name and converts it into
the project's :class:`HandSpec` (mm, rad, the palm frame of docs/hand.md): a new front door
to the same hand model. MuJoCo works in metres; every length is multiplied by 1000 here.
The model's own statements are read too: its joint equalities (``<equality><joint>``, linear
through zero) are couplings, its contact exclusions (``<contact><exclude>``) pairs of links
that are not self-contacts, and with ``fit_meshes: true`` each collision mesh becomes the
capsule or box that holds its convex hull (``synergrasp.hand.mesh_fit``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.geometry import Shape, axis_rotation, pose_matrix
from synergrasp.hand.hand_file import FINGERS, FingerSpec, HandSpec, JointSpec
from synergrasp.hand.mesh_fit import MeshFitError, fit_box, fit_capsule, hull_vertices

__all__ = ["mjcf_hand_spec", "compile_mjcf", "MM_PER_M"]

MM_PER_M = 1000.0

_KEYS = (
    "name",
    "mjcf",
    "urdf",
    "palm",
    "palm_normal",
    "finger_direction",
    "fixed_joints",
    "couplings",
    "ignore_geoms",
    "fit_meshes",
    "fingers",
)
_FINGER_KEYS = ("joints", "tip_site", "tip_mm")
_CHAIN_KEYS = ("mjcf", "name", "link", "reverse", "scale")
#: MuJoCo's joint, geom and equality type codes (mjtJoint, mjtGeom, mjtEq) and their names in messages.
_JOINT_TYPES = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
_GEOM_TYPES = {0: "plane", 1: "hfield", 2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh", 8: "sdf"}
_EQ_JOINT = 2


class _Error(ValueError):
    pass


@dataclass
class _Model:
    """The compiled MJCF model and the description's file names, for messages."""

    model: Any
    where: str  # "hand file '<description>'"
    xml: str  # the MJCF file's name
    fit_meshes: bool = False  # a collision mesh becomes the capsule or box holding its hull

    def find(self, kind: str, name: Any, field: str) -> int:
        """Index of the ``kind`` (body, joint, site, geom) named ``name``; one line naming the
        description, the field and the MJCF file otherwise."""
        import mujoco

        obj = {
            "body": mujoco.mjtObj.mjOBJ_BODY,
            "joint": mujoco.mjtObj.mjOBJ_JOINT,
            "site": mujoco.mjtObj.mjOBJ_SITE,
            "geom": mujoco.mjtObj.mjOBJ_GEOM,
        }[kind]
        index = mujoco.mj_name2id(self.model, obj, str(name)) if isinstance(name, str) else -1
        if index < 0:
            raise _Error(f"{self.where}: {field}: no {kind} named {name!r} in '{self.xml}'")
        return index


def compile_mjcf(path: str | Path) -> Any:
    """The ``mujoco.MjModel`` of an MJCF file (MuJoCo's compiler: includes, defaults, units)."""
    import mujoco

    return mujoco.MjModel.from_xml_path(str(path))


def _pose(quat: NDArray, pos_m: NDArray) -> NDArray[np.float64]:
    """A MuJoCo frame (unit quaternion, position in m) as a 4 × 4 pose, mm."""
    import mujoco

    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, quat)
    t = np.eye(4)
    t[:3, :3] = rot.reshape(3, 3)
    t[:3, 3] = np.asarray(pos_m) * MM_PER_M
    return t


def _local(model: Any, body: int) -> NDArray[np.float64]:
    """Pose (4 × 4, mm) of ``body`` in its parent body's frame, joints at zero."""
    return _pose(model.body_quat[body], model.body_pos[body])


def _hinge(model: Any, joint: int, angle: float) -> NDArray[np.float64]:
    """The motion (4 × 4, mm, body frame) of a hinge at ``angle`` rad about its anchor."""
    anchor = model.jnt_pos[joint] * MM_PER_M
    turn = np.eye(4)
    turn[:3, :3] = axis_rotation(model.jnt_axis[joint] / np.linalg.norm(model.jnt_axis[joint]), angle)
    return pose_matrix(anchor) @ turn @ pose_matrix(-anchor)


def _geom_shape(m: _Model, geom: int, pose: NDArray, palm: bool) -> Shape:
    """The project's shape of a collision geom (``pose``: its pose in the link frame, mm;
    ``palm``: the geom is part of the palm, whose frame is the link frame)."""
    model = m.model
    kind = int(model.geom_type[geom])
    size = model.geom_size[geom] * MM_PER_M
    if kind == 3:  # capsule: radius, half-length along local z
        return Shape("capsule", pose, radius=float(size[0]), length=float(2.0 * size[1]))
    if kind == 2:  # sphere: a capsule of length 0
        return Shape("capsule", pose, radius=float(size[0]), length=0.0)
    if kind == 6:  # box: half-sizes
        return Shape("box", pose, size=2.0 * size)
    label = repr(model.geom(geom).name) if model.geom(geom).name else f"#{geom} (unnamed)"
    where = f"{m.where}: geom {label} of body {model.body(model.geom_bodyid[geom]).name!r} in '{m.xml}'"
    if kind == 7 and m.fit_meshes:  # the capsule (finger link) or box (palm) holding the mesh's hull
        try:
            hull = hull_vertices(model, geom)
            if palm:
                fitted, edges = fit_box(hull, pose[:3, :3].T)  # the palm frame's axes, in the geom's frame
                return Shape("box", pose @ fitted, size=edges)
            fitted, radius, length = fit_capsule(hull)
        except MeshFitError as err:
            raise _Error(f"{where}: the mesh is refused: {err}") from None
        return Shape("capsule", pose @ fitted, radius=radius, length=length)
    hint = "; or fit_meshes: true" if kind == 7 else ""
    raise _Error(
        f"{where}: a {_GEOM_TYPES.get(kind, kind)} collision geom is refused (the closure collides "
        f"capsules, spheres and boxes); give the hand capsules/boxes or list it in ignore_geoms{hint}"
    )


def _geom_pose(model: Any, geom: int) -> NDArray[np.float64]:
    """Pose (4 × 4, mm) of a geom in its body's frame."""
    return _pose(model.geom_quat[geom], model.geom_pos[geom])


def _vector(doc: dict, key: str, where: str, default: list[float]) -> NDArray[np.float64]:
    value = doc.get(key, default)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)) or np.linalg.norm(arr) < 1e-9:
        raise _Error(f"{where}: {key}: must be a non-zero list of 3 numbers, got {value!r}")
    return arr / np.linalg.norm(arr)


def _palm_frame(doc: dict, where: str) -> NDArray[np.float64]:
    """The project's palm frame (4 × 4) in the palm body's frame: x the palm normal, z the
    finger direction (made orthogonal to x), y = z × x (toward the thumb of a right hand)."""
    normal = _vector(doc, "palm_normal", where, [1.0, 0.0, 0.0])
    along = _vector(doc, "finger_direction", where, [0.0, 0.0, 1.0])
    along = along - (along @ normal) * normal
    if np.linalg.norm(along) < 1e-6:
        raise _Error(f"{where}: finger_direction: must not be parallel to palm_normal")
    z = along / np.linalg.norm(along)
    frame = np.eye(4)
    frame[:3, :3] = np.column_stack([normal, np.cross(z, normal), z])
    return frame


def _names(doc: dict, key: str, where: str, kind: type) -> Any:
    value = doc.get(key, kind())
    if not isinstance(value, kind):
        raise _Error(f"{where}: {key}: must be a {'mapping' if kind is dict else 'list'}, got {value!r}")
    return value


def mjcf_hand_spec(doc: dict, path: Path, where: str) -> HandSpec:
    """The :class:`HandSpec` of a hand description ``doc`` (read from ``path``) naming an MJCF
    model; ValueError, one line naming the description, the field and the MJCF element, when
    the file is missing or MuJoCo refuses it, the palm body or a finger's joint does not
    exist, a joint is not a hinge, a collision geom is not a capsule, sphere or box, or a
    joint of the palm's subtree belongs to no finger and is neither fixed nor coupled."""
    unknown = [k for k in doc if k not in _KEYS]
    if unknown:
        raise _Error(f"{where}: unknown key(s) {unknown}; allowed keys: {list(_KEYS)}")
    fmt = "urdf" if "urdf" in doc else "mjcf"  # MuJoCo's compiler reads both
    if "urdf" in doc and "mjcf" in doc:
        raise _Error(f"{where}: mjcf, urdf: give one model, not both")
    xml = Path(path).parent / str(doc[fmt])
    if xml.is_dir():
        raise _Error(f"{where}: {fmt}: '{xml}' is a folder; give the model's file")
    if not xml.is_file():
        raise _Error(f"{where}: {fmt}: file '{xml}' does not exist")
    fit_meshes = doc.get("fit_meshes", False)
    if not isinstance(fit_meshes, bool):
        raise _Error(f"{where}: fit_meshes: must be true or false, got {fit_meshes!r}")
    try:
        m = _Model(compile_mjcf(xml), where, xml.name, fit_meshes)
    except ValueError as err:  # MuJoCo's compiler error: its first line names the element
        raise _Error(f"{where}: {fmt}: MuJoCo cannot compile '{xml}': {str(err).splitlines()[0]}") from None
    model = m.model
    palm = m.find("body", doc.get("palm"), "palm")
    fixed = _names(doc, "fixed_joints", where, dict)
    couplings = _equality_couplings(m, palm, _names(doc, "couplings", where, dict))
    ignored = {m.find("geom", g, "ignore_geoms") for g in _names(doc, "ignore_geoms", where, list)}
    for name in fixed:
        _hinge_joint(m, m.find("joint", name, f"fixed_joints.{name}"), f"fixed_joints.{name}")
    chains = _chains(m, doc, palm)
    owner = _link_owner(m, palm, chains, fixed, couplings)
    frame = _palm_frame(doc, where)
    body_pose = _body_poses(m, palm, fixed, frame)
    joint_frames = {
        j: body_pose[model.jnt_bodyid[j]] @ pose_matrix(model.jnt_pos[j] * MM_PER_M)
        for chain in chains.values()
        for j, _ in chain
    }
    shapes: dict[int, list[Shape]] = {-1: []}
    for geom in range(model.ngeom):
        body = int(model.geom_bodyid[geom])
        if body not in owner or geom in ignored or (model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0):
            continue  # outside the hand, left out, or a visual geom
        link = owner[body]
        base = np.eye(4) if link < 0 else joint_frames[link]
        shapes.setdefault(link, []).append(
            _geom_shape(m, geom, np.linalg.inv(base) @ body_pose[body] @ _geom_pose(model, geom), link < 0)
        )
    fingers = tuple(_finger(m, doc["fingers"][f], f, chains[f], joint_frames, shapes, couplings, body_pose) for f in FINGERS)
    return HandSpec(
        str(doc.get("name", xml.stem)),
        np.array([1.0, 0.0, 0.0]),
        tuple(shapes[-1]),
        fingers,
        (),
        shapeless_links=True,
        ignored_pairs=_excluded_pairs(m, owner, chains),
    )


def _equality_couplings(m: _Model, palm: int, couplings: dict) -> dict:
    """The description's ``couplings`` and the model's active joint equalities of joints
    below the palm, ``joint1 = c1 × joint2`` (polycoef c0 = c2 = c3 = c4 = 0), as entries
    ``{follows: joint2, ratio: c1}``; a joint coupled by both, or a non-linear equality,
    refused in one line."""
    model = m.model
    out = dict(couplings)
    for eq in range(model.neq):
        if int(model.eq_type[eq]) != _EQ_JOINT or not model.eq_active0[eq]:
            continue
        joint, master = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
        if not _descends(model, int(model.jnt_bodyid[joint]), palm, strictly=True):
            continue  # a joint outside the hand (an arm's)
        name = model.joint(joint).name
        coef = [float(c) for c in model.eq_data[eq][:5]]
        field = f"equality {model.eq(eq).name or f'#{eq}'!r} in '{m.xml}'"
        if master < 0 or coef[0] != 0.0 or any(c != 0.0 for c in coef[2:]) or coef[1] == 0.0:
            raise _Error(
                f"{m.where}: {field}: joint {name!r} is held by polycoef {coef}; only a coupling "
                "joint1 = c1 × joint2 (polycoef 0 c1 0 0 0) is read"
            )
        if name in out:
            raise _Error(f"{m.where}: couplings.{name}: joint {name!r} is coupled by {field} already")
        out[name] = {"follows": model.joint(master).name, "ratio": coef[1]}
    return out


def _excluded_pairs(m: _Model, owner: dict[int, int], chains: dict) -> tuple[tuple[str, str], ...]:
    """The model's contact exclusions (``<contact><exclude body1 body2>``) between bodies of the
    hand, as pairs of the project's link names (the palm: ``palm``): not self-contacts."""
    model = m.model
    link = {j: entry["link"] for chain in chains.values() for j, entry in chain}
    link[-1] = "palm"
    pairs = set()
    for signature in model.exclude_signature[: model.nexclude]:
        a, b = int(signature) >> 16, int(signature) & 0xFFFF
        if a in owner and b in owner and owner[a] != owner[b]:
            pairs.add(tuple(sorted((link[owner[a]], link[owner[b]]))))
    return tuple(sorted(pairs))


def _hinge_joint(m: _Model, joint: int, field: str) -> None:
    kind = int(m.model.jnt_type[joint])
    if kind != 3:
        raise _Error(
            f"{m.where}: {field}: joint {m.model.joint(joint).name!r} in '{m.xml}' is a "
            f"{_JOINT_TYPES.get(kind, kind)} joint; the hand model has hinge joints only"
        )


def _chains(m: _Model, doc: dict, palm: int) -> dict[str, list[tuple[int, dict]]]:
    """Per finger, its chain's joints (MuJoCo index, entry), proximal to distal: each joint a
    hinge in the subtree of the previous one's body (the first: of the palm)."""
    fingers = doc.get("fingers")
    if not isinstance(fingers, dict) or sorted(fingers) != sorted(FINGERS):
        raise _Error(
            f"{m.where}: fingers: must have exactly the keys {FINGERS}, got "
            f"{list(fingers) if isinstance(fingers, dict) else fingers!r}"
        )
    chains = {}
    for finger in FINGERS:
        node = fingers[finger]
        field = f"fingers.{finger}"
        if not isinstance(node, dict) or [k for k in node if k not in _FINGER_KEYS]:
            raise _Error(f"{m.where}: {field}: must be a mapping with the keys {list(_FINGER_KEYS)}")
        entries = node.get("joints")
        if not isinstance(entries, list) or not entries:
            raise _Error(f"{m.where}: {field}.joints: must be a non-empty list of {{mjcf, name, link}}")
        chain, above = [], palm
        for i, entry in enumerate(entries):
            f = f"{field}.joints[{i}]"
            if not isinstance(entry, dict) or [k for k in entry if k not in _CHAIN_KEYS] or "mjcf" not in entry:
                raise _Error(
                    f"{m.where}: {f}: must be a mapping with mjcf (a joint), link, and name "
                    f"unless the joint is coupled; allowed keys {list(_CHAIN_KEYS)}"
                )
            joint = m.find("joint", entry["mjcf"], f"{f}.mjcf")
            _hinge_joint(m, joint, f"{f}.mjcf")
            body = int(m.model.jnt_bodyid[joint])
            if not _descends(m.model, body, above, strictly=True):  # a joint of the palm body moves the palm
                raise _Error(
                    f"{m.where}: {f}.mjcf: joint {entry['mjcf']!r} (body {m.model.body(body).name!r}) "
                    f"does not continue the chain: not below body {m.model.body(above).name!r} in '{m.xml}'"
                )
            link = entry.get("link")
            if not isinstance(link, str) or not link.startswith(f"{finger}_"):
                raise _Error(f"{m.where}: {f}.link: must be a link name starting with '{finger}_', got {link!r}")
            chain.append((joint, entry))
            above = body
        chains[finger] = chain
    return chains


def _descends(model: Any, body: int, ancestor: int, strictly: bool) -> bool:
    if strictly and body == ancestor:
        return False
    while body != ancestor and body > 0:
        body = int(model.body_parentid[body])
    return body == ancestor


def _subtree(model: Any, root: int) -> list[int]:
    return [b for b in range(model.nbody) if _descends(model, b, root, strictly=False)]


def _link_owner(m: _Model, palm: int, chains: dict, fixed: dict, couplings: dict) -> dict[int, int]:
    """Per body of the palm's subtree, the MuJoCo joint whose link it is part of (−1: the
    palm): the nearest moving joint on its way to the palm. Every joint of the subtree must be
    a hinge, and in a finger chain or fixed; every coupled joint in a chain."""
    model = m.model
    in_chain = {j for chain in chains.values() for j, _ in chain}
    for name in couplings:
        j = m.find("joint", name, f"couplings.{name}")
        if j not in in_chain:
            raise _Error(f"{m.where}: couplings.{name}: joint {name!r} is in no finger's joints")
    owner: dict[int, int] = {}
    for body in _subtree(model, palm):  # MuJoCo numbers a parent before its children
        joints = [j for j in range(model.njnt) if model.jnt_bodyid[j] == body and body != palm]
        moving = []
        for j in joints:
            name = model.joint(j).name
            _hinge_joint(m, j, f"joint {name!r}")
            if j in in_chain:
                moving.append(j)
            elif name not in fixed:
                raise _Error(
                    f"{m.where}: fingers: joint {name!r} (body {model.body(body).name!r}) in '{m.xml}' "
                    "is below the palm but in no finger's joints, fixed_joints or couplings"
                )
        if len(moving) > 1:
            raise _Error(
                f"{m.where}: fingers: body {model.body(body).name!r} in '{m.xml}' has {len(moving)} "
                "moving joints; one per body is supported"
            )
        owner[body] = moving[0] if moving else (-1 if body == palm else owner[int(model.body_parentid[body])])
    return owner


def _body_poses(m: _Model, palm: int, fixed: dict, frame: NDArray) -> dict[int, NDArray]:
    """Pose (4 × 4, mm) of every body of the palm's subtree in the project's palm frame, moving
    joints at zero and fixed joints at their given angles (rad)."""
    model = m.model
    poses = {palm: np.linalg.inv(frame)}
    for body in _subtree(model, palm):
        if body == palm:
            continue
        pose = poses[int(model.body_parentid[body])] @ _local(model, body)
        for j in range(model.njnt):
            name = model.joint(j).name
            if model.jnt_bodyid[j] == body and name in fixed:
                value = fixed[name]
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise _Error(f"{m.where}: fixed_joints.{name}: must be an angle in rad, got {value!r}")
                pose = pose @ _hinge(model, j, float(value))
        poses[body] = pose
    return poses


def _finger(
    m: _Model, node: dict, finger: str, chain: list, joint_frames: dict, shapes: dict, couplings: dict, body_pose: dict
) -> FingerSpec:
    """A finger's :class:`FingerSpec`: one joint per chain entry, its frame at the MuJoCo
    joint's anchor with its body's orientation (the hinge axis in the body's frame)."""
    model = m.model
    joints, parent = [], np.eye(4)
    names: dict[int, str] = {}
    for i, (j, entry) in enumerate(chain):
        field = f"fingers.{finger}.joints[{i}]"
        axis = model.jnt_axis[j] / np.linalg.norm(model.jnt_axis[j])
        coupling = couplings.get(model.joint(j).name)
        sign = _scale(m, entry, field) if coupling is None else 1.0
        lower, upper = sorted(float(v) / sign + 0.0 for v in model.jnt_range[j])  # a follower: its MuJoCo range
        follows, scale = "", sign
        if coupling is not None:
            follows, scale = _coupling(m, coupling, model.joint(j).name, chain[:i], names)
        elif not isinstance(entry.get("name"), str):
            raise _Error(f"{m.where}: {field}.name: the project's name of joint {entry['mjcf']!r} is missing")
        else:
            names[j] = entry["name"]
        if not model.jnt_limited[j]:
            lower, upper = -math.pi, math.pi
        joints.append(
            JointSpec(
                entry.get("name", model.joint(j).name) if not follows else model.joint(j).name,
                axis,
                np.linalg.inv(parent) @ joint_frames[j],
                0.0,
                lower,
                upper,
                entry["link"],
                tuple(shapes.get(j, ())),
                scale,
                follows,
            )
        )
        parent = joint_frames[j]
    joints = _limit_masters(joints)
    distal = chain[-1][0]
    if "tip_mm" in node:  # a point in the last body's frame (URDF has no sites)
        point, body = _vector_mm(m, node["tip_mm"], f"fingers.{finger}.tip_mm"), int(model.jnt_bodyid[distal])
    else:
        site = m.find("site", node.get("tip_site"), f"fingers.{finger}.tip_site")
        point, body = model.site_pos[site] * MM_PER_M, int(model.site_bodyid[site])
        if not _descends(model, body, int(model.jnt_bodyid[distal]), strictly=False):
            raise _Error(f"{m.where}: fingers.{finger}.tip_site: site {node['tip_site']!r} is not on the chain's last body")
    tip = np.linalg.inv(joint_frames[distal]) @ body_pose[body] @ np.append(point, 1.0)
    return FingerSpec(finger, tip[:3], tuple(joints))


def _vector_mm(m: _Model, value: Any, field: str) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise _Error(f"{m.where}: {field}: must be a list of 3 numbers (mm), got {value!r}")
    return arr


def _scale(m: _Model, entry: dict, field: str) -> float:
    """The MuJoCo angle per unit of the project's q of a chain entry: ``scale`` (default 1),
    negated by ``reverse``."""
    scale = entry.get("scale", 1.0)
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) or scale == 0:
        raise _Error(f"{m.where}: {field}.scale: must be a non-zero number, got {scale!r}")
    return -float(scale) if entry.get("reverse", False) else float(scale)


def _coupling(m: _Model, coupling: Any, name: str, earlier: list, names: dict) -> tuple[str, float]:
    """(the project's name of the followed joint, ratio) of a ``couplings`` entry."""
    field = f"couplings.{name}"
    if not isinstance(coupling, dict) or sorted(coupling) != ["follows", "ratio"]:
        raise _Error(f"{m.where}: {field}: must be {{follows: <MJCF joint>, ratio: <number>}}, got {coupling!r}")
    master = m.find("joint", coupling["follows"], f"{field}.follows")
    if master not in [j for j, _ in earlier] or master not in names:
        raise _Error(f"{m.where}: {field}.follows: {coupling['follows']!r} is not an earlier, uncoupled joint of the same finger")
    ratio = coupling["ratio"]
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not math.isfinite(ratio) or ratio == 0:
        raise _Error(f"{m.where}: {field}.ratio: must be a non-zero number, got {ratio!r}")
    return names[master], float(ratio) * _scale(m, dict(earlier)[master], field)


def _limit_masters(joints: list[JointSpec]) -> list[JointSpec]:
    """A joint followed by a coupled one keeps the coupled joint inside its range too: its
    range narrowed to where scale × q stays within the follower's (rad)."""
    out = list(joints)
    for follower in joints:
        if not follower.follows:
            continue
        k = next(i for i, j in enumerate(out) if j.name == follower.follows and not j.follows)
        master = out[k]
        ends = sorted(v / follower.scale for v in (follower.lower_rad, follower.upper_rad))
        lower, upper = max(master.lower_rad, ends[0]), min(master.upper_rad, ends[1])
        out[k] = JointSpec(
            master.name, master.axis, master.offset, 0.0, lower, upper, master.link, master.shapes, master.scale, ""
        )
    return out
