"""All pybullet-specific code for the hand and the objects.

pybullet works in metres; every function here takes and returns mm (and the palm frame).
The hand's base (its palm) is fixed at the world origin with identity orientation, so
pybullet's world frame *is* the palm frame, scaled by 1/1000.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, fields
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pybullet as pb
from numpy.typing import NDArray

from synergrasp.hand.kinematics import Hand, write_urdf

MM = 1e-3  # metres per mm


@dataclass(frozen=True)
class HandBody:
    """A hand loaded into pybullet.

    ``joint_indices[j]`` is the pybullet joint of elementary axis j, turning by
    ``joint_scale[j] * q[joint_q[j]]``; ``link_index[i]`` is the pybullet link of hand link i
    (-1 = the base, i.e. the palm); ``hand_link`` maps a pybullet link index back to a hand
    link index (base -1 -> 0 = palm). The shape-less links between the two half axes of a
    rolling joint have no hand link and never appear in collision results.
    """

    body: int
    hand: Hand
    joint_indices: NDArray[np.int64]
    joint_q: NDArray[np.int64]
    joint_scale: NDArray[np.float64]
    link_index: NDArray[np.int64]
    hand_link: dict[int, int]

    @cached_property
    def joint_list(self) -> list[int]:
        """``joint_indices`` as the list pybullet's calls take."""
        return self.joint_indices.tolist()


@dataclass(frozen=True)
class ClosestPoints:
    """Closest-point pairs between two bodies, mm, palm frame (m rows).

    ``link_a`` / ``link_b`` are hand link indices when the body is a HandBody, pybullet link
    indices otherwise (-1 = base). ``normal_on_b`` points from B toward A; ``distance`` is
    negative when the shapes overlap (penetration depth).
    """

    link_a: NDArray[np.int64]
    link_b: NDArray[np.int64]
    point_a: NDArray[np.float64]
    point_b: NDArray[np.float64]
    normal_on_b: NDArray[np.float64]
    distance: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.distance)


def connect() -> int:
    """A headless DIRECT pybullet client with deterministic settings (no gravity; never stepped)."""
    client = pb.connect(pb.DIRECT)
    pb.resetSimulation(physicsClientId=client)
    pb.setGravity(0, 0, 0, physicsClientId=client)
    pb.setPhysicsEngineParameter(deterministicOverlappingPairs=1, physicsClientId=client)
    return client


def disconnect(client: int) -> None:
    """Close a client made by ``connect``."""
    pb.disconnect(physicsClientId=client)


def set_posture(client: int, body: HandBody, q: NDArray) -> None:
    """Put the hand at joint angles q (19, rad) instantly (no dynamics)."""
    q = np.asarray(q, dtype=float)
    if q.shape != (body.hand.n_joints,):
        raise ValueError(f"q must have shape ({body.hand.n_joints},), got {q.shape}")
    values = body.joint_scale * q[body.joint_q]
    pb.resetJointStatesMultiDof(body.body, body.joint_indices.tolist(), [[float(v)] for v in values], physicsClientId=client)


def collision_shape(client: int, shape: Any) -> int:
    """The collision shape of an object's shape (``synergrasp.simulation.shapes``: its
    ``collision_geometry()``, mm) in ``client``; returns its index."""
    kind, geometry = shape.collision_geometry()
    if kind == "box":
        half = np.asarray(geometry["half_extents_mm"], dtype=float)
        return pb.createCollisionShape(pb.GEOM_BOX, halfExtents=(half * MM).tolist(), physicsClientId=client)
    if kind == "sphere":
        return pb.createCollisionShape(pb.GEOM_SPHERE, radius=float(geometry["radius_mm"]) * MM, physicsClientId=client)
    if kind == "cylinder":  # along the shape's own z axis, as pybullet's
        return pb.createCollisionShape(
            pb.GEOM_CYLINDER,
            radius=float(geometry["radius_mm"]) * MM,
            height=float(geometry["height_mm"]) * MM,
            physicsClientId=client,
        )
    if kind == "convex_parts":  # one convex hull per part (a file of several: the engine's compound)
        parts = geometry["parts_mm"]
        if len(parts) == 1:
            return pb.createCollisionShape(pb.GEOM_MESH, vertices=(parts[0] * MM).tolist(), physicsClientId=client)
        from synergrasp.simulation.shapes.convex_parts import bullet_file

        return pb.createCollisionShape(pb.GEOM_MESH, fileName=str(bullet_file(parts)), meshScale=[MM] * 3, physicsClientId=client)
    raise ValueError(f"no collision shape for a {kind!r}")


