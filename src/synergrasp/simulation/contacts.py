"""The outcome of one closure and the contacts table (``results/objects/<object>/contacts.parquet``).

Every closure model returns a :class:`ClosureResult`; :func:`contacts_row` turns it into a
row of the table whose columns, types and units are ``synergrasp.table_contracts.CONTACTS``;
:func:`load_carrying_contacts` keeps the contacts that carry load (where the closure model
records loads). Pure numpy and pandas: pybullet is never imported here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp import table_contracts
from synergrasp.simulation.placement import ObjectPose

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand

__all__ = [
    "CLOSURE_STATUSES",
    "FINGER_STATES",
    "ClosureResult",
    "closure_result",
    "contacts_row",
    "contacts_table",
    "ContactsParams",
    "load_carrying_contacts",
]

CLOSURE_STATUSES: tuple[str, ...] = ("grasp", "intersects_open_hand", "no_contact", "caged", "lost")
"""``grasp``: the closure ran and at least one link touches the box; ``intersects_open_hand``:
the box overlaps the open hand (only the ``fixed`` placement can give it); ``no_contact``:
the closure ran, nothing touches the box (or, once the unloaded contacts are dropped, nothing
that touches it carries load); ``caged`` and ``lost`` (dynamic model only): the closing hand
moved the free box and nothing touches it at the end; ``caged``: its centre is inside the
closed hand (the convex hull of the hand's links, ``HandCapsules.encloses``), loose in the
fist; ``lost``: pushed out of the hand."""

FINGER_STATES: tuple[str, ...] = ("contact", "limit", "self")
"""How a finger ended: ``contact`` (one of its links touches the box), ``self`` (stopped by
another part of the hand), ``limit`` (followed the reference to the end of the closure path)."""


@dataclass(frozen=True)
class ClosureResult:
    """The outcome of one closure, palm frame.

    status:        one of CLOSURE_STATUSES
    q:             (19,) final joint angles, rad
    finger_state:  per finger thumb…little, one of FINGER_STATES (empty if the box
                   intersects the open hand)
    links:         (m,) hand link index per contact (0 = palm)
    points:        (m, 3) contact points on the object surface, mm
    normals:       (m, 3) object's inward unit normals
    jacobian:      (3m, 19) translational Jacobian of the contact points, mm/rad
    max_penetration_mm: deepest penetration among the contacts (0 if none)
    model:         closure model that made it (``kinematic``, ``dynamic`` or ``dynamic_held``)
    normal_force_N: (m,) normal force per contact at the settled state, N (NaN if unknown)
    settled_pose:  the box's final pose (``ObjectPose``) when it moved (dynamic model);
                   None: it stayed where it was placed
    settled:       the closure ended at rest (False: at the dynamic model's time limit)
    """

    status: str
    q: NDArray
    finger_state: tuple[str, ...]
    links: NDArray
    points: NDArray
    normals: NDArray
    jacobian: NDArray
    max_penetration_mm: float
    model: str = "kinematic"
    normal_force_N: NDArray | None = None
    settled_pose: ObjectPose | None = None
    settled: bool = True


def closure_result(
    hand: Hand,
    q: NDArray,
    finger_state: Sequence[str],
    links: NDArray,
    points: NDArray,
    normals: NDArray,
    max_penetration_mm: float,
    intersects_open_hand: bool = False,
) -> ClosureResult:
    """The :class:`ClosureResult` of a final posture ``q`` (rad) and its contacts (links,
    points mm, inward normals): the status follows from them, the Jacobian rows are
    ``hand.contact_jacobian`` at q (zero rows for the palm)."""
    from synergrasp.hand.kinematics import contact_jacobian

    n = hand.n_joints
    empty = (np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, n)))
    if intersects_open_hand:
        return ClosureResult("intersects_open_hand", q, tuple(finger_state), *empty, 0.0)
    if len(links) == 0:
        return ClosureResult("no_contact", q, tuple(finger_state), *empty, 0.0)
    jac = contact_jacobian(hand, q, links, points)
    return ClosureResult(
        "grasp",
        q,
        tuple(finger_state),
        np.asarray(links),
        np.asarray(points),
        np.asarray(normals),
        jac,
        float(max_penetration_mm),
    )


def contacts_row(
    object_name: str, pose: int, alpha_deg: float, beta_deg: float, result: ClosureResult, placed: ObjectPose
) -> dict[str, Any]:
    """One row of the contacts table (``table_contracts.CONTACTS``) from a closure result; the box pose
    columns hold its settled pose (``result.settled_pose``, else ``placed``)."""
    final = placed if result.settled_pose is None else result.settled_pose
    forces = (
        np.full(len(result.links), np.nan) if result.normal_force_N is None else np.asarray(result.normal_force_N, dtype=float)
    )
    turn = final.rotation @ placed.rotation.T
    angle = float(np.degrees(np.arccos(np.clip(0.5 * (np.trace(turn) - 1.0), -1.0, 1.0))))
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
        "object_center": [float(v) for v in final.center_mm],
        "object_rotation": [float(v) for v in np.ravel(final.rotation)],
        "max_penetration_mm": float(result.max_penetration_mm),
        "closure_model": result.model,
        "contact_normal_force_N": [float(v) for v in forces],
        "object_translation_mm": [float(v) for v in final.center_mm - placed.center_mm],
        "object_rotation_deg": angle,
        "settled": bool(result.settled),
    }


def contacts_table(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The contacts table of a list of :func:`contacts_row` rows, in the contract's column order."""
    table = pd.DataFrame(rows, columns=list(table_contracts.CONTACTS.names))
    for col in ("pose", "n_contacts"):
        table[col] = table[col].astype(np.int32)
    return table


@dataclass(frozen=True)
class ContactsParams:
    """Which contacts of a closure count (the ``contacts`` step). ``drop_unloaded``: keep only
    the contacts carrying at least ``load_threshold_N`` (N); only the dynamic model records
    loads (None otherwise)."""

    drop_unloaded: bool
    load_threshold_N: float | None

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> ContactsParams:
        """From a configuration or the step's own part of it; ``obj`` is not read (every
        object's closure is selected alike)."""
        closure = config["closure"]
        if closure["model"] != "dynamic":
            return cls(False, None)
        return cls(closure["dynamic"]["unloaded_contacts"] == "drop", closure["dynamic"]["load_threshold_N"])


def load_carrying_contacts(table: pd.DataFrame, threshold_N: float) -> pd.DataFrame:
    """The contacts table with only the contacts whose normal force is at least ``threshold_N``
    (N) in each row: its links, points, normals, Jacobian rows and forces kept, ``n_contacts``
    counted again, and a ``grasp`` left without any contact made ``no_contact``. Every other
    column is the closure's own (``max_penetration_mm`` stays the deepest touching link's)."""
    out = table.reset_index(drop=True)
    for i, row in enumerate(table.itertuples(index=False)):
        forces = np.asarray(row.contact_normal_force_N, dtype=float)
        if np.isnan(forces).any():
            raise ValueError(
                f"contacts table, pose {row.pose}: the closure model ({row.closure_model}) "
                "recorded no contact loads, so none can be selected by load"
            )
        if row.status != "grasp" or np.all(forces >= threshold_N):
            continue
        keep = np.flatnonzero(forces >= threshold_N)
        jac = np.asarray(row.jacobian, dtype=float).reshape(3 * len(forces), -1)
        jac_rows = (3 * keep[:, None] + np.arange(3)).ravel()
        out.at[i, "n_contacts"] = len(keep)
        out.at[i, "contact_link"] = [int(v) for v in np.asarray(row.contact_link)[keep]]
        for col in ("contact_point", "contact_normal"):
            out.at[i, col] = [float(v) for v in np.asarray(getattr(row, col), dtype=float).reshape(-1, 3)[keep].ravel()]
        out.at[i, "jacobian"] = [float(v) for v in jac[jac_rows].ravel()]
        out.at[i, "contact_normal_force_N"] = [float(v) for v in forces[keep]]
        if len(keep) == 0:
            out.at[i, "status"] = "no_contact"
    return out
