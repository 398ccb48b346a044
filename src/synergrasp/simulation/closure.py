"""Hand/object placement, the (α, β) pose grid, quasi-static closure along S1, contacts.

Conventions (docs/design.md, docs/closure.md): lengths in mm, angles in rad (degrees only
in pose labels), everything in the palm frame. pybullet works in metres; the conversion
happens here, at the interface. pybullet is imported only inside the functions that
simulate, so that :func:`read_grasps` (used by the optimisation step) never loads it.

The closure is kinematic and quasi-static: the joint reference follows
q_r(σ) = clip(q_m + σ·S1, lower, upper) from σ_open to σ_closed; a link that touches the
object (or the hand itself) holds the joints proximal to it, the distal joints and the
other fingers keep following the reference (soft synergies). The simulation is never
stepped: joints are reset and the collision pipeline is queried.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.optimisation.mechanics import Grasp

__all__ = [
    "ROTATION_ORDERS",
    "STATUSES",
    "FINGER_STATES",
    "CONTACT_COLUMNS",
    "Placement",
    "ClosureParams",
    "PoseGrid",
    "ObjectPose",
    "ClosureResult",
    "pose_grid",
    "object_pose",
    "simulate_object",
    "simulate_pose",
    "read_grasps",
]

ROTATION_ORDERS: tuple[str, ...] = ("alpha_then_beta", "beta_then_alpha")
STATUSES: tuple[str, ...] = ("grasp", "intersects_open_hand", "no_contact")
FINGER_STATES: tuple[str, ...] = ("contact", "limit", "self")
CONTACT_COLUMNS: tuple[str, ...] = (
    "object", "pose", "alpha_deg", "beta_deg", "status", "q", "finger_state", "n_contacts",
    "contact_link", "contact_point", "contact_normal", "jacobian", "object_center",
    "object_rotation", "max_penetration_mm",
)

#: Long-finger axis of the palm frame (β rotates about it).
FINGER_AXIS = np.array([0.0, 0.0, 1.0])
_MM = 1e-3  # metres per mm, pybullet side only


# --------------------------------------------------------------------------------------
# Placement and pose grid
# --------------------------------------------------------------------------------------

def _range_deg(start: float, stop: float, step: float, name: str) -> NDArray:
    """Inclusive grid start, start+step, ... stop (deg); stop must lie on the grid."""
    if not step > 0:
        raise ValueError(f"{name}.step must be > 0 deg, got {step}")
    n = (stop - start) / step
    if n < 0 or abs(n - round(n)) > 1e-9:
        raise ValueError(f"{name}: stop - start must be a non-negative multiple of step, "
                         f"got start={start}, stop={stop}, step={step}")
    return start + step * np.arange(int(round(n)) + 1, dtype=float)


@dataclass(frozen=True)
class Placement:
    """Where the box sits relative to the palm before and while it is rotated.

    center_mm:      box centre o in the palm frame (mm); α and β rotate about it, so it
                    is the same for every pose.
    box_axes:       ``box_axes[k]`` is the index (into ``size_mm``) of the box edge that
                    lies along palm axis k (x = palm normal, y, z = long fingers) at
                    α = β = 0; a permutation of (0, 1, 2).
    rotation_order: ``alpha_then_beta``: R = R_z(β)·R_n(α)·R_0 (α about the palm normal
                    n first, then β about the long-finger axis z, both palm-fixed axes);
                    ``beta_then_alpha``: R = R_n(α)·R_z(β)·R_0. Only ``alpha_then_beta``
                    keeps the α ↔ α + 180° symmetry of a box exact.
    alpha_deg, beta_deg: (start, stop, step) of the inclusive grids, deg; α is periodic.
    """

    center_mm: tuple[float, float, float] = (38.0, 5.0, 112.0)
    box_axes: tuple[int, int, int] = (0, 1, 2)
    rotation_order: str = "alpha_then_beta"
    alpha_deg: tuple[float, float, float] = (-180.0, 175.0, 5.0)
    beta_deg: tuple[float, float, float] = (-60.0, 60.0, 5.0)

    def __post_init__(self) -> None:
        center = tuple(float(v) for v in self.center_mm)
        if len(center) != 3 or not all(math.isfinite(v) for v in center):
            raise ValueError(f"Placement.center_mm must be 3 finite numbers (mm), got {self.center_mm!r}")
        axes = tuple(int(a) for a in self.box_axes)
        if sorted(axes) != [0, 1, 2]:
            raise ValueError(f"Placement.box_axes must be a permutation of (0, 1, 2), got {self.box_axes!r}")
        if self.rotation_order not in ROTATION_ORDERS:
            raise ValueError(f"Placement.rotation_order must be one of {list(ROTATION_ORDERS)}, "
                             f"got {self.rotation_order!r}")
        for name in ("alpha_deg", "beta_deg"):
            rng = tuple(float(v) for v in getattr(self, name))
            if len(rng) != 3:
                raise ValueError(f"Placement.{name} must be (start, stop, step) in deg, got {rng!r}")
            _range_deg(*rng, name=f"Placement.{name}")
            object.__setattr__(self, name, rng)
        alpha = _range_deg(*self.alpha_deg, name="Placement.alpha_deg")
        if alpha[-1] - alpha[0] >= 360.0:
            raise ValueError(f"Placement.alpha_deg spans {alpha[-1] - alpha[0]} deg; α is periodic, "
                             f"the grid must span less than 360 deg")
        object.__setattr__(self, "center_mm", center)
        object.__setattr__(self, "box_axes", axes)

    @classmethod
    def from_config(cls, placement: Mapping[str, Any], grid: Mapping[str, Any] | None = None) -> Placement:
        """From the config's ``placement`` block and (optionally) its ``grid`` block."""
        kwargs: dict[str, Any] = {}
        for key in ("center_mm", "box_axes", "rotation_order"):
            if key in placement:
                kwargs[key] = placement[key]
        unknown = set(placement) - {"center_mm", "box_axes", "rotation_order"}
        if unknown:
            raise ValueError(f"placement: unknown key(s) {sorted(unknown)}; allowed keys: "
                             f"['box_axes', 'center_mm', 'rotation_order']")
        for key in ("alpha_deg", "beta_deg"):
            if grid is not None and key in grid:
                g = grid[key]
                kwargs[key] = (g["start"], g["stop"], g["step"])
        return cls(**kwargs)


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
    return PoseGrid(_range_deg(*placement.alpha_deg, name="alpha_deg"),
                    _range_deg(*placement.beta_deg, name="beta_deg"))


