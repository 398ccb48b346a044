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

from synergrasp.config import build, dataclass_fields
from synergrasp.hand.synergies import Synergies, synergy_values
from synergrasp.resolved import effective_placement, friction_mu
from synergrasp.simulation.closure_params import ClosureMechanics, ClosureParams, DynamicParams
from synergrasp.simulation.contacts import ClosureResult, contacts_row, contacts_table
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.placement import ObjectPose, Placement, approach_line, object_pose, pose_grid
from synergrasp.simulation.scene import HandScene

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.simulation.shapes import Shape

__all__ = ["SimulateParams", "simulate_object", "closure_model", "place_object", "warm_up"]


@dataclass(frozen=True)
class SimulateParams:
    """The closure of one object (the ``simulate`` step): the hand file (None: the shipped
    hand), the mean posture q_m and the first synergy S1 of the synergy table (rad, in the
    hand's joint order: all the closure reads of the table), the object, its effective placement
    (with the pose grid), the closure settings, and what the dynamic model reads of
    ``mechanics`` (else None)."""

    hand: str | None
    mean_rad: tuple[float, ...]
    s1: tuple[float, ...]
    object: GraspedObject
    placement: Placement
    closure: ClosureParams
    mechanics: ClosureMechanics | None = None

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> SimulateParams:
        """From a configuration, or from the step's own part of it
        (``synergrasp.steps.step_config``), whose ``synergies`` holds q_m and S1 themselves."""
        values = config["synergies"]
        if not isinstance(values, Mapping):
            values = synergy_values(config["hand"], values, (1,))
        closure = config["closure"]
        dynamic_model = closure["model"] == "dynamic"  # reads the box's mass and the mechanics
        dynamic = build(DynamicParams, "closure.dynamic", **dataclass_fields(DynamicParams, closure["dynamic"]))
        return cls(
            hand=config["hand"],
            mean_rad=tuple(values["mean_rad"]),
            s1=tuple(values["S1"]),
            object=GraspedObject.from_config(config, obj, with_mass=dynamic_model),
            placement=Placement.from_config(effective_placement(config, obj), config["grid"]),
            closure=build(ClosureParams, "closure", **{**dataclass_fields(ClosureParams, closure), "dynamic": dynamic}),
            mechanics=build(
                ClosureMechanics,
                "mechanics",
                **{**dataclass_fields(ClosureMechanics, config["mechanics"]), "mu": friction_mu(config)},
            )
            if dynamic_model
            else None,
        )

    def synergies(self, joint_names: tuple[str, ...]) -> Synergies:
        """q_m and S1 as a one-synergy :class:`Synergies` of the hand's joints."""
        return Synergies(tuple(joint_names), np.array(self.mean_rad), np.array(self.s1)[:, None], ("S1",))


def closure_model(
    hand: Hand,
    synergies: Synergies,
    params: ClosureParams,
    mechanics: ClosureMechanics | None = None,
    weight_N: float | None = None,
):
    """The closure model of ``params`` on a new pybullet scene of ``hand``; the dynamic model
    also needs the :class:`ClosureMechanics` (k_ss, μ, gravity) and the object's weight (N)."""
    if params.model == "dynamic":
        from synergrasp.simulation.dynamic_closure import DynamicClosure

        if mechanics is None or weight_N is None:
            raise ValueError(
                "closure.model: dynamic needs the mechanics block (k_ss_Nmm_per_rad, mu, gravity) "
                "and the object's weight (mass_kg, mechanics.g_m_per_s2)"
            )
        return DynamicClosure(hand, synergies, params, mechanics, weight_N)
    from synergrasp.simulation.kinematic_closure import KinematicClosure

    return KinematicClosure(hand, synergies, params)


def place_object(
    scene: HandScene, q_open: NDArray, placement: Placement, shape: Shape, alpha_deg: float, beta_deg: float
) -> ObjectPose:
    """``shape`` at pose (α, β) deg by the placement rule: turned by (α, β), brought along
    the palm normal toward the placement's target, stopped at the target or at first touch
    of the open hand (posture ``q_open``, rad) of ``scene``, whichever comes first
    (:class:`synergrasp.simulation.placement.Placement`)."""
    hand = scene.hand
    turned = object_pose(placement, shape, alpha_deg, beta_deg, hand.palm_normal)
    point, direction = approach_line(placement, hand)
    return scene.bring_object(shape, turned.rotation, point, direction, q_open, placement.clearance_mm, stop_at_point=True)


