"""The compliant dynamic closure: the soft-synergy hand closing on a free box (pybullet).

The second closure model (``closure.model: dynamic``, docs/closure.md). Same inputs as the
kinematic closure (hand, synergies, box, the placed object pose, the σ path) and the same
result type. The 19 joints are springs of stiffness k_ss (N·mm/rad) about the synergy
reference q_r(σ) = clip(q_m + σ·S1, lower, upper), realised with the engine's joint motors:
every elementary axis i (scale s_i: 1, or 1/2 for each half of a rolling joint) is driven
toward s_i·q_r by a position motor whose torque is capped at (k_ss/s_i)·|s_i·q_r − θ_i|.
A motor that cannot reach its target (a link blocked by the box or the hand) therefore
pushes with exactly the spring torque; a free joint follows the reference at the motor's
rate (implicit, so stable at any time step). The two half axes of a rolling joint are two
such springs in series (2·k_ss each about q_r/2): the joint's stiffness is k_ss and, at
rest, k_ss·(q_r − q) = J_qᵀ f with q = θ_a + θ_b; under load the halves differ by
(J_b − J_a)ᵀ f / (2·k_ss) (reported, docs/closure.md). σ ramps over the path; the box is
a free rigid body with friction μ against the hand. The run ends when hand and box have settled (every joint
speed and the box's speed below their thresholds for ``settle_steps`` consecutive steps) or
at the time limit. The settled state is the soft-synergy equilibrium
k_ss·(q_r − q) = Jᵀ f, f the forces the hand applies at its contacts.

The dynamics are only the way to that equilibrium: link inertias, motor gain, time step,
ramp time and the box's mass during the closure are chosen for speed (DynamicParams), and
gravity is off by default. Units: mm, rad, N, N·mm, s; the palm frame. pybullet calls go
through :mod:`synergrasp.simulation.bullet`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["UNLOADED_CONTACTS", "DynamicParams", "DynamicResult", "CompliantHand"]

#: What happens to a contact whose normal force at the settled state is below
#: ``DynamicParams.load_threshold_N``: ``drop`` (not listed) or ``keep`` (listed).
UNLOADED_CONTACTS: tuple[str, ...] = ("drop", "keep")
_LONG_FINGERS = ("index", "middle", "ring", "little")


@dataclass(frozen=True)
class DynamicParams:
    """Settings of the dynamic closure (config ``closure.dynamic``, docs/closure.md).

    time_step_s:           physics time step, s.
    solver_iterations:     constraint-solver iterations per step.
    link_mass_kg:          mass of every elementary hand link during the closure, kg.
    link_inertia_kg_mm2:   rotational inertia of every elementary hand link about its own
                           frame, kg·mm² (sets the fastest joint mode: √(k_ss / I)).
    position_gain:         motor gain: a free joint closes the fraction ``position_gain`` of
                           its distance to the reference per step.
    object_mass_kg:        mass of the box during the closure, kg (its weight, if gravity is
                           on, is still mass_kg · g: see ``gravity``).
    object_damping_per_s:  linear and angular drag rate of the box, 1/s.
    ramp_time_s:           time over which σ runs from the open to the closed end, s.
    time_limit_s:          the closure stops here if it has not settled, s.
    settle_joint_speed_rad_per_s, settle_object_speed_mm_per_s: settled when every joint
                           and every point of the box move slower than these ...
    settle_steps:          ... for this many consecutive steps after the ramp.
    hand_hand_mu:          friction between two hand links (hand–box friction is mechanics.mu).
    gravity:               the box's weight acts during the closure (along
                           mechanics.gravity_direction) if true.
    lost_distance_mm:      a box with no contact at the end that moved farther than this from
                           its initial pose was pushed out of the hand: status ``lost``.
    load_threshold_N:      a contact carries load if its normal force is at least this, N.
    unloaded_contacts:     ``drop`` or ``keep`` the contacts below the threshold.
    """

    time_step_s: float = 1.0 / 240.0
    solver_iterations: int = 10
    link_mass_kg: float = 0.001
    link_inertia_kg_mm2: float = 10.0
    joint_damping_Nmm_s_per_rad: float = 4.0
    object_mass_kg: float = 0.05
    object_damping_per_s: float = 20.0
    ramp_time_s: float = 0.25
    time_limit_s: float = 1.0
    settle_joint_speed_rad_per_s: float = 0.02
    settle_object_speed_mm_per_s: float = 1.0
    settle_steps: int = 5
    hand_hand_mu: float = 0.1
    gravity: bool = False
    lost_distance_mm: float = 1.0
    load_threshold_N: float = 0.01
    unloaded_contacts: str = "drop"

    def __post_init__(self) -> None:
        positive = ("time_step_s", "link_mass_kg", "link_inertia_kg_mm2", "joint_damping_Nmm_s_per_rad", "object_mass_kg",
                    "ramp_time_s", "time_limit_s", "settle_joint_speed_rad_per_s",
                    "settle_object_speed_mm_per_s", "hand_hand_mu", "lost_distance_mm")
        for name in positive:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ValueError(f"closure.dynamic.{name} must be a positive number, got {v!r}")
            object.__setattr__(self, name, float(v))
        for name in ("object_damping_per_s", "load_threshold_N"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"closure.dynamic.{name} must be a number >= 0, got {v!r}")
            object.__setattr__(self, name, float(v))
        for name in ("solver_iterations", "settle_steps"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"closure.dynamic.{name} must be an integer >= 1, got {v!r}")
        if not isinstance(self.gravity, bool):
            raise ValueError(f"closure.dynamic.gravity must be true or false, got {self.gravity!r}")
        if self.unloaded_contacts not in UNLOADED_CONTACTS:
            raise ValueError(f"closure.dynamic.unloaded_contacts must be one of {list(UNLOADED_CONTACTS)}, "
                             f"got {self.unloaded_contacts!r}")
        if self.time_limit_s < self.ramp_time_s:
            raise ValueError(f"closure.dynamic.time_limit_s ({self.time_limit_s}) must be at least "
                             f"closure.dynamic.ramp_time_s ({self.ramp_time_s})")

    @classmethod
    def from_config(cls, dynamic: Mapping[str, Any]) -> DynamicParams:
        """From the config's ``closure.dynamic`` block."""
        allowed = {f.name for f in fields(cls)}
        unknown = set(dynamic) - allowed
        if unknown:
            raise ValueError(f"closure.dynamic: unknown key(s) {sorted(unknown)}; allowed keys: {sorted(allowed)}")
        return cls(**dict(dynamic))

    @property
    def ramp_steps(self) -> int:
        return max(1, int(round(self.ramp_time_s / self.time_step_s)))

    @property
    def max_steps(self) -> int:
        return max(self.ramp_steps, int(round(self.time_limit_s / self.time_step_s)))


