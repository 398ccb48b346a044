"""Closing the hand on an object at every pose: the closure settings and the study loop.

``simulate_object`` places the object at each pose of the grid (:func:`place_object`: brought
toward the placement's target, stopped there or at first touch of the open hand), runs a
closure model on it and collects one contacts-table row
per pose (``contacts``). A closure model (``kinematic_closure``, ``dynamic_closure``) takes
the hand, the synergies and :class:`ClosureParams`; it has the open posture ``q_open``
(rad) its closure starts from, ``grasp(placed) -> ClosureResult`` (``placed``: an
``ObjectPose``, the shape at its pose) and ``close()``.
mm, rad, palm frame (docs/closure.md).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.simulation.contacts import contacts_row, contacts_table
from synergrasp.simulation.dynamic_closure import DynamicParams
from synergrasp.simulation.placement import ObjectPose, Placement, approach_line, object_pose, pose_grid
from synergrasp.simulation.scene import HandScene

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.objects import GraspedObject
    from synergrasp.simulation.shapes import Shape

__all__ = ["ClosureParams", "simulate_object", "closure_model", "place_object"]

@dataclass(frozen=True)
class ClosureParams:
    """Closure settings (docs/closure.md), built by :func:`synergrasp.config.step_params`
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
        # Checked once, by the schema and config.check_relations (built by config.step_params).
        for name in ("tolerance_mm", "contact_distance_mm", "penetration_tolerance_mm", "step_mm"):
            object.__setattr__(self, name, float(getattr(self, name)))


def closure_model(hand: Hand, synergies: Synergies, params: ClosureParams,
                  mechanics: Mapping[str, Any] | None = None, mass_kg: float | None = None):
    """The closure model of ``params`` on a new pybullet scene of ``hand``; the dynamic model
    also needs the config's ``mechanics`` block (k_ss, μ, gravity) and the object's mass (kg)."""
    if params.model == "dynamic":
        from synergrasp.simulation.dynamic_closure import DynamicClosure

        if mechanics is None or mass_kg is None:
            raise ValueError("closure.model: dynamic needs the mechanics block (k_ss_Nmm_per_rad, mu, gravity) "
                             "and the object's mass_kg")
        return DynamicClosure(hand, synergies, params, mechanics, mass_kg)
    from synergrasp.simulation.kinematic_closure import KinematicClosure

    return KinematicClosure(hand, synergies, params)


def place_object(scene: HandScene, q_open: NDArray, placement: Placement, shape: Shape, alpha_deg: float,
                 beta_deg: float) -> ObjectPose:
    """``shape`` at pose (α, β) deg by the placement rule: turned by (α, β), brought along
    the palm normal toward the placement's target, stopped at the target or at first touch
    of the open hand (posture ``q_open``, rad) of ``scene``, whichever comes first
    (:class:`synergrasp.simulation.placement.Placement`)."""
    hand = scene.hand
    turned = object_pose(placement, shape, alpha_deg, beta_deg, hand.palm_normal)
    point, direction = approach_line(placement, hand)
    return scene.bring_object(shape, turned.rotation, point, direction, q_open, placement.clearance_mm,
                              stop_at_point=True)


def simulate_object(hand: Hand, synergies: Synergies, grasped: GraspedObject, placement: Placement,
                    closure_params: ClosureParams, poses: Iterable[int] | None = None,
                    mechanics: Mapping[str, Any] | None = None) -> pd.DataFrame:
    """Close the hand on the object ``grasped`` (name, shape, mass) at every pose of the
    placement's grid (or at ``poses``).

    Returns the contacts table (``synergrasp.tables.CONTACTS``, one row per pose, in the
    order of ``poses``). Deterministic.
    """
    grid = pose_grid(placement)
    pose_list = list(range(grid.n_poses)) if poses is None else [int(v) for v in poses]
    for v in pose_list:
        if not 0 <= v < grid.n_poses:
            raise ValueError(f"poses must be in 0 … {grid.n_poses - 1}, got {v}")
    shape = grasped.shape
    model = closure_model(hand, synergies, closure_params, mechanics, grasped.mass_kg)
    placer = HandScene(hand)  # the open hand the box is brought to (placement)
    try:
        rows = []
        for pose in pose_list:
            a, b = grid.angles_deg(pose)
            placed = place_object(placer, model.q_open, placement, shape, a, b)
            rows.append(contacts_row(str(grasped.name), pose, a, b, model.grasp(placed), placed))
    finally:
        model.close()
        placer.close()
    return contacts_table(rows)
