"""Where the box sits relative to the hand: placement, the (α, β) pose grid, the placed box.

Lengths in mm, angles in rad (degrees only in pose labels and grid ranges), palm frame
(docs/design.md, docs/closure.md). Pure numpy: no pybullet here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.config import build, dataclass_fields
from synergrasp.hand.kinematics import axis_rotation

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.simulation.shapes import Shape

__all__ = [
    "palm_centre",
    "approach_line",
    "placement_target",
    "searched_placement",
    "FINGER_AXIS",
    "MODES",
    "Placement",
    "PoseGrid",
    "ObjectPose",
    "pose_grid",
    "object_pose",
]

#: The placement modes: presets of one rule, which differ only in where the target comes from.
MODES: tuple[str, ...] = ("approach", "fixed", "searched")


#: Long-finger axis of the palm frame (β rotates about it).
FINGER_AXIS = np.array([0.0, 0.0, 1.0])


def _unit(v: Sequence[float]) -> NDArray:
    a = np.asarray(v, dtype=float)
    return a / np.linalg.norm(a)


def _range_deg(start: float, stop: float, step: float, name: str) -> NDArray:
    """Inclusive grid start, start+step, ... stop (deg); stop must lie on the grid."""
    if not step > 0:
        raise ValueError(f"{name}.step must be > 0 deg, got {step}")
    n = (stop - start) / step
    if n < 0 or abs(n - round(n)) > 1e-9:
        raise ValueError(
            f"{name}: stop - start must be a non-negative multiple of step, got start={start}, stop={stop}, step={step}"
        )
    return start + step * np.arange(int(round(n)) + 1, dtype=float)


@dataclass(frozen=True)
class Placement:
    """Where the box sits relative to the palm (docs/closure.md).

    Built by :meth:`from_config` from the configuration, whose schema holds the defaults
    and checks the values.

    One rule for every mode: the box, turned by (α, β) about its centre, travels along the
    palm normal from outside toward a target point (palm frame, mm) and stops at the target
    or when it first comes within ``clearance_mm`` of the open hand, whichever comes first
    (``HandScene.bring_object``). It never intersects the open hand, so no pose is dropped.
    The modes say where the target comes from (:func:`placement_target`):

    mode:           ``approach``: ``approach_point_mm`` (None = the palm centre, which lies
                    on the palm face, so the box always stops at first touch);
                    ``fixed``: ``center_mm`` (a box that reaches it without touching the
                    open hand sits there at every pose; one that would intersect the open
                    hand stops at first touch); ``searched``: ``target_mm``, the object's
                    target chosen by the placement search (docs/placement_search.md).
    approach_point_mm: ``approach`` target (palm frame, mm); None = :func:`palm_centre`.
    clearance_mm:   gap (mm, ≥ 0) left between the box and the open hand when it stops at
                    first touch.
    center_mm:      ``fixed`` target (palm frame, mm); α and β rotate the box about its centre.
    box_axes:       ``box_axes[k]`` is the object's own axis (for a box: the index into
                    ``size_mm`` of its edge) that lies along palm axis k (x = palm normal,
                    y, z = long fingers) at α = β = 0; a permutation of (0, 1, 2)
                    (``synergrasp.simulation.shapes.start_rotation``).
    rotation_order: ``alpha_then_beta``: R = R_z(β)·R_n(α)·R_0 (α about the palm normal
                    n first, then β about the long-finger axis z, both palm-fixed axes);
                    ``beta_then_alpha``: R = R_n(α)·R_z(β)·R_0. Only ``alpha_then_beta``
                    keeps the α ↔ α + 180° symmetry of a box exact.
    alpha_deg, beta_deg: (start, stop, step) of the inclusive grids, deg; α is periodic.
    target_mm:      ``searched`` target (palm frame, mm), read from the search's output by
                    the closure step; None in the other modes.
    search_rank:    ``searched``: which of the search's distinct targets (1 = the chosen one).
    """

    mode: str
    approach_point_mm: tuple[float, float, float] | None
    clearance_mm: float
    center_mm: tuple[float, float, float]
    box_axes: tuple[int, int, int]
    rotation_order: str
    alpha_deg: tuple[float, float, float]
    beta_deg: tuple[float, float, float]
    target_mm: tuple[float, float, float] | None = None
    search_rank: int = 1

    @classmethod
    def from_config(cls, placement: Mapping[str, Any], grid: Mapping[str, Any]) -> Placement:
        """The placement of an effective ``placement`` block (the global one with an object's
        override laid over it) and the configuration's ``grid`` block."""
        ranges = {k: (v["start"], v["stop"], v["step"]) for k, v in grid.items()}
        return build(cls, "placement", **dataclass_fields(cls, {**placement, **ranges}))

    def __post_init__(self) -> None:
        # Values are checked once, by the schema and config.check_relations; built by
        # Placement.from_config; the schema holds the defaults. Here only the types are settled.
        for name in ("approach_point_mm", "target_mm"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, tuple(float(v) for v in getattr(self, name)))
        object.__setattr__(self, "clearance_mm", float(self.clearance_mm))
        object.__setattr__(self, "center_mm", tuple(float(v) for v in self.center_mm))
        object.__setattr__(self, "box_axes", tuple(int(a) for a in self.box_axes))
        for name in ("alpha_deg", "beta_deg"):
            object.__setattr__(self, name, tuple(float(v) for v in getattr(self, name)))