def _exact_surface(client: int, body: int, shape: Any) -> None:
    """No collision margin on a convex hull (the engine rounds one by 1 mm otherwise; its
    primitives keep their own surface): contacts lie on the shape's surface."""
    if shape.collision_geometry()[0] == "convex_parts":
        pb.changeDynamics(body, -1, collisionMargin=0.0, physicsClientId=client)


def move_body(client: int, body: int, center_mm: NDArray, rotation: NDArray | None = None) -> None:
    """Place a (box) body's base at ``center_mm`` with orientation ``rotation`` (3 × 3), palm frame."""
    center = np.asarray(center_mm, dtype=float)
    if center.shape != (3,):
        raise ValueError(f"center_mm must be 3 numbers (mm), got {center_mm!r}")
    quat = _quaternion(np.eye(3) if rotation is None else np.asarray(rotation, dtype=float))
    pb.resetBasePositionAndOrientation(body, (center * MM).tolist(), quat, physicsClientId=client)


def remove_body(client: int, body: int) -> None:
    """Remove a body (e.g. a box) from the client."""
    pb.removeBody(body, physicsClientId=client)


def _quaternion(rotation: NDArray) -> list[float]:
    if rotation.shape != (3, 3) or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6):
        raise ValueError("rotation must be a 3 × 3 rotation matrix")
    from scipy.spatial.transform import Rotation  # scipy order (x, y, z, w) is pybullet's

    return Rotation.from_matrix(rotation).as_quat().tolist()


def _body_and_link(body: int | HandBody, link: int | None) -> tuple[int, int | None]:
    if isinstance(body, HandBody):
        if link is None:
            return body.body, None
        if not 0 <= link < body.hand.n_links:
            raise ValueError(f"link must be a hand link index 0 ... {body.hand.n_links - 1}, got {link!r}")
        return body.body, int(body.link_index[link])
    return body, link


def _to_hand_links(body: int | HandBody, links: list[int]) -> NDArray[np.int64]:
    if isinstance(body, HandBody):
        return np.array([body.hand_link.get(b, -1) for b in links], dtype=np.int64)
    return np.array(links, dtype=np.int64)


def closest_points(
    client: int,
    body_a: int | HandBody,
    body_b: int | HandBody,
    distance_mm: float,
    link_a: int | None = None,
    link_b: int | None = None,
) -> ClosestPoints:
    """Closest points between A and B closer than ``distance_mm`` (all links unless given).

    A HandBody argument takes and returns hand link indices. With the object as A and the
    hand as B, ``normal_on_b`` is the object's inward normal (from the hand into the object)
    and ``point_a`` lies on the object's surface. Uses the current postures; no stepping.
    """
    a, la = _body_and_link(body_a, link_a)
    b, lb = _body_and_link(body_b, link_b)
    kwargs = {}
    if la is not None:
        kwargs["linkIndexA"] = la
    if lb is not None:
        kwargs["linkIndexB"] = lb
    pts = pb.getClosestPoints(a, b, float(distance_mm) * MM, physicsClientId=client, **kwargs)
    return _closest(body_a, body_b, pts)


def _closest(body_a: int | HandBody, body_b: int | HandBody, pts: list) -> ClosestPoints:
    if not pts:
        e = np.zeros((0, 3))
        return ClosestPoints(np.zeros(0, np.int64), np.zeros(0, np.int64), e, e.copy(), e.copy(), np.zeros(0))
    return ClosestPoints(
        link_a=_to_hand_links(body_a, [p[3] for p in pts]),
        link_b=_to_hand_links(body_b, [p[4] for p in pts]),
        point_a=np.array([p[5] for p in pts]) / MM,
        point_b=np.array([p[6] for p in pts]) / MM,
        normal_on_b=np.array([p[7] for p in pts]),
        distance=np.array([p[8] for p in pts]) / MM,
    )


def self_collision_pairs(hand: Hand, links: tuple[int, ...] | None = None) -> tuple[tuple[int, int], ...]:
    """Pairs (i < j) of hand links to test against each other: every pair except
    ``hand.ignored_link_pairs`` (parent/child links that touch by design). With ``links``,
    only pairs with at least one link from that set."""
    ignored = set(hand.ignored_link_pairs)
    keep = None if links is None else set(links)
    shaped = [i for i in range(hand.n_links) if i not in hand.shapeless_links]  # a link without shape touches nothing
    return tuple(
        (i, j) for i in shaped for j in shaped if i < j and (i, j) not in ignored and (keep is None or i in keep or j in keep)
    )


