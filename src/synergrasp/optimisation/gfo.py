"""The one front door of the grasp-force optimisation: `solve_gfo(problems, method=...)`.

In the style of `scipy.optimize.linprog`: the problems (`problem.GFOProblem` or, for one
grasp and many synergy sets, `problem.GraspSets`) carry their friction-cone model; the
method picks the back end; every back end returns one `problem.GFOSolution`.

- "ipm": the compiled interior-point kernel (`ipm.solver`), circular and pyramid cones; the
  problems it leaves undecided are solved again by Clarabel and marked 'clarabel_fallback'
  (nothing is dropped).
- "clarabel": Clarabel per problem (`clarabel_solver`), the exact reference of the study.
- "cvxpy": the cvxpy reference (`cvxpy_reference`), for tests and benchmarks.
- "piqp": PIQP per problem (`piqp_solver`), for pyramid cones (a QP); a check of "ipm".
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synergrasp.optimisation import clarabel_solver, cvxpy_reference, piqp_solver
from synergrasp.optimisation.ipm import solver as ipm_solver
from synergrasp.optimisation.cones import CircularCone
from synergrasp.optimisation.ipm.solver import IPMSettings
from synergrasp.optimisation.mechanics import contact_frames
from synergrasp.optimisation.problem import (
    ALMOST_SOLVED_TOL,
    DEFAULT_TOL,
    MAX_ITER,
    GFOProblem,
    GFOSolution,
    GraspSets,
    Outcome,
    SynergySets,
    as_problems,
)

__all__ = ["FASTEST_METHOD", "METHODS", "solve_gfo", "warm_up"]

#: Methods of `solve_gfo` and the friction-cone kinds each accepts.
METHODS: dict[str, tuple[str, ...]] = {
    "ipm": ("circular", "pyramid"),
    "clarabel": ("circular", "pyramid"),
    "cvxpy": ("circular",),
    "piqp": ("pyramid",),
}

#: The fastest method for each cone kind (the study's choice).
FASTEST_METHOD: dict[str, str] = {"circular": "ipm", "pyramid": "ipm"}

#: Verdict of each kernel code; '' marks the problems that go to the Clarabel fallback.
_STATUS_OF_CODE = np.array(["", "feasible", "infeasible", ""], dtype=object)


def solve_gfo(
    problems: Sequence[GFOProblem] | GraspSets,
    method: str = "ipm",
    *,
    strict_shrink: float | None = None,
    tol: float = DEFAULT_TOL,
    max_iter: int = MAX_ITER,
    ipm: IPMSettings = IPMSettings(),
) -> GFOSolution:
    """Solve GFO problems; one row of the result per problem, in order.

    strict_shrink: if given, also Bicchi's strict internal-force test of every problem
        (`GFOProblem.strict_test`, the cone narrowed by this relative amount), else
        `strict_internal` is None.
    tol, max_iter: tolerance and iteration cap of Clarabel and PIQP (methods "clarabel",
        "piqp" and the fallback of "ipm"); ipm: settings of the interior-point kernel.
    Bad input (unknown method, a cone the method does not accept) raises ValueError before
    any solve; a failure on one problem is its status.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)}, got {method!r}")
    cones = {problems.cone.kind} if isinstance(problems, GraspSets) else {p.cone.kind for p in problems}
    if not cones <= set(METHODS[method]):
        raise ValueError(
            f"method {method!r} accepts the friction cones {list(METHODS[method])}, got {sorted(cones - set(METHODS[method]))}"
        )
    if strict_shrink is not None and not (0 < strict_shrink < 1):
        raise ValueError(f"strict_shrink must be in (0, 1), got {strict_shrink}")
    if method == "ipm" and isinstance(problems, GraspSets):
        return _ipm_sets(problems, strict_shrink, tol, max_iter, ipm)
    items = as_problems(problems)
    sol = GFOSolution.empty(len(items), strict_shrink is not None)
    solve = None if method == "ipm" else _per_problem(method, tol, max_iter)
    for k, problem in enumerate(items):
        sol.e_s[k] = problem.e_s
        if method == "ipm":
            _ipm_one(sol, k, problem, strict_shrink, tol, max_iter, ipm)
            continue
        sol.record(k, solve(problem))
        if strict_shrink is not None:
            sol.strict_internal[k] = solve(problem.strict_test(strict_shrink)).status == "feasible"
    return sol


def _per_problem(method: str, tol: float, max_iter: int):
    """The one-problem solver of a back end solved problem by problem (every method but the
    kernel's); a method in METHODS without one here is an error, never a silent cvxpy."""
    solvers = {
        "clarabel": lambda p: clarabel_solver.solve(p, tol=tol, max_iter=max_iter),
        "piqp": lambda p: piqp_solver.solve(p, tol=tol, max_iter=max_iter),
        "cvxpy": cvxpy_reference.solve,
    }
    if method not in solvers:
        raise ValueError(f"method {method!r} has no one-problem solver (gfo._per_problem)")
    return solvers[method]