def simulate_object(
    hand: Hand,
    synergies: Synergies,
    grasped: GraspedObject,
    placement: Placement,
    closure_params: ClosureParams,
    poses: Iterable[int] | None = None,
    mechanics: ClosureMechanics | None = None,
    *,
    as_in_grid: bool = False,
) -> pd.DataFrame:
    """Close the hand on the object ``grasped`` (name, shape, mass) at every pose of the
    placement's grid (or at ``poses``).

    Returns the contacts table (``synergrasp.table_contracts.CONTACTS``, one row per pose, in the
    order of ``poses``). Deterministic. With the kinematic model a pose whose box fills the
    region of an earlier pose of the run shares that pose's closure (``_RegionResults``);
    ``as_in_grid=True`` closes each of ``poses`` at the first pose of the whole grid that fills
    its region, so that its row is the whole grid's run's row bit for bit (the inspector).
    """
    grid = pose_grid(placement)
    pose_list = list(range(grid.n_poses)) if poses is None else [int(v) for v in poses]
    for v in pose_list:
        if not 0 <= v < grid.n_poses:
            raise ValueError(f"poses must be in 0 … {grid.n_poses - 1}, got {v}")
    shape = grasped.shape
    model = closure_model(hand, synergies, closure_params, mechanics, grasped.weight_N)
    placer = HandScene(hand)  # the open hand the box is brought to (placement)
    # the kinematic closure sees only the region the box fills: one region, one closure
    shared = _RegionResults(shape) if closure_params.model == "kinematic" else None
    try:
        rows = []
        for pose in pose_list:
            a, b = grid.angles_deg(pose)
            placed = place_object(placer, model.q_open, placement, shape, a, b)
            result = None if shared is None else shared.get(placed)
            if result is None and shared is not None and as_in_grid:  # close where the grid's run closed
                first = next(
                    (
                        other
                        for other in (
                            place_object(placer, model.q_open, placement, shape, *grid.angles_deg(earlier))
                            for earlier in range(pose)
                        )
                        if shared.same(other, placed)
                    ),
                    None,
                )
                if first is not None:
                    result = model.grasp(first)
                    shared.add(first, result)
            if result is None:
                result = model.grasp(placed)
                if shared is not None:
                    shared.add(placed, result)
            rows.append(contacts_row(str(grasped.name), pose, a, b, result, placed))
    finally:
        model.close()
        placer.close()
    return contacts_table(rows)


#: Unit directions (palm frame) of the rays that tell regions apart in ``_RegionResults``:
#: none along a palm axis or a diagonal, so that symmetric but distinct regions differ.
_PROBES = np.array([[1.0, 2.0, 3.0], [-2.0, 1.0, 1.5], [1.5, -1.0, 2.5], [3.0, 1.0, -2.0]])
_PROBES /= np.linalg.norm(_PROBES, axis=1, keepdims=True)


class _RegionResults:
    """Closure results by the region the placed box fills (``Shape.same_region``: a box's poses
    one α-period apart): the kinematic closure of the first pose in a region serves every
    later pose in it. Candidates are bucketed by the centre and the entry distances of four
    fixed rays aimed at it, rounded to 1e-6 mm (both depend on the region only); twins
    straddling a rounding boundary are closed apart, at the cost of a closure."""

    def __init__(self, shape: Shape) -> None:
        self.shape = shape
        self.buckets: dict[tuple[float, ...], list[tuple[ObjectPose, ClosureResult]]] = {}
        self._last: tuple[ObjectPose, tuple[float, ...]] | None = None  # the last pose keyed (get, then add)

    def _key(self, placed: ObjectPose) -> tuple[float, ...]:
        if self._last is not None and self._last[0] is placed:
            return self._last[1]
        center, rotation = np.asarray(placed.center_mm, dtype=float), np.asarray(placed.rotation, dtype=float)
        reach = 2.0 * self.shape.bounding_radius_mm
        # rays from outside toward the centre, in the shape's own frame (Rᵀ v = v R)
        t, _, _ = self.shape.ray_hits((reach * _PROBES) @ rotation, -_PROBES @ rotation)
        key = tuple(np.round(np.concatenate([center, t]), 6).tolist())
        self._last = (placed, key)
        return key

    def _fill_alike(self, a: ObjectPose, b: ObjectPose) -> bool:
        return self.shape.same_region(a.rotation, a.center_mm, b.rotation, b.center_mm)

    def same(self, a: ObjectPose, b: ObjectPose) -> bool:
        """Whether ``a`` and ``b`` are one region by the rule ``get`` applies."""
        return self._key(a) == self._key(b) and self._fill_alike(a, b)

    def get(self, placed: ObjectPose) -> ClosureResult | None:
        return next(
            (result for other, result in self.buckets.get(self._key(placed), []) if self._fill_alike(other, placed)), None
        )

    def add(self, placed: ObjectPose, result: ClosureResult) -> None:
        if result.settled_pose is not None:  # a box that moved is no longer the region's
            raise ValueError("a closure that moves the box cannot be shared between poses")
        self.buckets.setdefault(self._key(placed), []).append((placed, result))


def warm_up() -> None:
    """Compile the kinematic closure's distance queries and steps (numba), or load them from
    their cache (``synergrasp.simulation.shapes.compiled``: per user, named by the hash of their
    sources, so any checkout of the same sources loads them). Called once after installation
    (Makefile), beside the solver's warm-up, so that no workflow job compiles them and parallel
    jobs do not compile side by side: closes the shipped hand on the default study's first box
    at one pose, brought to the palm centre."""
    from dataclasses import replace

    from synergrasp.config import defaults
    from synergrasp.hand.kinematics import load_hand

    config = defaults()
    params = SimulateParams.from_config(config, next(iter(config["objects"])))
    hand = load_hand(params.hand)
    simulate_object(
        hand,
        params.synergies(hand.joint_names),
        params.object,
        replace(params.placement, mode="approach"),
        replace(params.closure, model="kinematic"),
        poses=[0],
    )
