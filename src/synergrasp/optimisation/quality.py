"""Grasp quality indices of one grasp, the measures peer tools report (docs/quality.md).

Units: lengths mm, forces N, torques N·mm; palm frame; the wrench reference point is the
object centre o. Every index that mixes forces and torques divides the torques by a stated
length L (``torque_length_mm``), so that the 6-D wrench space is dimensionless:
w = (f, τ / L). The study uses the object's bounding radius (the largest distance from its
centre to its surface): a torque of L·|f| is then worth a force |f|.

- ``sigma_min``, ``isotropy``: the smallest singular value of the scaled grasp matrix
  G_L (6, 3m) and σ_min / σ_max (Li & Sastry 1988; SynGrasp's ``SGminSVG``, ``SGgraspIsotropyIndex``).
- ``epsilon``: the Ferrari–Canny ε of the fully actuated hand, L1 variant (Ferrari & Canny
  1992; GraspIt!'s ε quality): the radius of the largest ball about the origin inside the
  convex hull of the primitive wrenches w_ij = (f_ij, (p_i − o) × f_ij / L), where the f_ij
  are the ``edges`` edges of each contact's friction cone linearised inside the Coulomb cone,
  each with a unit normal component (total normal force 1). 0 when the origin is not strictly
  inside (no force closure with the linearised cones) or the wrenches span fewer than 6
  dimensions. It ignores the synergy constraint: ε > 0 where the study's verdict fails is
  expected.
- ``manipulability``: the object motions the enrolled synergies can produce with the
  contacts held (no sliding), as the semi-axes of an ellipsoid: with S the synergy matrix
  (n, s) and J the contacts' Jacobian (3m, n), the synergy velocities ż whose contact
  motion J S ż is a rigid motion of the object (in the range of Gᵀ) map to the object twist
  ν = (Gᵀ)⁺ J S ż (linear mm per unit ż; rotation scaled by L); the semi-axes are the singular
  values of that map on the unit ball of such ż, largest first (SynGrasp's manipulability
  ellipsoid under rigid contact, ``SGmanipEllipsoid``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from synergrasp.optimisation.mechanics import Grasp, contact_frames, first_same_grasp, grasp_matrix
from synergrasp.simulation.opposition import HandAxes, OppositionRule, contacts_oppositions

__all__ = [
    "GraspQuality",
    "grasp_quality",
    "scaled_grasp_matrix",
    "primitive_wrenches",
    "ferrari_canny_l1",
    "synergy_manipulability",
    "QualityParams",
    "quality_table",
    "QUALITY_EDGES",
    "RANK_RTOL",
]

#: Edges of the linearised friction cone in ε (GraspIt! uses 8).
QUALITY_EDGES = 8
#: Singular values below this fraction of the largest count as zero (rank decisions).
RANK_RTOL = 1e-9


@dataclass(frozen=True)
class GraspQuality:
    """Quality indices of one grasp (see the module's docstring for each definition).

    rank_G:            rank of the grasp matrix (6: the contacts can resist any wrench)
    sigma_min:         smallest singular value of G_L (dimensionless; 0 if rank_G < 6)
    isotropy:          σ_min / σ_max of G_L (0 … 1)
    epsilon:           Ferrari–Canny ε (L1), in units of the total normal force (0 … 1)
    manipulability:    (6,) semi-axes of the synergy-actuated manipulability ellipsoid, largest
                       first, zero-padded (mm per unit synergy velocity; rotations × L)
    torque_length_mm:  the length L the torques are divided by, mm
    """

    rank_G: int
    sigma_min: float
    isotropy: float
    epsilon: float
    manipulability: NDArray
    torque_length_mm: float


def scaled_grasp_matrix(points: NDArray, center: NDArray, length_mm: float) -> NDArray:
    """G_L (6, 3m): the grasp matrix with its torque rows divided by ``length_mm``."""
    if not length_mm > 0:
        raise ValueError(f"torque_length_mm must be > 0, got {length_mm}")
    G = grasp_matrix(points, center)
    G[3:] /= length_mm
    return G


def primitive_wrenches(grasp: Grasp, mu: float, length_mm: float, edges: int = QUALITY_EDGES) -> NDArray:
    """(m·edges, 6) wrenches of the linearised cones' edges, each with a unit normal force:
    f = n + μ (cos φ_k t1 + sin φ_k t2), φ_k = 2πk / edges, torque about o divided by L."""
    if edges < 3:
        raise ValueError(f"edges must be >= 3, got {edges}")
    frames = contact_frames(grasp.normals)  # rows n, t1, t2
    phi = 2.0 * math.pi * np.arange(edges) / edges
    forces = frames[:, None, 0] + mu * (
        np.cos(phi)[None, :, None] * frames[:, None, 1] + np.sin(phi)[None, :, None] * frames[:, None, 2]
    )
    arms = (grasp.points - grasp.center)[:, None, :]
    torques = np.cross(np.broadcast_to(arms, forces.shape), forces) / length_mm
    return np.concatenate([forces, torques], axis=2).reshape(-1, 6)


def ferrari_canny_l1(wrenches: NDArray, rtol: float = RANK_RTOL) -> float:
    """Radius of the largest ball about the origin inside conv(``wrenches``) (k, 6); 0 if the
    wrenches span fewer than 6 dimensions or the origin is not strictly inside the hull."""
    W = np.asarray(wrenches, dtype=float)
    if W.shape[0] < 7:
        return 0.0
    sv = np.linalg.svd(W, compute_uv=False)
    if sv[5] <= rtol * sv[0]:
        return 0.0
    try:
        hull = ConvexHull(W)
    except QhullError:  # flat hull that the rank test above did not catch
        return 0.0
    # facets a·x + b <= 0 inside, |a| = 1: the origin's distance to facet k is -b_k
    depth = -hull.equations[:, -1]
    scale = float(np.max(np.abs(W)))
    return float(depth.min()) if depth.min() > rtol * scale else 0.0


def synergy_manipulability(grasp: Grasp, synergies: NDArray, length_mm: float, rtol: float = RANK_RTOL) -> NDArray:
    """(6,) semi-axes, largest first, of the object twists ν = (Gᵀ)⁺ J S ż over the unit ball
    of the synergy velocities ż whose contact motion J S ż is rigid (in range(Gᵀ))."""
    G = scaled_grasp_matrix(grasp.points, grasp.center, length_mm)
    JS = grasp.jacobian @ np.asarray(synergies, dtype=float)
    if JS.shape[1] == 0 or not np.any(JS):
        return np.zeros(6)
    Gt_pinv = np.linalg.pinv(G.T, rcond=rtol)
    rigid = G.T @ Gt_pinv  # projector onto range(Gᵀ)
    # synergy velocities whose contact motion has no non-rigid part: null space of (I - P) J S
    off = JS - rigid @ JS
    u, s, vt = np.linalg.svd(off)
    keep = s <= rtol * max(float(np.max(np.abs(JS))), 1.0)
    null = np.concatenate([vt[: len(s)][keep], vt[len(s) :]]).T  # (s, d) orthonormal
    if null.shape[1] == 0:
        return np.zeros(6)
    axes = np.linalg.svd(Gt_pinv @ JS @ null, compute_uv=False)
    axes = axes[axes > rtol * max(float(np.max(np.abs(JS))), 1.0)]  # round-off of an empty direction
    out = np.zeros(6)
    out[: min(6, axes.size)] = axes[:6]
    return out


def grasp_quality(
    grasp: Grasp, mu: float, length_mm: float, synergies: NDArray | None = None, edges: int = QUALITY_EDGES
) -> GraspQuality:
    """Every quality index of one grasp. ``synergies`` (n, s): the enrolled synergies of the
    manipulability ellipsoid (None: no ellipsoid, zeros)."""
    G = scaled_grasp_matrix(grasp.points, grasp.center, length_mm)
    sv = np.linalg.svd(G, compute_uv=False)
    rank = int(np.sum(sv > RANK_RTOL * sv[0])) if sv.size else 0
    sigma_min = float(sv[5]) if rank == 6 else 0.0
    manip = np.zeros(6) if synergies is None else synergy_manipulability(grasp, synergies, length_mm)
    return GraspQuality(
        rank_G=rank,
        sigma_min=sigma_min,
        isotropy=sigma_min / float(sv[0]) if rank == 6 else 0.0,
        epsilon=ferrari_canny_l1(primitive_wrenches(grasp, mu, length_mm, edges)),
        manipulability=manip,
        torque_length_mm=float(length_mm),
    )


@dataclass(frozen=True)
class QualityParams:
    """The quality table of one object (the ``quality`` step): the hand and synergy files
    (None: shipped; all synergies enter the manipulability ellipsoid), μ, the full set's id,
    the object's weight (N) and its bounding radius L (mm), the torque scale."""

    hand: str | None
    synergies: str | None
    mu: float
    full_set_id: str
    weight_N: float
    torque_length_mm: float
    opposition: OppositionRule

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> QualityParams:
        from synergrasp.ids import incremental_set_id
        from synergrasp.resolved import friction_mu, weight_N
        from synergrasp.simulation.objects import GraspedObject

        grasped = GraspedObject.from_config(config, obj)
        return cls(
            config["hand"],
            config["synergies"],
            friction_mu(config),
            incremental_set_id(config["synergy_sets"]["incremental_max"]),
            weight_N(config, obj),
            grasped.shape.bounding_radius_mm,
            OppositionRule.from_config(config),
        )


def quality_table(
    contacts: pd.DataFrame,
    gfo: pd.DataFrame,
    grasps: Sequence[Grasp | None],
    synergy_matrix: NDArray,
    params: QualityParams,
    axes: HandAxes,
) -> pd.DataFrame:
    """One row per pose of ``contacts`` (columns of ``synergrasp.table_contracts.QUALITY``): the quality
    indices of its grasp (``grasps``, one per row; None: no grasp, indices NaN), the full
    set's verdict and optimal force over the weight from ``gfo``, and the grasp's opposition
    (``axes``: the hand's, docs/opposition.md). Poses with one grasp
    (``mechanics.first_same_grasp``: a box's poses one α-period apart) share its indices,
    computed once at the first of them: the ε hull is most of the cost."""
    full = gfo[gfo["set_id"] == params.full_set_id]
    verdicts = {
        int(pose): (bool(closure), float(force) / params.weight_N)
        for pose, closure, force in zip(full["pose"].tolist(), full["force_closure_def1"].tolist(), full["force_norm"].tolist())
    }
    rows = []
    first = first_same_grasp(grasps)
    computed: dict[int, GraspQuality] = {}
    oppositions = contacts_oppositions(contacts, axes, params.opposition)
    for row, grasp, i, opposition in zip(contacts.itertuples(index=False), grasps, first, oppositions):
        out = {
            "object": row.object,
            "pose": row.pose,
            "alpha_deg": row.alpha_deg,
            "beta_deg": row.beta_deg,
            "n_contacts": int(row.n_contacts),
            "rank_G": 0,
            "sigma_min": np.nan,
            "isotropy": np.nan,
            "epsilon": np.nan,
            "manipulability": [np.nan] * 6,
        }
        if grasp is not None:
            if i not in computed:
                computed[i] = grasp_quality(grasp, params.mu, params.torque_length_mm, synergies=synergy_matrix)
            q = computed[i]
            out.update(
                rank_G=q.rank_G,
                sigma_min=q.sigma_min,
                isotropy=q.isotropy,
                epsilon=q.epsilon,
                manipulability=q.manipulability.tolist(),
            )
        out["force_closure"], out["force_per_weight"] = verdicts.get(int(row.pose), (False, np.nan))
        out["torque_length_mm"] = params.torque_length_mm
        out["opposition"] = opposition
        rows.append(out)
    return pd.DataFrame(rows)
