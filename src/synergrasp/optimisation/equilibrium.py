"""Is a closure's end state an equilibrium of the soft-synergy hand? Two per-grasp checks.

Definitions (docs/closure.md, "Equilibrium of the end state"); units mm, rad, N, N·mm; palm frame.

- **Joint torques.** The soft-synergy hand's joints are springs of stiffness k_ss (N·mm/rad)
  about the synergy reference q_r: τ = k_ss (q_r − q), N·mm, with q the end state's joint
  angles and q_r = q_r(σ_closed), the reference at the end of the closure path (both closure
  models end there; ``SynergyPath.closure_range``).
- **Relative torque residual.** The box can balance only the joints that move one of its
  contacts (a non-zero column of the contacts' Jacobian J, (3m, n) mm/rad): call them the box
  joints B. With f the forces the hand applies at the contacts (N, stacked per contact), each
  in its Coulomb cone (‖f_t‖ ≤ μ f·n, n the object's inward normal), the residual is
      r = min_f ‖τ_B − J_Bᵀ f‖ / ‖τ_B‖   (dimensionless, 0 … 1; f = 0 gives 1),
  a second-order-cone programme solved with Clarabel in epigraph form (min s, (s, τ_B/‖τ_B‖ −
  J_Bᵀ f) in a second-order cone), so r itself, not its square, is the solver's objective.
  Joints that move no box contact (fingers blocked by the hand, or free) are left out: their
  torque is carried by hand–hand contacts, which the contacts table does not record, and is
  reported beside r (``torque_other_Nmm``). Joint limits cannot help: q_r lies inside the
  limits, so at a limit the spring pulls the joint back into its range, as the stop does.
  r = 0 where ‖τ_B‖ = 0 (nothing to balance) and NaN where the grasp has no box joint.
- **S1 pushes a contact outside its cone.** S1's closing motion moves contact i with the
  velocity v_i = J_i S1 (mm per unit σ). It pushes the contact outside its friction cone if the
  angle between v_i and the inward normal n_i exceeds atan μ (a motion away from the box,
  angle > 90°, counts too). Contacts S1 does not move (palm, ‖v_i‖ = 0) are not counted.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.optimisation.mechanics import SAME_GRASP_ATOL, contact_frames, first_same_grasp, read_grasps

__all__ = ["EquilibriumParams", "torque_residual", "push_angles_deg", "grasp_equilibrium", "EQUILIBRIUM_COLUMNS"]

#: Clarabel's feasibility and gap tolerances for the residual (on the normalised torque).
RESIDUAL_TOL = 1e-9
#: A Jacobian entry (mm/rad) or a velocity (mm per unit σ) at most this is zero.
_ZERO = 1e-12
#: Per-grasp columns of :func:`grasp_equilibrium` (besides object, closure_model, pose).
EQUILIBRIUM_COLUMNS = ("torque_residual", "torque_box_Nmm", "torque_other_Nmm", "s1_outside_cone", "s1_pushed_contacts")


@dataclass(frozen=True)
class EquilibriumParams:
    """The soft-synergy hand's joint stiffness k_ss (N·mm/rad), the friction coefficient μ and
    the reference posture q_r (rad) at the end of the closure path."""

    k_ss_Nmm_per_rad: float
    mu: float
    reference: NDArray

    @classmethod
    def of(cls, hand, synergies, k_ss_Nmm_per_rad: float, mu: float) -> EquilibriumParams:
        """The parameters of a study: q_r = q_r(σ_closed) along S1 of ``synergies`` within the
        joint limits of ``hand`` (the end of both closure models' path)."""
        from synergrasp.hand.synergies import SynergyPath

        path = SynergyPath.along(synergies, hand.lower, hand.upper)
        _, sigma_closed = path.closure_range(hand.flexion_joints)
        return cls(float(k_ss_Nmm_per_rad), float(mu), path.reference(sigma_closed))

    def torques(self, q: NDArray) -> NDArray:
        """τ = k_ss (q_r − q), N·mm."""
        return self.k_ss_Nmm_per_rad * (np.asarray(self.reference, dtype=float) - np.asarray(q, dtype=float))


def torque_residual(torques: NDArray, jacobian: NDArray, normals: NDArray, mu: float) -> float:
    """min over cone-feasible f of ‖τ_B − J_Bᵀ f‖ / ‖τ_B‖ on the box joints B (module docstring).

    torques (n,) N·mm; jacobian (3m, n) mm/rad; normals (m, 3) inward unit normals; mu > 0.
    Returns NaN if no joint moves a contact, 0 if the box joints carry no torque.
    """
    import clarabel
    import scipy.sparse as sp

    J = np.asarray(jacobian, dtype=float)
    tau = np.asarray(torques, dtype=float)
    box = np.any(np.abs(J) > _ZERO, axis=0)
    if not box.any():
        return float("nan")
    norm = float(np.linalg.norm(tau[box]))
    if norm == 0.0:
        return 0.0
    moved = np.any(np.abs(J.reshape(-1, 3, J.shape[1])) > _ZERO, axis=(1, 2))  # contacts with a finger row
    frames = contact_frames(np.asarray(normals, dtype=float)[moved])
    Jb = J.reshape(-1, 3, J.shape[1])[moved][:, :, box].reshape(-1, int(box.sum()))  # (3k, b)
    k, b = frames.shape[0], Jb.shape[1]
    # x = (s, f); cone 1: (s, u - Jbᵀ f) ∈ SOC(1 + b); cones 2..: (μ n·f_i, t1·f_i, t2·f_i) ∈ SOC(3)
    top = np.zeros((1 + b, 1 + 3 * k))
    top[0, 0] = -1.0
    top[1:, 1:] = Jb.T
    rows = frames.copy()
    rows[:, 0, :] *= mu
    cones_f = np.zeros((3 * k, 1 + 3 * k))
    for i in range(k):
        cones_f[3 * i : 3 * i + 3, 1 + 3 * i : 4 + 3 * i] = -rows[i]
    A = sp.csc_matrix(np.vstack([top, cones_f]))
    rhs = np.concatenate([[0.0], tau[box] / norm, np.zeros(3 * k)])
    cost = np.zeros(1 + 3 * k)
    cost[0] = 1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_feas = settings.tol_gap_abs = settings.tol_gap_rel = RESIDUAL_TOL
    cones = [clarabel.SecondOrderConeT(1 + b)] + [clarabel.SecondOrderConeT(3)] * k
    solution = clarabel.DefaultSolver(sp.csc_matrix((1 + 3 * k, 1 + 3 * k)), cost, A, rhs, cones, settings).solve()
    if str(solution.status) not in ("Solved", "AlmostSolved"):
        return float("nan")
    f = np.asarray(solution.x[1:])
    # the residual of the returned forces (they are in the cones up to the tolerance)
    return float(min(1.0, np.linalg.norm(tau[box] / norm - Jb.T @ f)))


def push_angles_deg(jacobian: NDArray, normals: NDArray, synergy: NDArray) -> NDArray:
    """Per contact, the angle (deg) between S1's contact velocity J_i S1 and the inward normal
    n_i; NaN where S1 does not move the contact."""
    J = np.asarray(jacobian, dtype=float)
    v = (J @ np.asarray(synergy, dtype=float)).reshape(-1, 3)
    speed = np.linalg.norm(v, axis=1)
    n = np.asarray(normals, dtype=float).reshape(-1, 3)
    with np.errstate(invalid="ignore", divide="ignore"):
        cosine = np.clip(np.einsum("ij,ij->i", v, n) / speed, -1.0, 1.0)
    return np.where(speed > _ZERO, np.degrees(np.arccos(cosine)), np.nan)


def _one(row, params: EquilibriumParams, synergy: NDArray) -> dict[str, float]:
    m = int(row.n_contacts)
    tau = params.torques(np.asarray(row.q, dtype=float))
    J = np.asarray(row.jacobian, dtype=float).reshape(3 * m, -1)
    normals = np.asarray(row.contact_normal, dtype=float).reshape(m, 3)
    box = np.any(np.abs(J) > _ZERO, axis=0)
    angles = push_angles_deg(J, normals, synergy)
    limit = np.degrees(np.arctan(params.mu))
    return {
        "torque_residual": torque_residual(tau, J, normals, params.mu),
        "torque_box_Nmm": float(np.linalg.norm(tau[box])),
        "torque_other_Nmm": float(np.linalg.norm(tau[~box])),
        "s1_outside_cone": int(np.sum(angles > limit)),
        "s1_pushed_contacts": int(np.sum(np.isfinite(angles))),
    }


def grasp_equilibrium(contacts: pd.DataFrame, params: EquilibriumParams, synergy: NDArray) -> pd.DataFrame:
    """The two checks for every grasp (status ``grasp``) of a contacts table (``table_contracts.CONTACTS``).

    ``synergy``: S1 (n,), rad per unit σ. Returns one row per grasp: ``object``,
    ``closure_model``, ``pose`` and :data:`EQUILIBRIUM_COLUMNS` (``torque_residual``
    dimensionless, the torque norms N·mm, ``s1_outside_cone`` and ``s1_pushed_contacts``
    counts of contacts). A grasp that is one with an earlier row's (``first_same_grasp``: a
    box's poses one α-period apart) and ends in the same posture (q to ``SAME_GRASP_ATOL``
    rad) shares that row's checks, which depend on nothing else.
    """
    grasps = contacts[(contacts["status"] == "grasp") & (contacts["n_contacts"] > 0)]
    first = first_same_grasp(read_grasps(grasps))
    checks: list[dict[str, float]] = []
    for i, r in enumerate(grasps.itertuples(index=False)):
        j = int(first[i])
        same = j != i and np.allclose(r.q, grasps["q"].iat[j], rtol=0.0, atol=SAME_GRASP_ATOL)
        checks.append(checks[j] if same else _one(r, params, synergy))
    rows = [
        {"object": r.object, "closure_model": r.closure_model, "pose": int(r.pose), **c}
        for r, c in zip(grasps.itertuples(index=False), checks)
    ]
    return pd.DataFrame(rows, columns=["object", "closure_model", "pose", *EQUILIBRIUM_COLUMNS])