def _fallback(sol: GFOSolution, k: int, problem: GFOProblem, tol: float, max_iter: int) -> None:
    """Row k, left undecided by the kernel (or with e_s = 0, where f = f_p is judged
    directly): Clarabel's verdict, marked 'clarabel_fallback' when it solved something."""
    out = clarabel_solver.solve(problem, tol=tol, max_iter=max_iter)
    sol.record(k, out, solver="clarabel_fallback" if problem.e_s > 0 else "direct")


def _strict_fallback(problem: GFOProblem, shrink: float, tol: float, max_iter: int) -> bool:
    return clarabel_solver.solve(problem.strict_test(shrink), tol=tol, max_iter=max_iter).status == "feasible"


def _ipm_one(
    sol: GFOSolution, k: int, problem: GFOProblem, shrink: float | None, tol: float, max_iter: int, ipm: IPMSettings
) -> None:
    """Row k of a sequence of problems by the kernel, undecided ones by the fallback."""
    if problem.e_s == 0:
        _fallback(sol, k, problem, tol, max_iter)
        if shrink is not None:
            sol.strict_internal[k] = _strict_fallback(problem, shrink, tol, max_iter)
        return
    res = ipm_solver.solve_problem(
        contact_frames(problem.normals),
        problem.E,
        problem.f_p,
        problem.cone,
        problem.cone.narrowed(shrink) if shrink is not None else None,
        problem.f_min,
        ipm,
        ALMOST_SOLVED_TOL,
    )
    status, iters = _STATUS_OF_CODE[res.code[0]], int(res.iterations[0])
    if status == "feasible":
        forces = res.forces[0]
        sol.record(
            k,
            Outcome(
                status,
                float(res.force_norm[0]),
                forces,
                iters,
                "ipm",
                "",
                problem.cone.violation(forces, problem.normals, problem.f_min),
            ),
        )
    elif status == "infeasible":
        sol.record(k, Outcome(status, float("nan"), None, iters, "ipm"))
    else:
        _fallback(sol, k, problem, tol, max_iter)
    if shrink is not None:
        code = res.strict_code[0]
        sol.strict_internal[k] = (
            code == ipm_solver.OPTIMAL
            if code in (ipm_solver.OPTIMAL, ipm_solver.INFEASIBLE)
            else _strict_fallback(problem, shrink, tol, max_iter)
        )


def _ipm_sets(g: GraspSets, shrink: float | None, tol: float, max_iter: int, ipm: IPMSettings) -> GFOSolution:
    """All sets of one grasp in one compiled call (bases, rows, both SOCPs, forces), then the
    fallback for the undecided ones."""
    P, S = g.projector, g.synergies
    thresholds = g.basis_rtol * g.response_norm * S.norms
    strict = shrink is not None
    frames = contact_frames(g.normals) if g.frames is None else g.frames
    res = ipm_solver.solve_sets(
        P @ S.matrix,
        g.f_p,
        frames,
        S.table,
        S.sizes,
        thresholds,
        ipm_solver.Nesting(S.parent, S.within, S.order),
        g.cone,
        g.cone.narrowed(shrink) if strict else None,
        g.f_min,
        ipm,
        ALMOST_SOLVED_TOL,
    )
    n = len(g)
    status = _STATUS_OF_CODE[res.code]
    optimal = res.code == ipm_solver.OPTIMAL
    forces = np.full(n, None, dtype=object)
    for j in np.flatnonzero(optimal).tolist():
        forces[j] = res.forces[j]
    sol = GFOSolution(
        status=status,
        force_norm=np.where(optimal, res.force_norm, np.nan),
        forces=forces,
        e_s=res.e_s.astype(np.int32),
        iterations=res.iterations,
        strict_internal=res.strict_code == ipm_solver.OPTIMAL if strict else None,
        solver=np.where(res.implied, "implied", "ipm").astype(object),
        max_violation=np.where(optimal, res.max_violation, np.nan),
    )
    for j in np.flatnonzero((res.code == ipm_solver.UNDECIDED) | (res.code == ipm_solver.NOT_SOLVED)):  # status ''
        _fallback(sol, j, g.problem(j), tol, max_iter)
    if strict:
        undecided = (res.strict_code != ipm_solver.OPTIMAL) & (res.strict_code != ipm_solver.INFEASIBLE) & (res.e_s > 0)
        for j in np.flatnonzero(undecided):
            sol.strict_internal[j] = _strict_fallback(g.problem(j), shrink, tol, max_iter)
    return sol


def warm_up() -> None:
    """Compile the interior-point kernel's machine code, or load it from its cache
    (`ipm.compiled.cache_dir()`: per user, named by the hash of the kernel's sources, so any
    checkout of the same kernel loads it). Called once after installation (Makefile) so that
    no workflow job pays the compilation (docs/measurements) and parallel jobs do not compile
    side by side. Both entry points (`ipm_solver.solve_problem`, `ipm_solver.solve_sets`)
    are one compiled function; one pose with the strict test compiles all of it.
    """
    normals = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    squeeze = np.array([[1.0], [0.0], [0.0], [-1.0], [0.0], [0.0]]) / np.sqrt(2.0)
    sets = SynergySets(np.eye(1), ((1,),))
    solve_gfo(GraspSets(np.zeros(6), normals, squeeze, 1.0, sets, 0.5, CircularCone(1.0), basis_rtol=1e-9), strict_shrink=1e-5)