def _axis_rotation(axis: NDArray, angle: float) -> NDArray:
    """Rotation matrix of ``angle`` rad about the unit ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


@dataclass(frozen=True)
class ObjectPose:
    """A box placed in the palm frame: centre (mm) and rotation (box frame → palm frame)."""

    center_mm: NDArray
    rotation: NDArray
    half_extents_mm: NDArray  # along the box's own axes (size_mm / 2)


def object_pose(placement: Placement, size_mm: Sequence[float], alpha_deg: float, beta_deg: float,
                palm_normal: Sequence[float] = (1.0, 0.0, 0.0)) -> ObjectPose:
    """Centre and orientation of a box of ``size_mm`` at (α, β) deg.

    α turns about ``palm_normal`` (``synergrasp.hand.kinematics.PALM_NORMAL``), β about the palm z
    axis, both about the box centre; see :class:`Placement` for the order.
    """
    size = np.asarray(size_mm, dtype=float)
    if size.shape != (3,) or not np.all(size > 0):
        raise ValueError(f"size_mm must be 3 positive lengths (mm), got {size_mm!r}")
    R0 = np.zeros((3, 3))
    for k, edge in enumerate(placement.box_axes):
        R0[k, edge] = 1.0  # box edge `edge` lies along palm axis k
    if np.linalg.det(R0) < 0:  # an odd permutation: flip the box's z edge (a box is mirror-symmetric)
        R0[:, placement.box_axes[2]] *= -1.0
    Ra = _axis_rotation(np.asarray(palm_normal, dtype=float), math.radians(alpha_deg))
    Rb = _axis_rotation(FINGER_AXIS, math.radians(beta_deg))
    R = Rb @ Ra @ R0 if placement.rotation_order == "alpha_then_beta" else Ra @ Rb @ R0
    return ObjectPose(np.array(placement.center_mm, dtype=float), R, size / 2.0)


# --------------------------------------------------------------------------------------
# Closure parameters and results
# --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ClosureParams:
    """Closure settings (docs/closure.md).

    sigma_open, sigma_closed: S1 coordinate of the open and of the fully closed hand.
    tolerance_mm:             a stopping link ends within this gap of what it touches
                              (the refinement stops once the gap is in [0, tolerance_mm]).
    contact_distance_mm:      a link at most this far from the object counts as touching.
    penetration_tolerance_mm: the box intersects the open hand if it penetrates a link of
                              the open hand deeper than this; also the largest accepted
                              penetration of a recorded contact.
    step_mm:                  largest travel of any link point per coarse σ step, mm.
    """

    sigma_open: float = -2.0
    sigma_closed: float = 3.0
    tolerance_mm: float = 0.2
    contact_distance_mm: float = 0.5
    penetration_tolerance_mm: float = 0.5
    step_mm: float = 8.0

    def __post_init__(self) -> None:
        for name in ("sigma_open", "sigma_closed", "tolerance_mm", "contact_distance_mm",
                     "penetration_tolerance_mm", "step_mm"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ValueError(f"ClosureParams.{name} must be a finite number, got {v!r}")
            object.__setattr__(self, name, float(v))
        if not self.sigma_closed > self.sigma_open:
            raise ValueError(f"ClosureParams.sigma_closed ({self.sigma_closed}) must be greater than "
                             f"sigma_open ({self.sigma_open})")
        if not 0 < self.tolerance_mm <= 1:
            raise ValueError(f"ClosureParams.tolerance_mm must be in (0, 1] mm, got {self.tolerance_mm}")
        if not self.tolerance_mm <= self.contact_distance_mm <= 5:
            raise ValueError(f"ClosureParams.contact_distance_mm must be in [tolerance_mm, 5] mm, "
                             f"got {self.contact_distance_mm}")
        if not 0 <= self.penetration_tolerance_mm <= 5:
            raise ValueError(f"ClosureParams.penetration_tolerance_mm must be in [0, 5] mm, "
                             f"got {self.penetration_tolerance_mm}")
        if not self.step_mm > self.tolerance_mm:
            raise ValueError(f"ClosureParams.step_mm must be greater than tolerance_mm, got {self.step_mm}")

    @classmethod
    def from_config(cls, closure: Mapping[str, Any]) -> ClosureParams:
        """From the config's ``closure`` block."""
        allowed = {"sigma_open", "sigma_closed", "tolerance_mm", "contact_distance_mm",
                   "penetration_tolerance_mm", "step_mm"}
        unknown = set(closure) - allowed
        if unknown:
            raise ValueError(f"closure: unknown key(s) {sorted(unknown)}; allowed keys: {sorted(allowed)}")
        return cls(**dict(closure))


