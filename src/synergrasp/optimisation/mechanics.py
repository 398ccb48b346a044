"""Grasp mechanics in the palm frame: grasp matrix, contact stiffness, K-weighted
pseudo-inverse, particular force solution and the synergy-driven internal forces.

Conventions (docs/design.md): lengths in mm, forces in N, torques in N·mm, joint
stiffness in N·mm/rad, contact stiffness in N/mm. Contact forces are the forces the hand
applies to the object, stacked per contact as (f_1x, f_1y, f_1z, f_2x, ...) with c = 3m
components. The wrench reference point is the object centre o.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgError, lapack
from numpy.typing import NDArray

from synergrasp.hand.kinematics import cross_rows

__all__ = [
    "Grasp",
    "GraspMechanics",
    "contact_frames",
    "contact_stiffness",
    "first_same_grasp",
    "grasp_matrix",
    "grasp_mechanics",
    "internal_force_basis",
    "weight_wrench",
    "read_grasps",
    "same_grasp",
]

#: Relative tolerance of the rank decision on the dimensionless grasp matrix.
GRASP_RANK_RTOL = 1e-9
#: Relative tolerance of the rank decision for the internal-force basis E_s.
BASIS_RTOL = 1e-9
#: How far a normal may be from unit length before it is rejected.
_UNIT_TOL = 1e-6
#: Two grasps are one when their contact links are equal and their points and centre (mm),
#: normals and Jacobians (mm/rad) agree to this, entry by entry (``same_grasp``).
SAME_GRASP_ATOL = 1e-9


@dataclass(frozen=True)
class Grasp:
    """One simulated grasp, every quantity in the palm frame.

    points:   (m, 3) contact points on the object surface, mm
    normals:  (m, 3) object's inward unit surface normals
    links:    (m,) int, hand link index of each contact (0 = palm)
    jacobian: (3m, n) translational Jacobian of the contact points, mm/rad
              (rows of palm contacts are zero)
    center:   (3,) object centre o, mm (reference point of the wrench)
    """

    points: NDArray
    normals: NDArray
    links: NDArray
    jacobian: NDArray
    center: NDArray

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=float)
        m = points.shape[0] if points.ndim == 2 else -1
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(f"Grasp.points must have shape (m, 3), got {points.shape}")
        normals = _unit_normals(self.normals, m, "Grasp.normals")
        links = np.asarray(self.links)
        if links.shape != (m,) or not np.issubdtype(links.dtype, np.integer):
            raise ValueError(f"Grasp.links must be an int array of shape ({m},), got {links.dtype} {links.shape}")
        jac = np.asarray(self.jacobian, dtype=float)
        if jac.ndim != 2 or jac.shape[0] != 3 * m:
            raise ValueError(f"Grasp.jacobian must have shape (3m, n) = ({3 * m}, n), got {jac.shape}")
        center = np.asarray(self.center, dtype=float)
        if center.shape != (3,):
            raise ValueError(f"Grasp.center must have shape (3,), got {center.shape}")
        for name, value in (("points", points), ("normals", normals), ("jacobian", jac), ("center", center)):
            if not np.isfinite(value).all():
                raise ValueError(f"Grasp.{name} must be finite")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "normals", normals)
        object.__setattr__(self, "links", links.astype(np.int64))
        object.__setattr__(self, "jacobian", jac)
        object.__setattr__(self, "center", center)

    @property
    def n_contacts(self) -> int:
        return int(self.points.shape[0])


def same_grasp(a: Grasp, b: Grasp, atol: float = SAME_GRASP_ATOL) -> bool:
    """Whether two grasps are one: the same contact links, and points, normals, Jacobian and
    centre equal to ``atol`` entry by entry (mm, unit normals, mm/rad). A box's poses one
    α-period apart fill the same region and close to the same grasp up to round-off
    (1e-12 mm on the study's boxes)."""
    return bool(
        np.array_equal(a.links, b.links)
        and a.jacobian.shape == b.jacobian.shape
        and all(
            np.allclose(x, y, rtol=0.0, atol=atol)
            for x, y in ((a.points, b.points), (a.normals, b.normals), (a.center, b.center), (a.jacobian, b.jacobian))
        )
    )


def first_same_grasp(grasps: Sequence[Grasp | None]) -> NDArray:
    """Per grasp, the index of the first grasp of the sequence that is the same one
    (``same_grasp``; its own index for the first of its kind), -1 for None.

    Whatever is computed from a grasp alone (its quality, its optimal forces) is computed
    once, at that first index, and shared: then a pose's result depends on the first grasp
    of its kind only, not on which other poses a job computes. Candidates are bucketed by
    links and points rounded to 1e-6 mm; twins that straddle a rounding boundary are kept
    apart, which only costs a computation."""
    first = np.full(len(grasps), -1, dtype=np.intp)
    buckets: dict[tuple, list[int]] = {}
    for i, grasp in enumerate(grasps):
        if grasp is None:
            continue
        key = (tuple(grasp.links.tolist()), tuple(np.round(grasp.points, 6).ravel().tolist()))
        bucket = buckets.setdefault(key, [])
        first[i] = next((j for j in bucket if same_grasp(grasp, grasps[j])), i)  # type: ignore[arg-type]
        if first[i] == i:
            bucket.append(i)
    return first


def read_grasps(table) -> list[Grasp | None]:
    """One :class:`synergrasp.optimisation.mechanics.Grasp` per row of a contacts table, in row order.

    Rows whose status is not ``grasp`` or that have no contact give ``None``. Reads only
    numbers: pybullet is not imported.
    """
    missing = [
        c
        for c in ("status", "n_contacts", "contact_link", "contact_point", "contact_normal", "jacobian", "object_center")
        if c not in table.columns
    ]
    if missing:
        raise ValueError(f"contacts table: missing column(s) {missing}")
    grasps: list[Grasp | None] = []
    columns = (
        table[c] for c in ("status", "n_contacts", "contact_point", "contact_normal", "contact_link", "jacobian", "object_center")
    )
    for status, n_contacts, points, normals, links, jacobian, center in zip(*columns):
        m = int(n_contacts)
        if status != "grasp" or m == 0:
            grasps.append(None)
            continue
        jac = np.asarray(jacobian, dtype=float)
        grasps.append(
            Grasp(
                points=np.asarray(points, dtype=float).reshape(m, 3),
                normals=np.asarray(normals, dtype=float).reshape(m, 3),
                links=np.asarray(links, dtype=np.int64),
                jacobian=jac.reshape(3 * m, jac.size // (3 * m)),
                center=np.asarray(center, dtype=float),
            )
        )
    return grasps


def _unit_normals(normals: NDArray, m: int | None, field: str) -> NDArray:
    """Validate an (m, 3) array of unit vectors (returned as float)."""
    n = np.asarray(normals, dtype=float)
    if n.ndim != 2 or n.shape[1] != 3 or (m is not None and n.shape[0] != m):
        want = f"({m}, 3)" if m is not None else "(m, 3)"
        raise ValueError(f"{field} must have shape {want}, got {n.shape}")
    norms = _row_norms(n)
    if n.shape[0] and not (np.abs(norms - 1.0) <= _UNIT_TOL).all():
        raise ValueError(
            f"{field} must be unit vectors (|n| = 1 within {_UNIT_TOL}); got norms {norms.min():.6g}..{norms.max():.6g}"
        )
    return n


def _row_norms(a: NDArray) -> NDArray:
    """Euclidean norm of each row of an (m, 3) array: the arithmetic of
    np.linalg.norm(a, axis=1) (the square root of add.reduce of the squares), without its
    argument handling, which cost more than the arithmetic for a grasp's few contacts."""
    return np.sqrt((a * a).sum(axis=1))


def _cross_matrices(v: NDArray) -> NDArray:
    """(m, 3) vectors -> (m, 3, 3) matrices [v]x with [v]x w = v x w."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def grasp_matrix(points: NDArray, center: NDArray) -> NDArray:
    """Grasp matrix G (6, 3m): column block i is [I3; [p_i - o]x].

    G f gives the net force (N, rows 0-2) and the torque about the centre o (N·mm, rows
    3-5) of the contact forces f (N) applied at the points p_i (mm).
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (m, 3), got {p.shape}")
    o = np.asarray(center, dtype=float)
    if o.shape != (3,):
        raise ValueError(f"center must have shape (3,), got {o.shape}")
    m = p.shape[0]
    blocks = np.empty((2, 3, m, 3))
    blocks[0] = np.broadcast_to(np.eye(3)[:, None, :], (3, m, 3))
    blocks[1] = _cross_matrices(p - o).transpose(1, 0, 2)
    return blocks.reshape(6, 3 * m)


def weight_wrench(weight_N: float, gravity_direction: NDArray) -> NDArray:
    """Wrench w_e (6,) the contacts must apply against a weight of ``weight_N`` (N) along
    ``gravity_direction`` (normalised here): [-W ĝ; 0] (N, N·mm)."""
    d = np.asarray(gravity_direction, dtype=float)
    w = np.zeros(6)
    w[:3] = -weight_N * d / np.linalg.norm(d)
    return w


def contact_stiffness(jacobian: NDArray, k_stru: float, k_ss: float) -> NDArray:
    """Contact stiffness K = (C_s + J C_q J^T)^-1 (c, c), N/mm.

    C_s = I/k_stru (mm/N) is the structural compliance of the contacts, C_q = I/k_ss
    (rad/(N·mm)) the joint compliance. C is symmetric positive definite, so K is obtained by
    a Cholesky solve and symmetrised against round-off.
    """
    if not (np.isfinite(k_stru) and k_stru > 0):
        raise ValueError(f"k_stru must be a finite number > 0 (N/mm), got {k_stru}")
    if not (np.isfinite(k_ss) and k_ss > 0):
        raise ValueError(f"k_ss must be a finite number > 0 (N·mm/rad), got {k_ss}")
    J = np.asarray(jacobian, dtype=float)
    if J.ndim != 2:
        raise ValueError(f"jacobian must be a 2-D array (c, n), got shape {J.shape}")
    c = J.shape[0]
    compliance = np.eye(c) / k_stru + (J @ J.T) / k_ss
    K = _spd_solve(compliance, np.eye(c))
    return 0.5 * (K + K.T)


def _spd_solve(A: NDArray, B: NDArray) -> NDArray:
    """A^-1 B for a symmetric positive definite A, by Cholesky (LAPACK potrf, potrs): the
    routines and arithmetic of scipy's cho_factor / cho_solve, without their wrappers'
    checks and conversions (~20 us a call, the same order as the solve for a grasp's sizes)."""
    L, info = lapack.dpotrf(A, lower=1, clean=0)
    if info == 0:
        X, info = lapack.dpotrs(L, B, lower=1)
    if info != 0:
        raise LinAlgError(f"Cholesky solve failed (LAPACK info {info}): the matrix is not positive definite")
    return X


def _grasp_rank(G: NDArray, points: NDArray, center: NDArray, rtol: float) -> int:
    """Numerical rank of G, decided on its dimensionless form.

    The torque rows are in mm, the force rows dimensionless; dividing the torque rows by the
    largest lever arm makes the singular values comparable, so that `rtol` is a pure number.
    """
    if G.shape[1] == 0:
        return 0
    arm = float(_row_norms(points - center).max())
    scaled = G.copy()
    if arm > 0:
        scaled[3:] /= arm
    sv = np.linalg.svd(scaled, compute_uv=False)
    return int(np.sum(sv > rtol * sv[0]))


@dataclass(frozen=True)
class GraspMechanics:
    """Everything about a grasp that does not depend on the synergy set (one per pose).

    G:          (6, c) grasp matrix
    K:          (c, c) contact stiffness, N/mm
    GKR:        (c, 6) K-weighted right pseudo-inverse K G^T (G K G^T)^-1, or None if rank(G) < 6
    f_p:        (c,) particular contact forces G_K^R w_e, N, or None if rank(G) < 6
    projector:  (c, n) (I - G_K^R G) K J, N/rad, or None if rank(G) < 6;
                F_s = projector @ S for a synergy subset S (n, s)
    rank_G:     numerical rank of G
    normals:    (m, 3) inward unit normals
    links:      (m,) link index per contact
    wrench:     (6,) w_e, N and N·mm
    KJ:         (c, n) K J, N/rad (the contact-force response to joint motion)
    response_norm: ||K J||_2, N/rad: the scale of the rank decision of E_s
                (`internal_force_basis`)
    frames:     (m, 3, 3) the contact frames of the normals (`contact_frames`), computed
                when first read
    """

    G: NDArray
    K: NDArray
    GKR: NDArray | None
    f_p: NDArray | None
    projector: NDArray | None
    rank_G: int
    normals: NDArray
    links: NDArray
    wrench: NDArray
    KJ: NDArray
    response_norm: float

    @property
    def n_contacts(self) -> int:
        return int(self.normals.shape[0])

    @functools.cached_property
    def frames(self) -> NDArray:
        return contact_frames(self.normals)


def grasp_mechanics(
    grasp: Grasp,
    wrench: NDArray,
    k_stru: float,
    k_ss: float,
    rank_rtol: float = GRASP_RANK_RTOL,
) -> GraspMechanics:
    """Compute G, K, G_K^R, f_p and the internal-force projector of a grasp.

    wrench: (6,) w_e the contacts must apply (see `weight_wrench`), N and N·mm.
    A grasp with rank(G) < 6 is recorded (rank_G, and None for GKR, f_p and projector);
    it is never an error.
    """
    w = np.asarray(wrench, dtype=float)
    if w.shape != (6,) or not np.isfinite(w).all():
        raise ValueError(f"wrench must be a finite array of shape (6,), got {w.shape}")
    G = grasp_matrix(grasp.points, grasp.center)
    K = contact_stiffness(grasp.jacobian, k_stru, k_ss)
    KJ = K @ grasp.jacobian
    rank = _grasp_rank(G, grasp.points, grasp.center, rank_rtol)
    GKR = f_p = projector = None
    if rank == 6:
        GK = G @ K
        # G K G^T is SPD when rank(G) = 6; G_K^R = K G^T A^-1 = (A^-1 G K)^T since K, A symmetric.
        A = GK @ G.T
        GKR = _spd_solve(0.5 * (A + A.T), GK).T
        f_p = GKR @ w
        projector = KJ - GKR @ (G @ KJ)
    return GraspMechanics(
        G=G,
        K=K,
        GKR=GKR,
        f_p=f_p,
        projector=projector,
        rank_G=rank,
        normals=grasp.normals,
        links=grasp.links,
        wrench=w,
        KJ=KJ,
        response_norm=_spectral_norm(KJ),
    )


def internal_force_basis(
    projector: NDArray,
    synergy_matrix: NDArray,
    response_norm: float,
    rtol: float = BASIS_RTOL,
) -> NDArray:
    """Orthonormal basis E_s (c, e_s) of range(F_s), F_s = projector @ synergy_matrix.

    synergy_matrix: (n, s) the enrolled synergy columns S (rad per unit activation);
    response_norm: ||K J||_2 (N/rad, `GraspMechanics.response_norm`).
    Rank decision: a singular value of F_s counts if it exceeds
    rtol * ||K J||_2 * ||S||_2, the size of the contact forces the enrolled synergies can
    produce at all. The scale depends neither on how much the subset cancels nor on how much
    the projection (I - G_K^R G) removes, so internal forces that are round-off of K J S get
    e_s = 0 instead of a basis of noise, also where every motion of the hand moves the object
    rigidly and the projector itself is round-off (docs/force_optimisation.md).
    """
    P = np.asarray(projector, dtype=float)
    S = np.asarray(synergy_matrix, dtype=float)
    if S.ndim == 1:
        S = S[:, None]
    if P.ndim != 2 or S.ndim != 2 or P.shape[1] != S.shape[0]:
        raise ValueError(f"projector (c, n) and synergy_matrix (n, s) must agree in n; got {P.shape} and {S.shape}")
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ValueError(f"rtol must be in (0, 1), got {rtol}")
    c = P.shape[0]
    if S.shape[1] == 0 or c == 0:
        return np.zeros((c, 0))
    scale = float(response_norm) * _spectral_norm(S)
    if scale == 0.0:
        return np.zeros((c, 0))
    U, sv, _ = np.linalg.svd(P @ S, full_matrices=False)
    rank = int(np.sum(sv > rtol * scale))
    return U[:, :rank].copy()


def _spectral_norm(A: NDArray) -> float:
    # the largest singular value: np.linalg.norm(A, 2)'s arithmetic, without its dispatch
    return float(np.linalg.svd(A, compute_uv=False)[0]) if A.size else 0.0


def contact_frames(normals: NDArray) -> NDArray:
    """Orthonormal contact frames (m, 3, 3), rows [n; t1; t2] per contact (one per unit normal).

    t1 is the normalised cross product of n with the coordinate axis least aligned with n
    (never nearly parallel to n), t2 = n x t1, so (n, t1, t2) is right-handed and
    deterministic. Every friction-cone model and every solver back end takes its rows from
    these frames (`synergrasp.optimisation.cones`).
    """
    n = _unit_normals(normals, None, "normals")
    axis = np.zeros_like(n)
    axis[np.arange(n.shape[0]), np.argmin(np.abs(n), axis=1)] = 1.0
    t1 = cross_rows(n, axis)
    t1 /= _row_norms(t1)[:, None]
    t2 = cross_rows(n, t1)
    return np.stack([n, t1, t2], axis=1)
