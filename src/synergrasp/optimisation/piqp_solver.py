"""Back end: one GFO problem with a pyramid friction cone solved as a QP by PIQP.

With a pyramid (`cones.PyramidCone`) every constraint is linear, so the problem is
min ½ y^T (E^T E) y + (E^T f_p)^T y subject to G y <= h: per contact the normal bound
-(n.E) y <= n.f_p - f_min and per face (a_k.E) y <= -a_k.f_p. PIQP (a proximal interior
point method for QPs) solves it densely (e_s <= 15 unknowns).
"""

from __future__ import annotations

import numpy as np
import piqp

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
    """Solve one problem with a pyramid cone; e_s = 0 is judged directly.

    tol: PIQP's absolute and relative tolerances; max_iter: its iteration cap. Status
    mapping: solved -> 'feasible' (its forces violate no constraint by more than
    ALMOST_SOLVED_TOL max(1 N, ||f||), else 'numerical_failure'); primal infeasible ->
    'infeasible'; anything else -> 'numerical_failure'.
    """
    if problem.e_s == 0:
        return judge_direct(problem, tol)
    E, fp = problem.E, problem.f_p
    G, h = linear_constraints(problem)
    solver = piqp.DenseSolver()
    solver.settings.verbose = False
    solver.settings.eps_abs = solver.settings.eps_rel = float(tol)
    solver.settings.max_iter = int(max_iter)
    try:
        solver.setup(np.asfortranarray(E.T @ E), E.T @ fp, None, None, np.asfortranarray(G), None, h)
        status = solver.solve()
    except Exception as exc:  # a solver crash on one problem is a verdict, not an abort
        return Outcome("numerical_failure", float("nan"), None, 0, "piqp", f"error: {exc}")
    iterations = int(solver.result.info.iter)
    if status == piqp.PIQP_SOLVED:
        forces = fp + E @ np.asarray(solver.result.x, dtype=float)
        norm = float(np.linalg.norm(forces))
        viol = problem.cone.violation(forces, problem.normals, problem.f_min)
        if viol <= ALMOST_SOLVED_TOL * max(1.0, norm):
            return Outcome("feasible", norm, forces, iterations, "piqp", str(status), viol)
        return Outcome("numerical_failure", float("nan"), None, iterations, "piqp", str(status), viol)
    if status == piqp.PIQP_PRIMAL_INFEASIBLE:
        return Outcome("infeasible", float("nan"), None, iterations, "piqp", str(status))
    return Outcome("numerical_failure", float("nan"), None, iterations, "piqp", str(status))