@dataclass(frozen=True)
class ClosureResult:
    """The outcome of one closure, palm frame.

    status:        one of STATUSES
    q:             (19,) final joint angles, rad
    finger_state:  per finger thumb…little: ``contact``, ``limit`` or ``self``
    links:         (m,) hand link index per contact (0 = palm)
    points:        (m, 3) contact points on the object surface, mm
    normals:       (m, 3) object's inward unit normals
    jacobian:      (3m, 19) translational Jacobian of the contact points, mm/rad
    max_penetration_mm: deepest penetration among the contacts (0 if none)
    """

    status: str
    q: NDArray
    finger_state: tuple[str, ...]
    links: NDArray
    points: NDArray
    normals: NDArray
    jacobian: NDArray
    max_penetration_mm: float


# --------------------------------------------------------------------------------------
# Contacts table (results/{object}/contacts.parquet) and its reader
# --------------------------------------------------------------------------------------

def contacts_schema():
    """The pyarrow schema of contacts.parquet (docs/design.md)."""
    import pyarrow as pa

    f64, i32, s = pa.float64(), pa.int32(), pa.string()
    return pa.schema([
        ("object", s), ("pose", i32), ("alpha_deg", f64), ("beta_deg", f64), ("status", s),
        ("q", pa.list_(f64)), ("finger_state", pa.list_(s)), ("n_contacts", i32),
        ("contact_link", pa.list_(i32)), ("contact_point", pa.list_(f64)),
        ("contact_normal", pa.list_(f64)), ("jacobian", pa.list_(f64)),
        ("object_center", pa.list_(f64)), ("object_rotation", pa.list_(f64)),
        ("max_penetration_mm", f64),
    ])


