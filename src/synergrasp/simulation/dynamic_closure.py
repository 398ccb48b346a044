"""The compliant dynamic closure: the soft-synergy hand closing on a free box (pybullet).

The second closure model (``closure.model: dynamic``, docs/closure.md). Same inputs as the
kinematic closure (hand, synergies, box, the placed object pose, the σ path) and the same
result type. The 19 joints are springs of stiffness k_ss (N·mm/rad) about the synergy
reference q_r(σ) = clip(q_m + σ·S1, lower, upper), realised as explicit joint torques on the
elementary axes: axis i (scale s_i: 1, or 1/2 for each half of a rolling joint) gets
(k_ss/s_i)·(s_i·q_r − θ_i) − c·θ̇_i. The two half axes of a rolling joint are thus two
springs in series (2·k_ss each about q_r/2): the joint's stiffness is k_ss and at rest
k_ss·(q_r − q) = J_qᵀ f with q = θ_a + θ_b and J_q = (J_a + J_b)/2, exactly the soft-synergy
balance. (A gear constraint that would keep the halves equal is not usable on this
multibody in pybullet 3.2.7: with several of them the joints leave their limits; under load
the halves therefore differ by (J_b − J_a)ᵀ f / (2·k_ss), reported in docs/closure.md.)
σ ramps over the path; the box is a free rigid body with friction μ against the hand. The
run ends when hand and box have settled (no joint and no point of the box moved by more than
a threshold over the last ``settle_window_s``) or at the time limit.

The dynamics are only the way to that equilibrium: link inertias, joint damping, time
step, ramp time and the box's mass during the closure are chosen for speed (DynamicParams), and
gravity is off by default. Units: mm, rad, N, N·mm, s; the palm frame. pybullet calls go
through :mod:`synergrasp.simulation.bullet`.
"""

from __future__ import annotations

import math
from collections import deque
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.synergies import SynergyPath
from synergrasp.simulation.capsules import HandCapsules
from synergrasp.simulation.contacts import ClosureResult
from synergrasp.simulation.placement import ObjectPose

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.closure_params import ClosureMechanics, ClosureParams
    from synergrasp.simulation.shapes import Shape

__all__ = ["DynamicClosure", "compliant_self_pairs"]

_LONG_FINGERS = ("index", "middle", "ring", "little")


def compliant_self_pairs(hand: Any) -> tuple[tuple[int, int], ...]:
    """Hand link pairs that collide during the dynamic closure: the pairs that can meet, i.e. a
    finger link against the palm, the thumb against a long finger, and neighbouring long
    fingers (index–middle, middle–ring, ring–little); never links of one finger, never
    ``hand.ignored_link_pairs`` (parent and child touch by design)."""
    from synergrasp.simulation.bullet import self_collision_pairs

    pairs = []
    for i, j in self_collision_pairs(hand):
        fi, fj = hand.link_finger[i], hand.link_finger[j]
        if fi == fj:
            continue
        if fi in _LONG_FINGERS and fj in _LONG_FINGERS and abs(_LONG_FINGERS.index(fi) - _LONG_FINGERS.index(fj)) != 1:
            continue
        pairs.append((i, j))
    return tuple(pairs)


