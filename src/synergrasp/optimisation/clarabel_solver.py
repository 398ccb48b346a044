"""Back end: one GFO problem solved exactly by Clarabel (conic QP), circular or pyramid cone.

Minimising ½||f_p + E y||² has the argmin of ||f_p + E y||, so the problem is passed to
Clarabel as a QP over cones: P = E^T E (= I for an orthonormal E), q = E^T f_p, and per
contact the rows of the nonnegative cone (n.f - f_min >= 0) and of SOC(3) (the rows
[mu n; t1; t2] of `CircularCone.soc_rows` applied to f), or, for a pyramid, the linear rows
of `problem.linear_constraints` in one nonnegative cone. Also the fallback of the compiled
interior-point back end for the problems it leaves undecided (`gfo.solve_gfo`).
"""

from __future__ import annotations

import clarabel
import numpy as np
import scipy.sparse as sp

from synergrasp.optimisation.mechanics import contact_frames
from synergrasp.optimisation.problem import (
    ALMOST_SOLVED_TOL,
    DEFAULT_TOL,
    MAX_ITER,
    GFOProblem,
    Outcome,
    judge_direct,
    linear_constraints,
)

__all__ = ["solve"]


def solve(problem: GFOProblem, *, tol: float = DEFAULT_TOL, max_iter: int = MAX_ITER) -> Outcome:
    """Solve one problem; e_s = 0 is judged by `judge_direct`.

    tol: Clarabel's feasibility, gap and infeasibility tolerances; max_iter: its iteration
    cap. Status mapping (docs/force_optimisation.md): Solved -> 'feasible';
    AlmostSolved -> 'feasible' if the point violates no constraint by more than
    ALMOST_SOLVED_TOL max(1 N, ||f||), else 'numerical_failure'; PrimalInfeasible and
    AlmostPrimalInfeasible -> 'infeasible'; anything else -> 'numerical_failure'.
    A solver failure is a status, never an exception.
    """
    if problem.e_s == 0:
        return judge_direct(problem, tol)
    Em, fp = problem.E, problem.f_p
    A, b, cones = _conic_constraints(problem) if problem.cone.kind == "circular" else _linear_constraints(problem)
    P = sp.csc_matrix(np.triu(Em.T @ Em))
    q = Em.T @ fp

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = int(max_iter)
    settings.tol_feas = settings.tol_gap_abs = settings.tol_gap_rel = float(tol)
    settings.tol_infeas_abs = settings.tol_infeas_rel = float(tol)
    try:
        sol = clarabel.DefaultSolver(P, q, A, b, cones, settings).solve()
    except Exception as exc:  # a solver crash on one problem is a verdict, not an abort
        return Outcome("numerical_failure", float("nan"), None, 0, "clarabel", f"error: {exc}")
    return _verdict(str(sol.status), np.asarray(sol.x, dtype=float), int(sol.iterations), problem)


def _conic_constraints(problem: GFOProblem):
    """Constraints as A y + s = b, s in K (Clarabel's form), f = f_p + E y:
    n_i.f - f_min >= 0 -> rows -(N E), b = N f_p - f_min (nonnegative cone, m);
    R_i f_i in SOC(3) -> rows -(R E), b = R f_p (m cones of size 3)."""
    fp, Em, n, f_min = problem.f_p, problem.E, problem.normals, problem.f_min
    m, e = problem.n_contacts, problem.e_s
    E3 = Em.reshape(m, 3, e)
    R = problem.cone.soc_rows(contact_frames(n))
    NE = np.einsum("ij,ijk->ik", n, E3)
    RE = np.einsum("iab,ibk->iak", R, E3).reshape(3 * m, e)
    A = sp.csc_matrix(-np.vstack([NE, RE]))
    F3 = fp.reshape(m, 3)
    b = np.concatenate([np.einsum("ij,ij->i", n, F3) - f_min, np.einsum("iab,ib->ia", R, F3).ravel()])
    return A, b, [clarabel.NonnegativeConeT(m)] + [clarabel.SecondOrderConeT(3)] * m


def _linear_constraints(problem: GFOProblem):
    """A pyramid's constraints G y <= h as A = G, b = h in one nonnegative cone."""
    G, h = linear_constraints(problem)
    return sp.csc_matrix(G), h, [clarabel.NonnegativeConeT(h.size)]


def _verdict(name: str, x: np.ndarray, iterations: int, problem: GFOProblem) -> Outcome:
    if name in ("Solved", "AlmostSolved"):
        forces = problem.f_p + problem.E @ x
        norm = float(np.linalg.norm(forces))
        viol = problem.cone.violation(forces, problem.normals, problem.f_min)
        if name == "Solved" or viol <= ALMOST_SOLVED_TOL * max(1.0, norm):
            return Outcome("feasible", norm, forces, iterations, "clarabel", name, viol)
        return Outcome("numerical_failure", float("nan"), None, iterations, "clarabel", name, viol)
    if name in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
        return Outcome("infeasible", float("nan"), None, iterations, "clarabel", name)
    return Outcome("numerical_failure", float("nan"), None, iterations, "clarabel", name)