def write_contacts(table: pd.DataFrame, path: str) -> None:
    """Write a contacts table to Parquet with the exact column types of the contract."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    missing = [c for c in CONTACT_COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"contacts table: missing column(s) {missing}; required: {list(CONTACT_COLUMNS)}")
    pq.write_table(pa.Table.from_pandas(table[list(CONTACT_COLUMNS)], schema=contacts_schema(),
                                        preserve_index=False), path)


def _row(object_name: str, pose: int, alpha_deg: float, beta_deg: float, result: ClosureResult,
         placed: ObjectPose) -> dict[str, Any]:
    return {
        "object": object_name,
        "pose": int(pose),
        "alpha_deg": float(alpha_deg),
        "beta_deg": float(beta_deg),
        "status": result.status,
        "q": [float(v) for v in result.q],
        "finger_state": list(result.finger_state),
        "n_contacts": int(len(result.links)),
        "contact_link": [int(v) for v in result.links],
        "contact_point": [float(v) for v in np.ravel(result.points)],
        "contact_normal": [float(v) for v in np.ravel(result.normals)],
        "jacobian": [float(v) for v in np.ravel(result.jacobian)],
        "object_center": [float(v) for v in placed.center_mm],
        "object_rotation": [float(v) for v in np.ravel(placed.rotation)],
        "max_penetration_mm": float(result.max_penetration_mm),
    }


def _table(rows: list[dict[str, Any]]) -> pd.DataFrame:
    table = pd.DataFrame(rows, columns=list(CONTACT_COLUMNS))
    for col in ("pose", "n_contacts"):
        table[col] = table[col].astype(np.int32)
    return table


def read_grasps(table: pd.DataFrame) -> list[Grasp | None]:
    """One :class:`synergrasp.optimisation.mechanics.Grasp` per row of a contacts table, in row order.

    Rows whose status is not ``grasp`` or that have no contact give ``None``. Reads only
    numbers: pybullet is not imported.
    """
    from synergrasp.optimisation.mechanics import Grasp

    missing = [c for c in ("status", "n_contacts", "contact_link", "contact_point", "contact_normal",
                           "jacobian", "object_center") if c not in table.columns]
    if missing:
        raise ValueError(f"contacts table: missing column(s) {missing}")
    grasps: list[Grasp | None] = []
    for row in table.itertuples(index=False):
        m = int(row.n_contacts)
        if row.status != "grasp" or m == 0:
            grasps.append(None)
            continue
        jac = np.asarray(row.jacobian, dtype=float)
        grasps.append(Grasp(
            points=np.asarray(row.contact_point, dtype=float).reshape(m, 3),
            normals=np.asarray(row.contact_normal, dtype=float).reshape(m, 3),
            links=np.asarray(row.contact_link, dtype=np.int64),
            jacobian=jac.reshape(3 * m, jac.size // (3 * m)),
            center=np.asarray(row.object_center, dtype=float),
        ))
    return grasps


# --------------------------------------------------------------------------------------
# Quasi-static closure along S1 (pybullet)
# --------------------------------------------------------------------------------------

_LONG_FINGERS = ("index", "middle", "ring", "little")
#: Distance (mm) within which the hand is queried for the next step size.
_QUERY_MARGIN_MM = 40.0
_MAX_REFINE = 40


class _Closer:
    """One pybullet scene (hand + box) and the closure along S1 on it."""

    def __init__(self, hand: Any, synergies: Any, params: ClosureParams) -> None:
        from synergrasp.simulation import bullet

        self.bullet = bullet
        self.hand = hand
        self.params = params
        names = tuple(synergies.joint_names)
        if names != tuple(hand.joint_names):
            raise ValueError(f"synergies.joint_names must equal hand.joint_names {hand.joint_names}, got {names}")
        self.mean = np.asarray(synergies.mean, dtype=float)
        self.s1 = np.asarray(synergies.matrix, dtype=float)[:, 0]
        self.lower = np.asarray(hand.lower, dtype=float)
        self.upper = np.asarray(hand.upper, dtype=float)
        # σ interval on which each joint's reference is inside its limits (clipped outside)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (self.lower - self.mean) / self.s1
            b = (self.upper - self.mean) / self.s1
        self.active_lo = np.where(self.s1 != 0, np.minimum(a, b), np.inf)
        self.active_hi = np.where(self.s1 != 0, np.maximum(a, b), -np.inf)
        self.client = bullet.connect()
        self.body = bullet.load_hand_body(self.client, hand)
        self.box: int | None = None
        self.box_size: NDArray | None = None
        self.fingers = [(tuple(j), tuple(li)) for j, li in zip(hand.finger_joints, hand.finger_links)]
        self.link_finger_index = np.full(hand.n_links, -1)
        self.link_chain_pos = np.full(hand.n_links, -1)
        for f, (_, links) in enumerate(self.fingers):
            for i, link in enumerate(links):
                self.link_finger_index[link] = f
                self.link_chain_pos[link] = i
        self.reach = self._finger_reach()
        self._profiles: dict[tuple[int, tuple[int, ...]], tuple[NDArray, NDArray]] = {}
        self.q_open = self.reference(params.sigma_open)
        self.self_pairs = self._monitored_pairs()

    def close(self) -> None:
        self.bullet.disconnect(self.client)

    # -- kinematic helpers -------------------------------------------------------------
    def reference(self, sigma: float) -> NDArray:
        """q_r(σ) = clip(q_m + σ·S1, lower, upper), rad."""
        return np.clip(self.mean + sigma * self.s1, self.lower, self.upper)

    def _finger_reach(self) -> NDArray:
        """Per finger, an upper bound (mm) on the distance of any point of its links from any
        of its joint axes: the extended chain (q = 0) from the finger's first axis, plus radius."""
        from synergrasp.hand.kinematics import forward_kinematics

        frames = forward_kinematics(self.hand, np.zeros(self.hand.n_joints))
        reach = np.zeros(len(self.fingers))
        for f, (_, links) in enumerate(self.fingers):
            base = frames[links[0], :3, 3]
            r = 0.0
            for link in links:
                for shape in self.hand.link_shapes[link]:
                    centre = frames[link] @ shape.pose
                    half = 0.5 * shape.length if shape.kind == "capsule" else 0.5 * float(np.linalg.norm(shape.size))
                    ext = half + shape.radius
                    r = max(r, float(np.linalg.norm(centre[:3, 3] - base)) + ext)
            reach[f] = r + 10.0  # the first axis sits up to one rolling gap before the base frame
        return reach

    def _monitored_pairs(self) -> tuple[tuple[int, int], ...]:
        """Self-collision pairs that stop a finger: a finger link against the palm or against a
        link of another finger, except long finger against long finger (they flex in
        side-by-side planes and slide along each other) and pairs already overlapping at the
        open posture (a property of the model, not an event)."""
        hand = self.hand
        pairs = []
        for i, j in self.bullet.self_collision_pairs(hand):
            fi, fj = hand.link_finger[i], hand.link_finger[j]
            if fi == fj:
                continue
            if fi in _LONG_FINGERS and fj in _LONG_FINGERS:
                continue
            # the knuckles barely move: only the outer links can run into the palm or the thumb
            if any(hand.link_names[k].endswith("_knuckle") for k in (i, j)):
                continue
            pairs.append((i, j))
        self.bullet.set_posture(self.client, self.body, self.q_open)
        overlap = self.bullet.self_closest_points(self.client, self.body, 0.0, tuple(pairs))
        bad = {(int(a), int(b)) for a, b, d in zip(overlap.link_a, overlap.link_b, overlap.distance) if d < 0}
        return tuple(p for p in pairs if p not in bad and (p[1], p[0]) not in bad)

    # -- scene ----------------------------------------------------------------------------
    def place_box(self, size_mm: NDArray, placed: ObjectPose) -> None:
        size = np.asarray(size_mm, dtype=float)
        if self.box is None or self.box_size is None or not np.array_equal(size, self.box_size):
            if self.box is not None:
                self.bullet.remove_body(self.client, self.box)
            self.box = self.bullet.load_box(self.client, size, placed.center_mm, placed.rotation)
            self.box_size = size
        else:
            self.bullet.move_body(self.client, self.box, placed.center_mm, placed.rotation)

    def object_distance(self, margin_mm: float) -> NDArray:
        """(n_links,) distance of each hand link to the box (mm; +inf beyond ``margin_mm``)."""
        pts = self.bullet.closest_points(self.client, self.box, self.body, margin_mm)
        d = np.full(self.hand.n_links, np.inf)
        if len(pts):
            np.minimum.at(d, pts.link_b, pts.distance)
        return d

    def self_distance(self, pairs: tuple[tuple[int, int], ...], margin_mm: float) -> NDArray:
        """(n_links,) per link the distance to the nearest hand link of ``pairs`` (mm, +inf beyond margin)."""
        d = np.full(self.hand.n_links, np.inf)
        if pairs:
            pts = self.bullet.self_closest_points(self.client, self.body, margin_mm, pairs)
            if len(pts):
                np.minimum.at(d, pts.link_a, pts.distance)
                np.minimum.at(d, pts.link_b, pts.distance)
        return d

    # -- the closure ------------------------------------------------------------------------
    def _travel_profile(self, f: int, moving: tuple[int, ...]) -> tuple[NDArray, NDArray]:
        """Knots σ_k on [σ_open, σ_closed] and the travel bound T(σ_k) (mm) accumulated from
        σ_open by any point of finger f when only the joints ``moving`` follow the reference.

        T is piecewise linear: joint j adds |S1_j| · reach(f) mm per unit σ while its
        reference is inside its limits (a clipped joint does not move). Cached per
        (finger, moving joints): there are only a few such sets per finger.
        """
        key = (f, moving)
        profile = self._profiles.get(key)
        if profile is None:
            p = self.params
            idx = list(moving)
            lo, hi = self.active_lo[idx], self.active_hi[idx]
            rate = np.abs(self.s1[idx]) * self.reach[f]  # mm per unit σ while active
            knots = np.unique(np.clip(np.concatenate([lo, hi, [p.sigma_open, p.sigma_closed]]),
                                      p.sigma_open, p.sigma_closed))
            mids = 0.5 * (knots[:-1] + knots[1:])
            speed = np.array([float(np.sum(rate[(lo <= m) & (hi >= m)])) for m in mids])
            profile = (knots, np.concatenate([[0.0], np.cumsum(speed * np.diff(knots))]))
            self._profiles[key] = profile
        return profile

    def advance(self, sigma: float, budget_mm: NDArray, held: NDArray) -> float:
        """Largest σ' ≤ σ_closed such that no point of finger f travels more than
        budget_mm[f] on [σ, σ'] (clipped joints do not move; held joints do not move)."""
        best = self.params.sigma_closed
        for f, (joints, _) in enumerate(self.fingers):
            moving = tuple(j for j in joints if not held[j])
            if not moving:
                continue
            knots, travel = self._travel_profile(f, moving)
            level = float(np.interp(sigma, knots, travel)) + budget_mm[f]
            if level > travel[-1]:
                continue  # the budget outlasts the closure
            k = int(np.searchsorted(travel, level, side="left"))  # travel[k-1] < level <= travel[k]
            t0, t1 = travel[k - 1], travel[k]
            best = min(best, knots[k - 1] + (level - t0) / (t1 - t0) * (knots[k] - knots[k - 1]))
        return best

    def posture(self, sigma: float, held: NDArray, q_held: NDArray) -> NDArray:
        return np.where(held, q_held, self.reference(sigma))

    def gaps(self, q: NDArray, moving_links: NDArray, pairs: tuple[tuple[int, int], ...],
             margin_mm: float) -> tuple[NDArray, NDArray]:
        """Per link: distance to the box and to the monitored hand links, at posture q (mm)."""
        self.bullet.set_posture(self.client, self.body, q)
        d_obj = self.object_distance(margin_mm)
        d_self = self.self_distance(pairs, margin_mm)
        d_obj[~moving_links] = np.inf
        d_self[~moving_links] = np.inf
        return d_obj, d_self

    def run(self) -> tuple[NDArray, list[str], bool]:
        """Close the hand on the placed box from σ_open. Returns (q, finger_state,
        intersects_open_hand)."""
        p = self.params
        hand = self.hand
        n = hand.n_joints
        held = np.zeros(n, dtype=bool)
        q_held = np.zeros(n)
        touched_obj = np.zeros(len(self.fingers), dtype=bool)
        touched_self = np.zeros(len(self.fingers), dtype=bool)
        q = self.q_open.copy()
        self.bullet.set_posture(self.client, self.body, q)
        d_all = self.object_distance(p.contact_distance_mm)
        if np.min(d_all) < -p.penetration_tolerance_mm:
            return q, [], True

        def moving_links() -> NDArray:
            mv = np.zeros(hand.n_links, dtype=bool)
            for joints, links in self.fingers:
                for i, link in enumerate(links):
                    mv[link] = not held[joints[i]]  # a link moves unless its own joint (and so all proximal) is held
            return mv

        def hold(links_touching: NDArray, q_now: NDArray) -> None:
            for link in np.flatnonzero(links_touching):
                f = self.link_finger_index[link]
                if f < 0:
                    continue
                joints = self.fingers[f][0][: self.link_chain_pos[link] + 1]
                for j in joints:
                    if not held[j]:
                        held[j] = True
                        q_held[j] = q_now[j]

        # links touching (or slightly penetrating) the box in the open posture hold at once
        touching = d_all <= p.contact_distance_mm
        touching[0] = False
        hold(touching, q)
        touched_obj[self.link_finger_index[np.flatnonzero(touching)]] = True

        sigma = p.sigma_open
        mv = moving_links()
        pairs = tuple(pr for pr in self.self_pairs if mv[pr[0]] or mv[pr[1]])
        # gaps (margin _QUERY_MARGIN_MM) at the posture of σ, when already known from the
        # previous step's check or event: every query is made once
        known: tuple[NDArray, NDArray] | None = None
        while sigma < p.sigma_closed:
            if not mv.any():
                break
            q = self.posture(sigma, held, q_held)
            d_obj, d_self = known if known is not None else self.gaps(q, mv, pairs, _QUERY_MARGIN_MM)
            budget = np.full(len(self.fingers), p.step_mm)
            for f, (_, links) in enumerate(self.fingers):
                free = min(float(np.min(d_obj[list(links)])), 0.5 * float(np.min(d_self[list(links)])))
                budget[f] = max(p.step_mm, min(free, _QUERY_MARGIN_MM))
            sigma_next = self.advance(sigma, budget, held)
            if sigma_next <= sigma:
                break
            q_next = self.posture(sigma_next, held, q_held)
            o_next, s_next = self.gaps(q_next, mv, pairs, _QUERY_MARGIN_MM)
            if min(o_next.min(), s_next.min()) >= 0.0:
                sigma, known = sigma_next, (o_next, s_next)
                continue
            # a moving link crosses something in (σ, σ_next]: find where, to within tolerance_mm
            lo, hi = sigma, sigma_next
            d_lo = min(d_obj.min(), d_self.min())
            d_hi = min(o_next.min(), s_next.min())
            side = 0
            o_at, s_at, q_at = None, None, None
            for _ in range(_MAX_REFINE):
                # Illinois false position on the smallest gap, bisection when it stalls
                if np.isfinite(d_lo) and (hi - lo) > 1e-12:
                    mid = hi - d_hi * (hi - lo) / (d_hi - d_lo)
                    if not lo < mid < hi:
                        mid = 0.5 * (lo + hi)
                else:
                    mid = 0.5 * (lo + hi)
                q_mid = self.posture(mid, held, q_held)
                o_mid, s_mid = self.gaps(q_mid, mv, pairs, _QUERY_MARGIN_MM)
                d_mid = min(o_mid.min(), s_mid.min())
                if d_mid < 0.0:
                    hi, d_hi = mid, d_mid
                    if side == -1:
                        d_lo *= 0.5
                    side = -1
                else:
                    lo, d_lo = mid, d_mid
                    o_at, s_at, q_at = o_mid, s_mid, q_mid
                    if d_mid <= p.tolerance_mm:
                        break
                    if side == +1:
                        d_hi *= 0.5
                    side = +1
            if q_at is None:  # never left σ: the gaps at σ are the event
                q_at, o_at, s_at = q, d_obj, d_self
                lo = sigma
            obj_touch = o_at <= p.contact_distance_mm
            self_touch = s_at <= p.contact_distance_mm
            if not (obj_touch.any() or self_touch.any()):
                # refinement ran out of iterations: hold the closest link so the loop progresses
                nearest = np.argmin(np.minimum(o_at, s_at))
                (obj_touch if o_at[nearest] <= s_at[nearest] else self_touch)[nearest] = True
            hold(obj_touch | self_touch, q_at)
            for link in np.flatnonzero(obj_touch):
                touched_obj[self.link_finger_index[link]] = True
            for link in np.flatnonzero(self_touch):
                touched_self[self.link_finger_index[link]] = True
            sigma = lo
            # the posture at σ is q_at again (the new holds keep q_at's values); a link that
            # still moves keeps all its pairs, so its gaps are those of the event
            mv = moving_links()
            pairs = tuple(pr for pr in self.self_pairs if mv[pr[0]] or mv[pr[1]])
            o_at, s_at = o_at.copy(), s_at.copy()
            o_at[~mv] = np.inf
            s_at[~mv] = np.inf
            known = (o_at, s_at)
        q_final = self.posture(min(sigma, p.sigma_closed), held, q_held)
        state = ["contact" if touched_obj[f] else "self" if touched_self[f] else "limit"
                 for f in range(len(self.fingers))]
        return q_final, state, False

    def contacts(self, q: NDArray, placed: ObjectPose) -> tuple[NDArray, NDArray, NDArray, float]:
        """One contact per hand link within contact_distance_mm of the box, at posture q:
        (links (m,), points on the box surface (m, 3) mm, inward unit normals (m, 3),
        deepest penetration mm)."""
        self.bullet.set_posture(self.client, self.body, q)
        pts = self.bullet.closest_points(self.client, self.box, self.body, self.params.contact_distance_mm)
        links, points, normals, depth = [], [], [], 0.0
        for link in sorted(set(int(v) for v in pts.link_b)):
            if link < 0:
                continue
            rows = np.flatnonzero(pts.link_b == link)
            k = rows[np.argmin(pts.distance[rows])]
            point, normal = _box_surface_point(placed, pts.point_b[k], pts.point_a[k], pts.normal_on_b[k])
            links.append(link)
            points.append(point)
            normals.append(normal)
            depth = max(depth, -float(pts.distance[k]))
        return (np.asarray(links, dtype=np.int64), np.asarray(points).reshape(-1, 3),
                np.asarray(normals).reshape(-1, 3), depth)


