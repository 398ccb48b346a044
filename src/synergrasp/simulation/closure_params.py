"""Settings of the closure (config ``closure``; docs/closure.md): :class:`ClosureParams`,
:class:`DynamicParams` of the dynamic model (``closure.dynamic``) and
:class:`ClosureMechanics`, what the dynamic model reads of ``mechanics``. Data only, so that the
closure models and the study loop (:mod:`synergrasp.simulation.closure`) all read them
without importing one another.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ClosureParams", "DynamicParams", "ClosureMechanics"]


@dataclass(frozen=True)
class DynamicParams:
    """Settings of the dynamic closure (config ``closure.dynamic``; docs/dynamic_closure.md).

    The values are checked once, by the config schema and ``config.check_relations``; this
    class only carries them.

    time_step_s:           physics time step, s (one tick of the engine; a workflow step is
                           another thing).
    solver_iterations:     constraint-solver iterations per tick.
    link_mass_kg:          mass of every elementary hand link during the closure, kg.
    link_inertia_kg_mm2:   rotational inertia of every elementary hand link about its own
                           frame, kg·mm² (sets the fastest joint mode: √(k_ss / I)).
    joint_damping_Nmm_s_per_rad: viscous damping on every elementary axis, N·mm·s/rad.
    object_mass_kg:        mass of the box during the closure, kg (its weight, if gravity is
                           on, is still mass_kg · g: see ``gravity``).
    object_damping_per_s:  linear and angular drag rate of the box, 1/s.
    ramp_time_s:           time over which σ runs from the open to the closed end, s.
    time_limit_s:          the closure stops here if it has not settled, s.
    settle_window_s:       settled when, over the last window of this length (s) after the
                           ramp, ...
    settle_joint_change_rad: ... no joint angle q changed by more than this (rad) ...
    settle_object_change_mm: ... and no point of the box moved by more than this (mm:
                           displacement of the centre + rotation angle × half diagonal).
    hand_hand_mu:          friction between two hand links (hand–box friction is mechanics.mu).
    gravity:               the box's weight acts during the closure (along
                           mechanics.gravity_direction) if true.
    lost_distance_mm:      a box with no contact at the end that moved farther than this from
                           its initial pose was moved by the hand and is held by nothing:
                           ``caged`` if its centre is inside the closed hand
                           (``HandCapsules.encloses``), ``lost`` (pushed out) if not.

    object:                ``free`` (the box is a free rigid body) or ``held`` (the box cannot
                           move: a fixed body in the engine, as if the arm held it; the compliant
                           fingers slide on it with friction μ and settle).

    Every hand link touching the box is listed with the normal force it carries; which of
    them count (``closure.dynamic.unloaded_contacts``) is decided downstream
    (``synergrasp.simulation.contacts.load_carrying_contacts``), so both choices share one closure.
    """

    time_step_s: float
    solver_iterations: int
    link_mass_kg: float
    link_inertia_kg_mm2: float
    joint_damping_Nmm_s_per_rad: float
    object_mass_kg: float
    object_damping_per_s: float
    ramp_time_s: float
    time_limit_s: float
    settle_window_s: float
    settle_joint_change_rad: float
    settle_object_change_mm: float
    hand_hand_mu: float
    gravity: bool
    lost_distance_mm: float
    object: str

    @property
    def held(self) -> bool:
        return self.object == "held"

    @property
    def ramp_ticks(self) -> int:
        """Ticks (physics time steps of ``time_step_s``) over which σ runs from open to closed."""
        return max(1, int(round(self.ramp_time_s / self.time_step_s)))

    @property
    def max_ticks(self) -> int:
        """Most ticks a closure runs: ``time_limit_s``, at least the ramp."""
        return max(self.ramp_ticks, int(round(self.time_limit_s / self.time_step_s)))

    @property
    def window_ticks(self) -> int:
        """Ticks in the settling window ``settle_window_s`` (at least one)."""
        return max(1, int(round(self.settle_window_s / self.time_step_s)))


@dataclass(frozen=True)
class ClosureParams:
    """Closure settings (docs/closure.md), built by :meth:`synergrasp.simulation.closure.SimulateParams.from_config`
    (``"simulate"``) from the configuration, whose schema holds the defaults and checks them.

    The path itself is not a setting: it runs from the fully open hand to the σ at which
    every joint moved by S1 is at a limit (``SynergyPath.closure_range``).
    tolerance_mm:             a stopping link ends within this gap of what it touches
                              (the refinement stops once the gap is in [0, tolerance_mm]).
    contact_distance_mm:      a link at most this far from the object counts as touching.
    penetration_tolerance_mm: the box intersects the open hand if it penetrates a link of
                              the open hand deeper than this; also the largest accepted
                              penetration of a recorded contact.
    step_mm:                  largest travel of any link point per coarse σ step, mm.
    model:                    ``kinematic`` (the quasi-static closure: links stop at first
                              touch, the box fixed) or ``dynamic`` (the compliant hand
                              closing on a free box, ``dynamic_closure``).
    dynamic:                  settings of the dynamic model (``DynamicParams``).
    """

    tolerance_mm: float
    contact_distance_mm: float
    penetration_tolerance_mm: float
    step_mm: float
    model: str
    dynamic: DynamicParams

    def __post_init__(self) -> None:
        # Checked once, by the schema and config.check_relations (built by SimulateParams.from_config).
        for name in ("tolerance_mm", "contact_distance_mm", "penetration_tolerance_mm", "step_mm"):
            object.__setattr__(self, name, float(getattr(self, name)))


@dataclass(frozen=True)
class ClosureMechanics:
    """What the dynamic closure reads of the configuration's ``mechanics``: the joint
    stiffness k_ss (N·mm/rad), the hand–box friction μ and the direction of gravity (palm
    frame; normalised where used). The box's weight is the object's (``synergrasp.resolved``)."""

    k_ss_Nmm_per_rad: float
    mu: float
    gravity_direction: tuple[float, float, float]

    def __post_init__(self) -> None:
        for name in ("k_ss_Nmm_per_rad", "mu"):
            object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "gravity_direction", tuple(float(v) for v in self.gravity_direction))