def self_closest_points(
    client: int, body: HandBody, distance_mm: float, pairs: tuple[tuple[int, int], ...] | None = None
) -> ClosestPoints:
    """Closest points between pairs of hand links (default ``self_collision_pairs``), mm.

    ``link_a`` / ``link_b`` are hand link indices; distances < 0 are overlaps.
    """
    pairs = self_collision_pairs(body.hand) if pairs is None else pairs
    pts: list = []
    for i, j in pairs:
        pts.extend(
            pb.getClosestPoints(
                body.body,
                body.body,
                float(distance_mm) * MM,
                linkIndexA=int(body.link_index[i]),
                linkIndexB=int(body.link_index[j]),
                physicsClientId=client,
            )
        )
    return _closest(body, body, pts)


# --------------------------------------------------------------------------------------
# Dynamics: the compliant hand and a free box (synergrasp.simulation.dynamic_closure)
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ContactForces(ClosestPoints):
    """Contact points of the last physics step between two bodies (m rows), mm, N, palm frame.

    Fields as in :class:`ClosestPoints`; ``normal_force`` is the constraint force along
    ``normal_on_b`` (N, ≥ 0).
    """

    normal_force: NDArray[np.float64]


def load_compliant_hand(client: int, hand: Hand, link_mass_kg: float, link_inertia_kg_mm2: float, friction: float) -> HandBody:
    """Load ``hand`` for dynamics: fixed palm at the origin, self-collision possible (choose the
    pairs with ``set_self_collision``), every elementary link
    with mass ``link_mass_kg`` and inertia ``link_inertia_kg_mm2`` (kg·mm², about its own
    frame), lateral friction ``friction``, no Bullet damping, joint motors released."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "hand.urdf"
        write_urdf(hand, path)
        uid = pb.loadURDF(
            str(path),
            basePosition=[0, 0, 0],
            baseOrientation=[0, 0, 0, 1],
            useFixedBase=True,
            flags=pb.URDF_USE_INERTIA_FROM_FILE | pb.URDF_USE_SELF_COLLISION,
            physicsClientId=client,
        )
    body = _hand_body(client, uid, hand)
    n = pb.getNumJoints(uid, physicsClientId=client)
    inertia = link_inertia_kg_mm2 * MM * MM
    for link in range(-1, n):
        pb.changeDynamics(
            uid,
            link,
            lateralFriction=float(friction),
            linearDamping=0.0,
            angularDamping=0.0,
            jointDamping=0.0,
            physicsClientId=client,
        )
        if link >= 0:
            pb.changeDynamics(uid, link, mass=float(link_mass_kg), localInertiaDiagonal=[inertia] * 3, physicsClientId=client)
    pb.setJointMotorControlArray(uid, list(range(n)), pb.VELOCITY_CONTROL, forces=[0.0] * n, physicsClientId=client)
    return body


def set_self_collision(client: int, body: HandBody, pairs: tuple[tuple[int, int], ...]) -> None:
    """Exactly the hand link pairs ``pairs`` (hand link indices) collide with each other during
    dynamics (the hand must come from ``load_compliant_hand``)."""
    wanted = {(min(i, j), max(i, j)) for i, j in pairs}
    n = body.hand.n_links
    for i in range(n):
        for j in range(i + 1, n):
            pb.setCollisionFilterPair(
                body.body,
                body.body,
                int(body.link_index[i]),
                int(body.link_index[j]),
                int((i, j) in wanted),
                physicsClientId=client,
            )


def _hand_body(client: int, uid: int, hand: Hand) -> HandBody:
    by_joint_name: dict[str, int] = {}
    by_link_name: dict[str, int] = {}
    for j in range(pb.getNumJoints(uid, physicsClientId=client)):
        info = pb.getJointInfo(uid, j, physicsClientId=client)
        by_joint_name[info[1].decode()] = j
        by_link_name[info[12].decode()] = j
    joint_indices = np.array([by_joint_name[hand.frame_joint_names[f]] for f in range(1, len(hand.frame_names))])
    link_index = np.array([-1] + [by_link_name[name] for name in hand.link_names[1:]])
    return HandBody(
        body=uid,
        hand=hand,
        joint_indices=joint_indices,
        joint_q=hand.frame_joint[1:].copy(),
        joint_scale=hand.frame_scale[1:].copy(),
        link_index=link_index,
        hand_link={int(b): i for i, b in enumerate(link_index)},
    )


def set_dynamics(client: int, time_step_s: float, solver_iterations: int) -> None:
    """Time step (s) and constraint-solver iterations of the client; no gravity (a body's weight
    is applied as an explicit force, ``apply_force``)."""
    pb.setGravity(0.0, 0.0, 0.0, physicsClientId=client)
    pb.setPhysicsEngineParameter(
        fixedTimeStep=float(time_step_s),
        numSolverIterations=int(solver_iterations),
        numSubSteps=0,
        deterministicOverlappingPairs=1,
        physicsClientId=client,
    )


def apply_force(client: int, body: int, force_N: NDArray) -> None:
    """Apply ``force_N`` (N, palm frame) at a body's centre of mass during the next step."""
    pos, _ = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    pb.applyExternalForce(body, -1, [float(v) for v in force_N], pos, pb.WORLD_FRAME, physicsClientId=client)