def _box_surface_point(placed: ObjectPose, on_link: NDArray, on_box: NDArray,
                       normal: NDArray) -> tuple[NDArray, NDArray]:
    """The contact point on the exact box surface and the box's inward unit normal there.

    pybullet's box has rounded edges (collision margin); the link's closest point is
    projected onto the exact box instead. Outside the box: the nearest box point, normal
    from the link point toward it. Inside (penetration): the nearest face.
    """
    R, c, h = placed.rotation, placed.center_mm, placed.half_extents_mm
    local = R.T @ (np.asarray(on_link, dtype=float) - c)
    clamped = np.clip(local, -h, h)
    gap = local - clamped
    if np.linalg.norm(gap) > 1e-6:
        n_local = -gap / np.linalg.norm(gap)
    else:  # link point inside the box: leave through the nearest face
        slack = h - np.abs(local)
        k = int(np.argmin(slack))
        clamped = local.copy()
        sign = 1.0 if local[k] >= 0 else -1.0
        clamped[k] = sign * h[k]
        n_local = np.zeros(3)
        n_local[k] = -sign
    point = R @ clamped + c
    n = R @ n_local
    return point, n / np.linalg.norm(n)


def simulate_pose(closer: _Closer, size_mm: NDArray, placed: ObjectPose) -> ClosureResult:
    """Close the hand of ``closer`` on a box of ``size_mm`` placed at ``placed``."""
    from synergrasp.hand.kinematics import contact_jacobian

    closer.place_box(size_mm, placed)
    q, state, intersects = closer.run()
    n = closer.hand.n_joints
    empty = (np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, n)))
    if intersects:
        return ClosureResult("intersects_open_hand", q, tuple(state), *empty, 0.0)
    links, points, normals, depth = closer.contacts(q, placed)
    if len(links) == 0:
        return ClosureResult("no_contact", q, tuple(state), *empty, 0.0)
    jac = contact_jacobian(closer.hand, q, links, points)
    return ClosureResult("grasp", q, tuple(state), links, points, normals, jac, depth)


def simulate_object(hand: Any, synergies: Any, box: Any, placement: Placement,
                    closure_params: ClosureParams, poses: Iterable[int] | None = None) -> pd.DataFrame:
    """Close the hand on ``box`` at every pose of the placement's grid (or at ``poses``).

    Returns the contacts table (docs/design.md, one row per pose, in the order of
    ``poses``). ``box`` has ``name`` and ``size_mm``. Deterministic.
    """
    grid = pose_grid(placement)
    pose_list = list(range(grid.n_poses)) if poses is None else [int(v) for v in poses]
    for v in pose_list:
        if not 0 <= v < grid.n_poses:
            raise ValueError(f"poses must be in 0 … {grid.n_poses - 1}, got {v}")
    size = np.asarray(box.size_mm, dtype=float)
    closer = _Closer(hand, synergies, closure_params)
    try:
        rows = []
        for pose in pose_list:
            a, b = grid.angles_deg(pose)
            placed = object_pose(placement, size, a, b, hand.palm_normal)
            rows.append(_row(str(box.name), pose, a, b, simulate_pose(closer, size, placed), placed))
    finally:
        closer.close()
    return _table(rows)