class DynamicClosure:
    """The compliant dynamic closure on one pybullet scene: the hand and a free box.

    ``params`` is the closure's :class:`synergrasp.simulation.closure.ClosureParams` (contact
    distance, penetration tolerance, ``params.dynamic``); the σ path is the kinematic
    model's (``SynergyPath.closure_range``); ``mechanics`` the :class:`ClosureMechanics` (k_ss,
    μ, gravity direction); ``weight_N`` the box's weight m·g, N (``synergrasp.resolved``;
    applied if gravity is on).
    """

    def __init__(
        self, hand: Hand, synergies: Synergies, params: ClosureParams, mechanics: ClosureMechanics, weight_N: float
    ) -> None:
        from synergrasp.simulation import bullet

        names = tuple(synergies.joint_names)
        if names != tuple(hand.joint_names):
            raise ValueError(f"synergies.joint_names must equal hand.joint_names {hand.joint_names}, got {names}")
        self.bullet = bullet
        self.hand = hand
        self.closure = params
        self.params = p = params.dynamic
        self.k_ss = mechanics.k_ss_Nmm_per_rad
        self.mu = mechanics.mu
        down = np.asarray(mechanics.gravity_direction, dtype=float)
        # weight of the box, N (palm frame), applied only when params.dynamic.gravity is true
        self.weight = float(weight_N) * down / np.linalg.norm(down)
        self.path = SynergyPath.along(synergies, hand.lower, hand.upper)
        # the same path as the kinematic model: fully open hand to every S1 joint at a limit
        self.sigma_open, self.sigma_closed = self.path.closure_range(hand.flexion_joints)
        self.client = bullet.connect()
        bullet.set_dynamics(self.client, p.time_step_s, p.solver_iterations)
        # hand–hand friction = product of the two links' coefficients (Bullet's rule): √μ_hh on
        # every hand link; the box's coefficient μ/√μ_hh makes hand–box friction exactly μ
        self.link_friction = math.sqrt(p.hand_hand_mu)
        self.body = bullet.load_compliant_hand(self.client, hand, p.link_mass_kg, p.link_inertia_kg_mm2, self.link_friction)
        self.axis_joint = self.body.joint_q
        self.axis_scale = self.body.joint_scale
        self.axis_sum = np.zeros((hand.n_joints, len(self.axis_joint)))  # q = axis_sum @ θ
        self.axis_sum[self.axis_joint, np.arange(len(self.axis_joint))] = 1.0
        self.q_open = self.path.reference(self.sigma_open)
        # the axes' targets s_i·q_r(σ) after each tick (time step) of the σ ramp, the same for every grasp
        ramp = p.ramp_ticks
        sigmas = [self.sigma_open + (self.sigma_closed - self.sigma_open) * (tick + 1) / ramp for tick in range(ramp)]
        self.ramp_targets = self.axis_scale * self.path.reference(np.array(sigmas))[:, self.axis_joint]
        self.self_pairs = self._colliding_pairs()
        self.capsules = HandCapsules.of(hand)
        self.box: int | None = None  # the object's body
        self.shape: Shape | None = None

    @property
    def model_name(self) -> str:
        """The contacts table's ``closure_model``: ``dynamic`` (free box) or ``dynamic_held``."""
        return "dynamic_held" if self.params.held else "dynamic"

    def close(self) -> None:
        self.bullet.disconnect(self.client)

    def joint_values(self, axis_values: NDArray) -> NDArray:
        """Joint angles (rad) from the elementary axes' angles: q_j = Σ θ_i over the axes of joint j."""
        return self.axis_sum @ axis_values

    def _place(self, placed: ObjectPose) -> None:
        if self.box is None or self.shape != placed.shape:
            if self.box is not None:
                self.bullet.remove_body(self.client, self.box)
            mass = 0.0 if self.params.held else self.params.object_mass_kg  # mass 0: a fixed body
            self.box = self.bullet.load_free_object(
                self.client, placed.shape, mass, self.mu / self.link_friction, self.params.object_damping_per_s
            )
            self.shape = placed.shape
        self.bullet.reset_body(self.client, self.box, placed.center_mm, placed.rotation)

    def _colliding_pairs(self) -> tuple[tuple[int, int], ...]:
        """``compliant_self_pairs`` except those overlapping at the open posture (a property of
        the model, not an event); set them in the engine."""
        b = self.bullet
        pairs = compliant_self_pairs(self.hand)
        b.reset_hand(self.client, self.body, self.q_open)
        pts = b.self_closest_points(self.client, self.body, 0.0, pairs)
        bad = {(min(i, j), max(i, j)) for i, j, d in zip(pts.link_a, pts.link_b, pts.distance) if d < 0}
        kept = tuple(pair for pair in pairs if pair not in bad)
        b.set_self_collision(self.client, self.body, kept)
        return kept

    def grasp(self, placed: ObjectPose) -> ClosureResult:
        """Close the hand from q_r(σ_open) to q_r(σ_closed) (the fully open hand to the end of
        S1) on the free object ``placed`` (its shape at its starting pose); the contacts of its
        settled state."""
        p, b, c = self.params, self.bullet, self.closure
        q_open = self.q_open
        self._place(placed)
        b.reset_hand(self.client, self.body, q_open)
        gaps = b.closest_points(self.client, self.box, self.body, c.contact_distance_mm)
        if len(gaps) and float(gaps.distance.min()) < -c.penetration_tolerance_mm:
            return self._result("intersects_open_hand", q_open, (), None, True)
        weight = self.weight if p.gravity and not p.held else None
        radius = placed.shape.bounding_radius_mm
        settled, ticks = False, p.max_ticks
        ramp, targets, window_ticks = p.ramp_ticks, self.ramp_targets, p.window_ticks
        axis_k = self.k_ss / self.axis_scale  # N·mm/rad per axis (2·k_ss for each half of a rolling joint)
        damping, client, body, box = p.joint_damping_Nmm_s_per_rad, self.client, self.body, self.box
        # settled by the change over a window, not by instantaneous speeds: the engine's
        # contacts jitter and creep (~1 mm/s) long after the grasp has formed
        window: deque = deque(maxlen=window_ticks + 1)
        for tick in range(p.max_ticks):
            theta, omega = b.axis_states(client, body)
            if tick < ramp:
                target = targets[tick]
            else:
                center, rotation = b.body_pose(client, box)
                window.append((self.axis_sum @ theta, center, rotation))
                if len(window) > window_ticks:
                    q0, c0, r0 = window[0]
                    turn = math.acos(min(1.0, max(-1.0, 0.5 * (float(np.sum(r0 * rotation)) - 1.0))))
                    if (
                        np.max(np.abs(window[-1][0] - q0)) < p.settle_joint_change_rad
                        and np.linalg.norm(center - c0) + turn * radius < p.settle_object_change_mm
                    ):
                        settled, ticks = True, tick
                        break
            if weight is not None:
                b.apply_force(client, box, weight)
            b.tick_with_torques(client, body, axis_k * (target - theta) - damping * omega)
        self.ticks = ticks
        return self._settled(placed, settled)

    def _result(
        self,
        status: str,
        q: NDArray,
        state: tuple[str, ...],
        settled_pose: ObjectPose | None,
        settled: bool,
        links: list[int] = (),
        points: list = (),
        normals: list = (),
        loads: list = (),
        depth: float = 0.0,
    ) -> ClosureResult:
        from synergrasp.hand.kinematics import contact_jacobian

        links_a = np.asarray(links, dtype=np.int64)
        points_a = np.asarray(points, dtype=float).reshape(-1, 3)
        jac = contact_jacobian(self.hand, q, links_a, points_a) if len(links_a) else np.zeros((0, self.hand.n_joints))
        return ClosureResult(
            status,
            q,
            state,
            links_a,
            points_a,
            np.asarray(normals, dtype=float).reshape(-1, 3),
            jac,
            float(depth),
            model=self.model_name,
            normal_force_N=np.asarray(loads, dtype=float),
            settled_pose=settled_pose,
            settled=settled,
        )

    def _finger_states(self, touching: list[int]) -> tuple[str, ...]:
        """Per finger: ``contact`` (a link touches the box), ``self`` (a link touches the hand), ``limit``."""
        on_hand = self.bullet.contact_forces(self.client, self.body, self.body)
        self_links = set(on_hand.link_a.tolist()) | set(on_hand.link_b.tolist())
        return tuple(
            "contact" if any(li in touching for li in links) else "self" if any(li in self_links for li in links) else "limit"
            for links in self.hand.finger_links
        )

    def _settled(self, placed: ObjectPose, settled: bool) -> ClosureResult:
        """The settled state: q, the box pose, one contact per hand link touching the box (the
        force-weighted mean of its engine contact points, projected onto the exact box)."""
        b, p = self.bullet, self.params
        theta, _ = b.axis_states(self.client, self.body)
        q = self.joint_values(theta)
        center, rotation, _, _ = b.body_state(self.client, self.box)
        now = ObjectPose(center, rotation, placed.shape)
        forces = b.contact_forces(self.client, self.box, self.body)
        near = b.closest_points(self.client, self.box, self.body, self.closure.contact_distance_mm)
        touching = sorted({int(v) for v in near.link_b if v >= 0})
        state = self._finger_states(touching)
        links, points, normals, loads, depth = [], [], [], [], 0.0
        for link in touching:
            rows = np.flatnonzero(forces.link_b == link)
            load = float(forces.normal_force[rows].sum()) if len(rows) else 0.0
            if load > 0.0:
                on_link = (forces.normal_force[rows] / load) @ forces.point_b[rows]
            else:
                k = np.flatnonzero(near.link_b == link)
                on_link = near.point_b[k[np.argmin(near.distance[k])]]
            point, normal = now.surface_point(on_link)
            links.append(link)
            points.append(point)
            normals.append(normal)
            loads.append(load)
            depth = max(depth, -float(near.distance[near.link_b == link].min()))
        if links:
            return self._result("grasp", q, state, now, settled, links, points, normals, loads, max(depth, 0.0))
        moved = float(np.linalg.norm(center - placed.center_mm))
        status = "no_contact"
        if moved > p.lost_distance_mm:  # moved by the hand, held by nothing: still inside it, or out
            status = "caged" if self.capsules.encloses(q, center) else "lost"
        return self._result(status, q, state, now, settled)