def load_free_object(client: int, shape: Any, mass_kg: float, friction: float, damping_per_s: float) -> int:
    """A free (dynamic) body of ``shape`` (``synergrasp.simulation.shapes``) and mass
    ``mass_kg``, uniform density (the engine's inertia of the shape), lateral friction
    ``friction``, linear and angular drag at the rate ``damping_per_s`` (1/s); with ``mass_kg``
    = 0 a fixed body (Bullet's static body: it never moves, what touches it slides on it with
    the same friction). Place it with ``move_body``; returns its body id."""
    if not mass_kg >= 0:
        raise ValueError(f"mass_kg must be >= 0 (0: a fixed body), got {mass_kg!r}")
    body = pb.createMultiBody(
        baseMass=float(mass_kg), baseCollisionShapeIndex=collision_shape(client, shape), physicsClientId=client
    )
    pb.changeDynamics(
        body,
        -1,
        lateralFriction=float(friction),
        linearDamping=float(damping_per_s),
        angularDamping=float(damping_per_s),
        physicsClientId=client,
    )
    _exact_surface(client, body, shape)
    return body


def reset_hand(client: int, body: HandBody, q: NDArray) -> None:
    """Put the hand at joint angles q (19, rad) at rest (zero joint velocities)."""
    q = np.asarray(q, dtype=float)
    values = body.joint_scale * q[body.joint_q]
    pb.resetJointStatesMultiDof(
        body.body,
        body.joint_indices.tolist(),
        [[float(v)] for v in values],
        targetVelocities=[[0.0]] * len(values),
        physicsClientId=client,
    )


def reset_body(client: int, body: int, center_mm: NDArray, rotation: NDArray) -> None:
    """Place a free body at ``center_mm`` with orientation ``rotation`` (3 × 3), at rest."""
    move_body(client, body, center_mm, rotation)
    pb.resetBaseVelocity(body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], physicsClientId=client)


def axis_states(client: int, body: HandBody) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Angles (rad) and angular velocities (rad/s) of every elementary axis, HandBody order."""
    states = pb.getJointStates(body.body, body.joint_list, physicsClientId=client)
    return np.array([s[0] for s in states]), np.array([s[1] for s in states])


def body_pose(client: int, body: int) -> tuple[NDArray, NDArray]:
    """Centre (mm) and rotation (3 × 3) of a body."""
    pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    return np.array(pos) / MM, np.array(pb.getMatrixFromQuaternion(quat)).reshape(3, 3)


def body_state(client: int, body: int) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Centre (mm), rotation (3 × 3), linear velocity (mm/s) and angular velocity (rad/s) of a body."""
    pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    lin, ang = pb.getBaseVelocity(body, physicsClientId=client)
    rotation = np.array(pb.getMatrixFromQuaternion(quat)).reshape(3, 3)
    return np.array(pos) / MM, rotation, np.array(lin) / MM, np.array(ang)


def contact_forces(client: int, body_a: int | HandBody, body_b: HandBody) -> ContactForces:
    """The contact points of the last step between body A and the hand B, with normal forces (N).
    With the hand as A too: its contacts with itself (both link columns are hand links)."""
    a = body_a.body if isinstance(body_a, HandBody) else body_a
    pts = pb.getContactPoints(a, body_b.body, physicsClientId=client)
    closest = _closest(body_a, body_b, pts)  # the shared fields, read the same way
    shared = {f.name: getattr(closest, f.name) for f in fields(ClosestPoints)}
    return ContactForces(**shared, normal_force=np.array([p[9] for p in pts], dtype=float).reshape(-1))


def tick_with_torques(client: int, body: HandBody, torques_Nmm: NDArray) -> None:
    """Apply ``torques_Nmm`` (N·mm, one per elementary axis, HandBody order) and take one step."""
    pb.setJointMotorControlArray(
        body.body,
        body.joint_list,
        pb.TORQUE_CONTROL,
        forces=(np.asarray(torques_Nmm, dtype=float) * MM).tolist(),
        physicsClientId=client,
    )
    pb.stepSimulation(physicsClientId=client)