@dataclass(frozen=True)
class PoseGrid:
    """The (α, β) grid: pose = alpha_index * n_beta + beta_index."""

    alpha_deg: NDArray
    beta_deg: NDArray

    @property
    def n_alpha(self) -> int:
        return len(self.alpha_deg)

    @property
    def n_beta(self) -> int:
        return len(self.beta_deg)

    @property
    def n_poses(self) -> int:
        return self.n_alpha * self.n_beta

    def angles_deg(self, pose: int) -> tuple[float, float]:
        """(α, β) in deg of a pose index."""
        if not 0 <= pose < self.n_poses:
            raise ValueError(f"pose must be in 0 … {self.n_poses - 1}, got {pose}")
        ia, ib = divmod(int(pose), self.n_beta)
        return float(self.alpha_deg[ia]), float(self.beta_deg[ib])

    def index(self, alpha_deg: float, beta_deg: float) -> int:
        """Pose index of the grid point (α, β) in deg (α taken modulo 360)."""
        da = (np.asarray(self.alpha_deg) - alpha_deg + 180.0) % 360.0 - 180.0
        ia = np.flatnonzero(np.abs(da) < 1e-6)
        ib = np.flatnonzero(np.abs(np.asarray(self.beta_deg) - beta_deg) < 1e-6)
        if len(ia) != 1 or len(ib) != 1:
            raise ValueError(f"(alpha_deg, beta_deg) = ({alpha_deg}, {beta_deg}) is not on the grid")
        return int(ia[0]) * self.n_beta + int(ib[0])


def pose_grid(placement: Placement) -> PoseGrid:
    """The pose grid of a placement (72 × 25 = 1800 poses with the study's values)."""
    return PoseGrid(_range_deg(*placement.alpha_deg, name="alpha_deg"), _range_deg(*placement.beta_deg, name="beta_deg"))


@dataclass(frozen=True)
class ObjectPose:
    """An object placed in the palm frame: centre (mm), rotation (own frame → palm frame) and
    its shape (``synergrasp.simulation.shapes``)."""

    center_mm: NDArray
    rotation: NDArray
    shape: Shape

    def surface_point(self, point_mm: NDArray) -> tuple[NDArray, NDArray]:
        """The point of the exact surface nearest to ``point_mm`` (palm frame, mm) and the
        object's inward unit normal there (``Shape.surface_point``; pybullet rounds box edges
        by its collision margin, contacts are projected onto the exact shape)."""
        return self.shape.surface_point(point_mm, self.rotation, self.center_mm)


def object_pose(
    placement: Placement, shape: Shape, alpha_deg: float, beta_deg: float, palm_normal: Sequence[float] = (1.0, 0.0, 0.0)
) -> ObjectPose:
    """Centre and orientation of ``shape`` at (α, β) deg, at the placement's fixed centre.

    It starts at ``shape.start_rotation(placement.box_axes)``; α turns about ``palm_normal``
    (``synergrasp.hand.kinematics.PALM_NORMAL``), β about the palm z axis, both about its
    centre; see :class:`Placement` for the order.
    """
    R0 = shape.start_rotation(placement.box_axes)
    Ra = axis_rotation(_unit(palm_normal), math.radians(alpha_deg))
    Rb = axis_rotation(FINGER_AXIS, math.radians(beta_deg))
    R = Rb @ Ra @ R0 if placement.rotation_order == "alpha_then_beta" else Ra @ Rb @ R0
    return ObjectPose(np.array(placement.center_mm, dtype=float), R, shape)


