"""Which contacts block a synergy set's internal forces (docs/blockers.md).

A set fails Definition 1 at a grasp of rank 6 when no internal force f = E_s y it reaches
lies strictly inside every friction cone. How far it is from doing so, and where, is the
optimum of one small conic problem over the same basis E_s the study's solver uses
(`GraspSets.problem(j).E`, `mechanics.internal_force_basis`):

    maximise t   over y (e_s,), t
    subject to   m_i(f) >= t at every contact i,   sum_i n_i . f_i = 1,   f = E_s y

with the contact's cone margin m_i(f) = mu n_i.f_i - ||f_i - (n_i.f_i) n_i|| (circular cone;
for a pyramid the least of its faces' mu_face n_i.f_i - d_k.f_i). The normalisation fixes
the total normal force at 1 N (margins are N per N of total normal force); it excludes
f = 0, which any other bound (||y|| <= 1) leaves as a maximiser with t = 0 whenever the set
fails. t* > 0 exactly when some reachable internal force is strictly inside every cone.
When t* <= 0 the **blockers** are the contacts whose margin at the optimum lies within
``tol`` of t*: no reachable internal force improves one of them without worsening another
(an interior-point optimum lies in the relative interior of the optimal face, so these are
the contacts active at every optimum).

Solved by Clarabel directly, as the exact GFO back end (`clarabel_solver`) is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from synergrasp.optimisation.mechanics import contact_frames
from synergrasp.optimisation.problem import DEFAULT_TOL, MAX_ITER, GFOProblem

__all__ = ["ACTIVE_TOL", "REASONS", "Blocking", "blocking_contacts", "contact_margins"]

#: A contact is a blocker when its margin lies within this of t* (N per N of total normal
#: force; 100x Clarabel's tolerance, far below the margins of the study's grasps, ~0.01-0.5).
ACTIVE_TOL = 1e-6
#: Why a set fails, as recorded (docs/blockers.md): ``contacts`` (the blockers are named),
#: ``no_internal_force`` (e_s = 0: the set reaches no internal force), ``rank_deficient``
#: (rank(G) < 6), ``no_squeeze`` (every reachable internal force has zero total normal force),
#: ``numerical_failure`` (the solver did not decide).
REASONS: tuple[str, ...] = ("contacts", "no_internal_force", "rank_deficient", "no_squeeze", "numerical_failure")


@dataclass(frozen=True)
class Blocking:
    """The max-margin internal force of one (grasp, set) and its blockers.

    reason: one of REASONS; margin: t*, N per N of total normal force (NaN unless reason is
    ``contacts``); forces: (3m,) the optimal internal force, N per N of total normal force
    (None unless ``contacts``); contact_margin, normal_force: (m,) each contact's margin and
    n_i.f_i at it (same unit); angle_outside_deg: (m,) angle between f_i and the inward normal
    minus atan(mu) (deg; > 0 outside the circular cone, > 90 - atan(mu) for a pulling contact;
    NaN where f_i = 0); blockers: (m,) bool.
    """

    reason: str
    margin: float
    forces: NDArray | None
    contact_margin: NDArray
    normal_force: NDArray
    angle_outside_deg: NDArray
    blockers: NDArray

    @classmethod
    def without_contacts(cls, reason: str, m: int) -> Blocking:
        nan = np.full(m, np.nan)
        return cls(reason, float("nan"), None, nan, nan.copy(), nan.copy(), np.zeros(m, dtype=bool))


def contact_margins(forces: NDArray, problem: GFOProblem) -> NDArray:
    """Each contact's cone margin (m,) of forces (3m,) under the problem's cone: mu n.f - ||f_t||
    (circular) or the least face margin -a_k.f (pyramid); N, as the forces."""
    F = np.asarray(forces, dtype=float).reshape(-1, 3)
    frames = contact_frames(problem.normals)
    if problem.cone.kind == "circular":
        fn = np.einsum("ij,ij->i", F, frames[:, 0])
        return problem.cone.mu * fn - np.linalg.norm(F - fn[:, None] * frames[:, 0], axis=1)
    return -np.einsum("ikj,ij->ik", problem.cone.face_rows(frames), F).max(axis=1)


def blocking_contacts(
    problem: GFOProblem, *, tol: float = ACTIVE_TOL, solver_tol: float = DEFAULT_TOL, max_iter: int = MAX_ITER
) -> Blocking:
    """The blockers of one (grasp, set): its basis E, normals and cone (f_p and f_min are not
    used: the question is about internal forces alone). e_s = 0 gives ``no_internal_force``."""
    m, e = problem.n_contacts, problem.e_s
    if e == 0:
        return Blocking.without_contacts("no_internal_force", m)
    E3 = problem.E.reshape(m, 3, e)
    frames = contact_frames(problem.normals)
    squeeze = np.einsum("ij,ijk->k", frames[:, 0], E3)  # total normal force per unit y
    if np.linalg.norm(squeeze) <= 1e-9 * np.linalg.norm(problem.E):
        return Blocking.without_contacts("no_squeeze", m)
    A, cones = _margin_rows(problem, frames, E3)
    # x = (y, t); minimise -t; first row: sum_i n_i.f_i = 1 (zero cone)
    A = sp.csc_matrix(np.vstack([np.append(squeeze, 0.0)[None, :], A]))
    b = np.zeros(A.shape[0])
    b[0] = 1.0
    q = np.zeros(e + 1)
    q[-1] = -1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = int(max_iter)
    settings.tol_feas = settings.tol_gap_abs = settings.tol_gap_rel = float(solver_tol)
    try:
        sol = clarabel.DefaultSolver(sp.csc_matrix((e + 1, e + 1)), q, A, b, [clarabel.ZeroConeT(1)] + cones, settings).solve()
    except Exception:  # a solver crash on one problem is a recorded reason, not an abort
        return Blocking.without_contacts("numerical_failure", m)
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        return Blocking.without_contacts("numerical_failure", m)
    return _at_optimum(problem, frames, problem.E @ np.asarray(sol.x, dtype=float)[:e], tol)


def _margin_rows(problem: GFOProblem, frames: NDArray, E3: NDArray):
    """Clarabel rows (A x + s = b, b = 0) of m_i(f) >= t, x = (y, t): per contact the SOC
    (mu n.f - t, t1.f, t2.f), or per pyramid face -a_k.f - t >= 0."""
    m, e = E3.shape[0], E3.shape[2]
    if problem.cone.kind == "circular":
        R = problem.cone.soc_rows(frames)  # [mu n; t1; t2]
        RE = np.einsum("iab,ibk->iak", R, E3)
        last = np.zeros((m, 3, 1))
        last[:, 0, 0] = -1.0
        rows = -np.concatenate([RE, last], axis=2).reshape(3 * m, e + 1)
        return rows, [clarabel.SecondOrderConeT(3)] * m
    faces = problem.cone.face_rows(frames)  # (m, sides, 3)
    FE = np.einsum("isj,ijk->isk", faces, E3).reshape(-1, e)
    rows = np.hstack([FE, np.ones((FE.shape[0], 1))])
    return rows, [clarabel.NonnegativeConeT(FE.shape[0])]


def _at_optimum(problem: GFOProblem, frames: NDArray, forces: NDArray, tol: float) -> Blocking:
    F = forces.reshape(-1, 3)
    margin = contact_margins(forces, problem)
    t = float(margin.min())
    fn = np.einsum("ij,ij->i", F, frames[:, 0])
    ft = np.linalg.norm(F - fn[:, None] * frames[:, 0], axis=1)
    size = np.linalg.norm(F, axis=1)
    with np.errstate(invalid="ignore"):
        angle = np.degrees(np.arctan2(ft, fn)) - math.degrees(math.atan(problem.cone.mu))
    angle[size <= 1e-12] = np.nan
    return Blocking("contacts", t, forces, margin, fn, angle, margin <= t + tol)
