"""Back end: the cvxpy reference, written from the method text (tests and benchmarks).

The objective is the norm itself (cp.norm), the circular cones are cp.SOC on the
tangential part f_i - (n_i.f_i) n_i (no tangent basis), and cvxpy's canonicalisation builds
the conic problem, so this shares neither the formulation nor the matrix assembly of the
other back ends. The conic solver is cvxpy's CLARABEL unless told otherwise.
"""

from __future__ import annotations

import numpy as np

from synergrasp.optimisation.problem import GFOProblem, Outcome

__all__ = ["solve"]

#: Violation (N) below which f = f_p counts as admissible when e_s = 0.
_DIRECT_TOL = 1e-8


def solve(problem: GFOProblem, *, solver: str = "CLARABEL") -> Outcome:
    """Solve one problem through cvxpy. Status mapping: optimal and optimal_inaccurate ->
    'feasible'; infeasible and infeasible_inaccurate -> 'infeasible'; anything else ->
    'numerical_failure'."""
    import cvxpy as cp

    fp, Em, n, f_min, mu = problem.f_p, problem.E, problem.normals, problem.f_min, problem.cone.mu
    m, e = problem.n_contacts, problem.e_s
    name = f"cvxpy:{solver}"
    if e == 0:
        F = fp.reshape(m, 3)
        fn = np.sum(F * n, axis=1)
        ft = np.sqrt(np.maximum(np.sum(F * F, axis=1) - fn**2, 0.0))
        if np.all(fn >= f_min - _DIRECT_TOL) and np.all(ft <= mu * fn + _DIRECT_TOL):
            return Outcome("feasible", float(np.linalg.norm(fp)), fp.copy(), 0, "cvxpy:none", "direct")
        return Outcome("infeasible", float("nan"), None, 0, "cvxpy:none", "direct")

    normal_rows = np.zeros((m, 3 * m))
    tangent_proj = np.zeros((3 * m, 3 * m))
    for i in range(m):
        normal_rows[i, 3 * i : 3 * i + 3] = n[i]
        tangent_proj[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] = np.eye(3) - np.outer(n[i], n[i])
    y = cp.Variable(e)
    f = fp + Em @ y
    fn = normal_rows @ f
    ft = cp.reshape(tangent_proj @ f, (3, m), order="F")  # column i = tangential force of contact i
    cvx = cp.Problem(cp.Minimize(cp.norm(f, 2)), [fn >= f_min, cp.SOC(mu * fn, ft, axis=0)])
    try:
        cvx.solve(solver=solver)
    except cp.error.SolverError as exc:
        return Outcome("numerical_failure", float("nan"), None, 0, name, f"error: {exc}")
    status = cvx.status
    iterations = int(getattr(cvx.solver_stats, "num_iters", 0) or 0)
    if status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        forces = fp + Em @ y.value
        return Outcome(
            "feasible", float(np.linalg.norm(forces)), forces, iterations, name, status, problem.cone.violation(forces, n, f_min)
        )
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        return Outcome("infeasible", float("nan"), None, iterations, name, status)
    return Outcome("numerical_failure", float("nan"), None, iterations, name, status)