def _palm_points(hand: Hand) -> NDArray:
    """(p, 3) points spanning the palm link's collision shapes (box corners; a capsule's end
    points widened by its radius along ±x, ±y, ±z), palm frame, mm."""
    corners = []
    for shape in hand.link_shapes[0]:
        if shape.kind == "box":
            signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
            local = 0.5 * signs * shape.size
        else:
            r = shape.radius
            ends = np.array([[0.0, 0.0, -0.5 * shape.length], [0.0, 0.0, 0.5 * shape.length]])
            local = np.concatenate([ends + d for d in r * np.vstack([np.eye(3), -np.eye(3)])])
        corners.append(local @ shape.pose[:3, :3].T + shape.pose[:3, 3])
    if not corners:
        raise ValueError(f"{hand.source}: palm.shapes: the palm has no collision shape; give placement.approach_point_mm")
    return np.vstack(corners)


def palm_centre(hand: Hand) -> NDArray:
    """The centre of the palm's face (palm frame, mm): the centre of the palm link's
    collision shapes' bounding box, moved along the palm normal onto their outermost
    point. The default approach point (docs/closure.md: where a hand takes an object it
    holds against the palm; a property of the hand alone)."""
    pts = _palm_points(hand)
    n = _unit(hand.palm_normal)
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    return centre + (float(np.max(pts @ n)) - float(centre @ n)) * n


def hand_region(hand: Hand, synergies: Any) -> tuple[tuple[float, float], ...]:
    """The placement search's region for any hand (docs/placement_search.md, ``region_mm:
    hand``), palm frame (mm), each bound rounded outward to a whole mm: x (the palm normal)
    from the palm's face to the farthest point the finger links' axes reach along x on the
    closure path q_r(σ), σ_open … σ_closed (where a box centre can still be met by the
    closing fingers); y the palm's width; z from the palm's wrist end to the highest
    fingertip of the open hand q_r(σ_open)."""
    from synergrasp.hand.kinematics import fingertip_positions
    from synergrasp.hand.synergies import SynergyPath
    from synergrasp.simulation.capsules import HandCapsules

    if not np.allclose(hand.palm_normal, (1.0, 0.0, 0.0)):
        raise ValueError(
            f"{hand.source}: palm_normal: region_mm 'hand' needs the palm frame of docs/hand.md "
            f"(palm normal +x), got {list(hand.palm_normal)}"
        )
    pts = _palm_points(hand)
    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    sigma_open, sigma_closed = path.closure_range(hand.flexion_joints)
    capsules = HandCapsules.of(hand)
    reach = max(
        float(np.max(np.concatenate(capsules.segments(path.reference(s)))[:, 0]))
        for s in np.linspace(sigma_open, sigma_closed, 201)
    )
    top = float(np.max(fingertip_positions(hand, path.reference(sigma_open))[:, 2]))
    bounds = (
        (float(np.max(pts[:, 0])), reach),
        (float(np.min(pts[:, 1])), float(np.max(pts[:, 1]))),
        (float(np.min(pts[:, 2])), top),
    )
    return tuple((float(math.floor(lo + 1e-9)), float(math.ceil(hi - 1e-9))) for lo, hi in bounds)


def placement_target(placement: Placement, hand: Hand) -> NDArray:
    """The target point (palm frame, mm) the box travels toward in the placement's mode."""
    if placement.mode == "fixed":
        return np.asarray(placement.center_mm, dtype=float)
    if placement.mode == "searched":
        if placement.target_mm is None:
            raise ValueError(
                "placement.mode 'searched' needs the object's searched target (target_mm): "
                "the closure reads it from the search's placement.csv"
            )
        return np.asarray(placement.target_mm, dtype=float)
    if placement.approach_point_mm is None:
        return palm_centre(hand)
    return np.asarray(placement.approach_point_mm, dtype=float)


def approach_line(placement: Placement, hand: Hand) -> tuple[NDArray, NDArray]:
    """The target point (mm) and the unit direction from the palm outward (the palm
    normal): the box centre moves on target + t·direction, t ≥ 0, from far out toward t = 0."""
    return placement_target(placement, hand), _unit(hand.palm_normal)


def searched_placement(placement: Placement, table: Any) -> Placement:
    """``placement`` (mode ``searched``) with its target: the row of the search's placement
    table (a DataFrame of ``table_contracts.PLACEMENT``) whose ``distinct_rank`` is the placement's
    ``search_rank``."""
    rows = table[table["distinct_rank"] == placement.search_rank]
    if len(rows) != 1:
        raise ValueError(
            f"placement.search_rank {placement.search_rank}: the search has "
            f"{int((table['distinct_rank'] > 0).sum())} distinct targets"
        )
    row = rows.iloc[0]
    return dataclasses.replace(placement, target_mm=(float(row["x_mm"]), float(row["y_mm"]), float(row["z_mm"])))