@dataclass(frozen=True)
class DynamicResult:
    """The settled state of one dynamic closure, palm frame.

    status:        ``grasp``, ``no_contact``, ``lost`` or ``intersects_open_hand``
    q:             (19,) settled joint angles, rad
    finger_state:  per finger: ``contact`` (a link touches the box), ``self`` (touches the
                   hand), ``limit`` (neither)
    links, points, normals, jacobian: the contacts, as the kinematic closure gives them
    forces_N:      (m,) normal force of each contact at the settled state, N
    max_penetration_mm: deepest penetration among the listed contacts
    center_mm, rotation: the box's settled pose
    settled:       False if the time limit ended the closure
    steps:         physics steps taken
    """

    status: str
    q: NDArray
    finger_state: tuple[str, ...]
    links: NDArray
    points: NDArray
    normals: NDArray
    jacobian: NDArray
    forces_N: NDArray
    max_penetration_mm: float
    center_mm: NDArray
    rotation: NDArray
    settled: bool
    steps: int


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


class CompliantHand:
    """One pybullet scene for the dynamic closure: the compliant hand and a free box.

    ``k_ss_Nmm_per_rad`` is the joint stiffness, ``mu`` the hand–box friction coefficient,
    ``gravity_mm_s2`` the gravity vector (palm frame, mm/s²) that acts on the box when
    ``params.gravity`` is true.
    """

    def __init__(self, hand: Any, synergies: Any, k_ss_Nmm_per_rad: float, mu: float, params: DynamicParams,
                 gravity_mm_s2: NDArray | None = None) -> None:
        from synergrasp.simulation import bullet

        names = tuple(synergies.joint_names)
        if names != tuple(hand.joint_names):
            raise ValueError(f"synergies.joint_names must equal hand.joint_names {hand.joint_names}, got {names}")
        if not k_ss_Nmm_per_rad > 0 or not mu > 0:
            raise ValueError(f"mechanics.k_ss_Nmm_per_rad and mechanics.mu must be > 0, got {k_ss_Nmm_per_rad}, {mu}")
        self.bullet = bullet
        self.hand = hand
        self.params = params
        self.k_ss = float(k_ss_Nmm_per_rad)
        self.mu = float(mu)
        self.gravity = np.zeros(3) if gravity_mm_s2 is None else np.asarray(gravity_mm_s2, dtype=float)
        self.mean = np.asarray(synergies.mean, dtype=float)
        self.s1 = np.asarray(synergies.matrix, dtype=float)[:, 0]
        self.client = bullet.connect()
        bullet.set_dynamics(self.client, params.time_step_s, params.solver_iterations)
        # hand–hand friction = product of the two links' coefficients (Bullet's rule): √μ_hh on
        # every hand link; the box's coefficient μ/√μ_hh makes hand–box friction exactly μ
        self.link_friction = math.sqrt(params.hand_hand_mu)
        self.self_pairs = compliant_self_pairs(hand)
        self.body = bullet.load_compliant_hand(self.client, hand, params.link_mass_kg,
                                               params.link_inertia_kg_mm2, self.link_friction)
        self.axis_joint = self.body.joint_q
        self.axis_scale = self.body.joint_scale
        self.axis_sum = np.zeros((hand.n_joints, len(self.axis_joint)))  # q = axis_sum @ θ
        self.axis_sum[self.axis_joint, np.arange(len(self.axis_joint))] = 1.0
        self.box: int | None = None
        self.box_size: NDArray | None = None

    def close(self) -> None:
        self.bullet.disconnect(self.client)

    def reference(self, sigma: float) -> NDArray:
        """q_r(σ) = clip(q_m + σ·S1, lower, upper), rad."""
        return np.clip(self.mean + sigma * self.s1, self.hand.lower, self.hand.upper)

    def joint_values(self, axis_values: NDArray) -> NDArray:
        """Joint angles (rad) from the elementary axes' angles: q_j = Σ θ_i over the axes of joint j."""
        return self.axis_sum @ axis_values

    def _place(self, size_mm: NDArray, placed: Any) -> None:
        size = np.asarray(size_mm, dtype=float)
        if self.box is None or self.box_size is None or not np.array_equal(size, self.box_size):
            if self.box is not None:
                self.bullet.remove_body(self.client, self.box)
            self.box = self.bullet.load_free_box(self.client, size, self.params.object_mass_kg,
                                                 self.mu / self.link_friction, self.params.object_damping_per_s)
            self.box_size = size
        self.bullet.reset_body(self.client, self.box, placed.center_mm, placed.rotation)

    def _exclude_open_overlaps(self, q_open: NDArray) -> None:
        """Collide the pairs of ``compliant_self_pairs`` except those overlapping at ``q_open``
        (a property of the model, not an event)."""
        b = self.bullet
        if getattr(self, "_q_open", None) is not None and np.array_equal(self._q_open, q_open):
            return
        b.reset_hand(self.client, self.body, q_open)
        pts = b.self_closest_points(self.client, self.body, 0.0, self.self_pairs)
        bad = {(min(i, j), max(i, j)) for i, j, d in zip(pts.link_a, pts.link_b, pts.distance) if d < 0}
        b.set_self_collision(self.client, self.body, tuple(p for p in self.self_pairs if p not in bad))
        self._q_open = q_open.copy()

    def run(self, size_mm: NDArray, mass_kg: float, placed: Any, sigma_open: float, sigma_closed: float,
            contact_distance_mm: float, penetration_tolerance_mm: float) -> DynamicResult:
        """Close the hand from q_r(σ_open) to q_r(σ_closed) on a free box of ``size_mm`` (mm) and
        ``mass_kg`` placed at ``placed`` (an ObjectPose); return its settled state."""
        p, b = self.params, self.bullet
        q_open = self.reference(sigma_open)
        self._exclude_open_overlaps(q_open)
        self._place(size_mm, placed)
        b.reset_hand(self.client, self.body, q_open)
        gaps = b.closest_points(self.client, self.box, self.body, contact_distance_mm)
        if len(gaps) and float(gaps.distance.min()) < -penetration_tolerance_mm:
            return self._empty("intersects_open_hand", q_open, (), placed.center_mm, placed.rotation, True, 0)
        weight = 1e-3 * float(mass_kg) * self.gravity if p.gravity else None  # N
        radius = float(np.linalg.norm(placed.half_extents_mm))
        calm, settled, steps = 0, False, p.max_steps
        scale, axis_joint = self.axis_scale, self.axis_joint
        target = scale * q_open[axis_joint]
        axis_k = self.k_ss / scale  # N·mm/rad per axis (2·k_ss for each half of a rolling joint)
        for step in range(p.max_steps):
            theta, omega = b.axis_states(self.client, self.body)
            if step >= p.ramp_steps:
                _, _, v, w = b.body_state(self.client, self.box)
                still = (np.max(np.abs(self.joint_values(omega))) < p.settle_joint_speed_rad_per_s
                         and np.linalg.norm(v) + np.linalg.norm(w) * radius < p.settle_object_speed_mm_per_s)
                calm = calm + 1 if still else 0
                if calm >= p.settle_steps:
                    settled, steps = True, step
                    break
            else:
                sigma = sigma_open + (sigma_closed - sigma_open) * (step + 1) / p.ramp_steps
                target = scale * self.reference(sigma)[axis_joint]
            if weight is not None:
                b.apply_force(self.client, self.box, weight)
            b.step_with_torques(self.client, self.body, axis_k * (target - theta) - p.joint_damping_Nmm_s_per_rad * omega)
        return self._settled(placed, contact_distance_mm, settled, steps)

    def _empty(self, status: str, q: NDArray, state: tuple[str, ...], center: NDArray, rotation: NDArray,
               settled: bool, steps: int) -> DynamicResult:
        n = self.hand.n_joints
        e3 = np.zeros((0, 3))
        return DynamicResult(status, q, state, np.zeros(0, np.int64), e3, e3.copy(), np.zeros((0, n)),
                             np.zeros(0), 0.0, np.asarray(center, dtype=float), np.asarray(rotation, dtype=float),
                             settled, steps)

    def _settled(self, placed: Any, contact_distance_mm: float, settled: bool, steps: int) -> DynamicResult:
        """Read the settled state: q, the box pose, one contact per touching hand link."""
        from synergrasp.hand.kinematics import contact_jacobian
        from synergrasp.simulation.closure import ObjectPose

        b, p, hand = self.bullet, self.params, self.hand
        theta, _ = b.axis_states(self.client, self.body)
        q = self.joint_values(theta)
        center, rotation, _, _ = b.body_state(self.client, self.box)
        now = ObjectPose(center, rotation, placed.half_extents_mm)
        forces = b.contact_forces(self.client, self.box, self.body)
        near = b.closest_points(self.client, self.box, self.body, contact_distance_mm)
        touching = sorted({int(v) for v in near.link_b if v >= 0})
        on_hand = b.contact_forces(self.client, self.body, self.body)
        self_links = set(on_hand.link_a.tolist()) | set(on_hand.link_b.tolist())
        finger_of = {link: f for f, links in enumerate(hand.finger_links) for link in links}
        state = tuple("contact" if any(finger_of.get(li) == f for li in touching)
                      else "self" if any(li in self_links for li in links) else "limit"
                      for f, links in enumerate(hand.finger_links))
        links, points, normals, loads, depth = [], [], [], [], 0.0
        for link in touching:
            rows = np.flatnonzero(forces.link_b == link)
            load = float(forces.normal_force[rows].sum()) if len(rows) else 0.0
            if load < p.load_threshold_N and p.unloaded_contacts == "drop":
                continue
            if load > 0.0:
                w = forces.normal_force[rows] / load
                on_link = w @ forces.point_b[rows]
                on_box = w @ forces.point_a[rows]
            else:
                k = np.flatnonzero(near.link_b == link)
                k = k[np.argmin(near.distance[k])]
                on_link, on_box = near.point_b[k], near.point_a[k]
            point, normal = _surface_point(now, on_link, on_box)
            links.append(link)
            points.append(point)
            normals.append(normal)
            loads.append(load)
            depth = max(depth, -float(near.distance[near.link_b == link].min()))
        if not links:
            moved = float(np.linalg.norm(center - placed.center_mm))
            status = "lost" if not touching and moved > p.lost_distance_mm else "no_contact"
            return self._empty(status, q, state, center, rotation, settled, steps)
        links_a = np.asarray(links, dtype=np.int64)
        points_a = np.asarray(points)
        return DynamicResult("grasp", q, state, links_a, points_a, np.asarray(normals),
                             contact_jacobian(hand, q, links_a, points_a), np.asarray(loads), max(depth, 0.0),
                             center, rotation, settled, steps)


def _surface_point(placed: Any, on_link: NDArray, on_box: NDArray) -> tuple[NDArray, NDArray]:
    """The contact point on the exact box surface and the box's inward unit normal there."""
    from synergrasp.simulation.closure import _box_surface_point

    return _box_surface_point(placed, on_link, on_box, np.zeros(3))
