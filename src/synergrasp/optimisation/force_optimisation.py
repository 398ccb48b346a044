"""Exact grasp-force optimisation (GFO) per problem, its cvxpy reference, and Bicchi's
strict internal-force test (method.md §4; docs/force_optimisation.md).

The problem, for the internal-force coordinates y (e_s,):

    minimise ||f_p + E y||_2
    subject to, at every contact i,  n_i.f_i >= f_min  and  ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i

Forces in N. Minimising ½||f||² has the same argmin, so the problem is passed to Clarabel as
a QP over second-order cones: P = E^T E (= I for an orthonormal E), q = E^T f_p.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import clarabel
import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from synergrasp.optimisation.mechanics import (
    BASIS_RTOL,
    GRASP_RANK_RTOL,
    Grasp,
    GraspMechanics,
    _unit_normals,
    friction_cone_rows,
    grasp_mechanics,
    internal_force_basis,
    object_wrench,
)

__all__ = [
    "GFOParams",
    "GFOResult",
    "STATUSES",
    "StrictResult",
    "constraint_violation",
    "mechanics_for",
    "optimise_grasp",
    "solve_gfo",
    "solve_gfo_cvxpy",
    "strict_internal_forces",
]

#: Verdicts of one GFO problem (the `status` column of gfo.parquet, minus `no_grasp`).
STATUSES: tuple[str, ...] = ("force_closure", "infeasible", "rank_deficient", "numerical_failure")

#: Clarabel's feasibility / gap tolerances used unless told otherwise (its own defaults).
DEFAULT_TOL = 1e-8
#: A reduced-accuracy ("AlmostSolved") point is accepted when its worst constraint
#: violation is below this, relative to max(1 N, ||f||).
ALMOST_SOLVED_TOL = 1e-6
#: Default relative shrink of mu in the strict internal-force test.
STRICT_SHRINK = 1e-5


@dataclass(frozen=True, kw_only=True)
class GFOParams:
    """Parameters of the grasp-force optimisation (method.md §4).

    gravity_direction: unit vector of gravity in the palm frame (required: the placement
        decides it, the configuration holds it)
    mu: Coulomb friction coefficient; f_min: least normal force, N
    k_stru: structural contact stiffness, N/mm; k_ss: joint stiffness, N·mm/rad
    mass_kg, g (m/s²): the object's weight
    basis_rtol: rank tolerance of E_s; grasp_rank_rtol: rank tolerance of G
    strict_shrink: relative shrink of mu in the strict internal-force test
    tol: Clarabel feasibility and gap tolerance; max_iter: interior-point iteration cap
    """

    gravity_direction: tuple[float, float, float]
    mu: float = 1.5
    f_min: float = 0.1
    k_stru: float = 1.0
    k_ss: float = 200.0
    mass_kg: float = 1.0
    g: float = 9.81
    basis_rtol: float = BASIS_RTOL
    grasp_rank_rtol: float = GRASP_RANK_RTOL
    strict_shrink: float = STRICT_SHRINK
    tol: float = DEFAULT_TOL
    max_iter: int = 200

    def __post_init__(self) -> None:
        d = np.asarray(self.gravity_direction, dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or abs(np.linalg.norm(d) - 1.0) > 1e-6:
            raise ValueError(f"gravity_direction must be a unit 3-vector, got {self.gravity_direction!r}")
        object.__setattr__(self, "gravity_direction", tuple(float(v) for v in d))
        _check_positive("mu", self.mu)
        _check_positive("k_stru", self.k_stru)
        _check_positive("k_ss", self.k_ss)
        for name in ("f_min", "mass_kg", "g"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value}")
        for name in ("basis_rtol", "grasp_rank_rtol", "strict_shrink", "tol"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0 < value < 1):
                raise ValueError(f"{name} must be in (0, 1), got {value}")
        if not (isinstance(self.max_iter, int) and self.max_iter > 0):
            raise ValueError(f"max_iter must be a positive int, got {self.max_iter!r}")

    def wrench(self) -> NDArray:
        """w_e (6,) the contacts must apply against the weight, N and N·mm."""
        return object_wrench(self.mass_kg, np.asarray(self.gravity_direction), self.g)


def _check_positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value}")


@dataclass(frozen=True)
class GFOResult:
    """Outcome of one grasp-force optimisation.

    status: 'force_closure' | 'infeasible' | 'rank_deficient' | 'numerical_failure'
    force_norm: optimal ||f||_2, N (NaN unless force closure)
    forces: (c,) optimal contact forces f_p + E y, N (None unless force closure)
    y: (e_s,) optimal internal-force coordinates (None unless force closure)
    e_s: number of internal-force directions; iterations: interior-point iterations
    solver: 'clarabel', 'cvxpy:<SOLVER>', 'direct' (e_s = 0) or 'none' (not solved)
    solver_status: the solver's own status string
    max_violation: worst constraint violation of `forces`, N (NaN when there are none)
    """

    status: str
    force_norm: float
    forces: NDArray | None
    y: NDArray | None
    e_s: int
    iterations: int
    solver: str
    solver_status: str = ""
    max_violation: float = float("nan")

    @property
    def force_closure(self) -> bool:
        return self.status == "force_closure"


@dataclass(frozen=True)
class StrictResult:
    """Bicchi's strict internal-force test: is some E y strictly inside every cone?

    strict: the verdict; status: the verdict of the underlying SOCP (see
    `strict_internal_forces`), or 'rank_deficient'; shrink: the relative shrink of mu used;
    result: that SOCP's GFOResult (None when not solved).
    """

    strict: bool
    status: str
    shrink: float
    result: GFOResult | None = field(default=None, repr=False)


def _check_problem(f_p: NDArray, E: NDArray, normals: NDArray, mu: float, f_min: float):
    n = _unit_normals(normals, None, "normals")
    m = n.shape[0]
    fp = np.asarray(f_p, dtype=float)
    if fp.shape != (3 * m,):
        raise ValueError(f"f_p must have shape (3m,) = ({3 * m},), got {fp.shape}")
    Em = np.asarray(E, dtype=float)
    if Em.ndim == 1:
        Em = Em[:, None]
    if Em.ndim != 2 or Em.shape[0] != 3 * m:
        raise ValueError(f"E must have shape (3m, e_s) = ({3 * m}, e_s), got {Em.shape}")
    if not (np.all(np.isfinite(fp)) and np.all(np.isfinite(Em))):
        raise ValueError("f_p and E must be finite")
    _check_positive("mu", mu)
    if not (math.isfinite(f_min) and f_min >= 0):
        raise ValueError(f"f_min must be a finite number >= 0 (N), got {f_min}")
    return fp, Em, n


def constraint_violation(forces: NDArray, normals: NDArray, mu: float, f_min: float) -> float:
    """Worst violation (N) of n.f >= f_min and ||f_t|| <= mu n.f over the contacts (<= 0 if feasible)."""
    n = np.asarray(normals, dtype=float)
    F = np.asarray(forces, dtype=float).reshape(-1, 3)
    if F.shape[0] == 0:
        return float("nan")
    fn = np.einsum("ij,ij->i", F, n)
    ft = np.linalg.norm(F - fn[:, None] * n, axis=1)
    return float(max(np.max(f_min - fn), np.max(ft - mu * fn)))


def _direct_result(fp: NDArray, n: NDArray, mu: float, f_min: float, tol: float) -> GFOResult:
    """e_s = 0: the only candidate is f = f_p; it is feasible within the solver tolerance."""
    viol = constraint_violation(fp, n, mu, f_min)
    norm = float(np.linalg.norm(fp))
    if viol <= tol * max(1.0, norm):
        return GFOResult("force_closure", norm, fp.copy(), np.zeros(0), 0, 0, "direct", "direct", viol)
    return GFOResult("infeasible", float("nan"), None, None, 0, 0, "direct", "direct", viol)


def solve_gfo(
    f_p: NDArray,
    E: NDArray,
    normals: NDArray,
    mu: float,
    f_min: float,
    *,
    tol: float = DEFAULT_TOL,
    max_iter: int = 200,
) -> GFOResult:
    """Solve one GFO problem exactly with Clarabel.

    f_p: (c,) particular forces, N; E: (c, e_s) internal-force basis (need not be
    orthonormal); normals: (m, 3) inward unit normals, c = 3m; mu: friction coefficient;
    f_min: least normal force, N; tol: Clarabel's feasibility, gap and infeasibility
    tolerances. Status mapping (docs/force_optimisation.md): Solved -> 'force_closure';
    AlmostSolved -> 'force_closure' if the point violates no constraint by more than
    1e-6·max(1 N, ||f||), else 'numerical_failure'; PrimalInfeasible and
    AlmostPrimalInfeasible -> 'infeasible'; anything else -> 'numerical_failure'.
    Bad input raises ValueError; a solver failure is a status, never an exception.
    """
    fp, Em, n = _check_problem(f_p, E, normals, mu, f_min)
    m, e = n.shape[0], Em.shape[1]
    if e == 0:
        return _direct_result(fp, n, mu, f_min, tol)

    # Constraints as A y + s = b, s in K (Clarabel's form), f = f_p + E y:
    #   n_i.f - f_min >= 0            -> rows -(N E), b = N f_p - f_min   (nonnegative cone, m)
    #   R_i f_i in SOC(3)              -> rows -(R E), b = R f_p           (m cones of size 3)
    E3 = Em.reshape(m, 3, e)
    R = friction_cone_rows(n, mu)
    NE = np.einsum("ij,ijk->ik", n, E3)
    RE = np.einsum("iab,ibk->iak", R, E3).reshape(3 * m, e)
    A = sp.csc_matrix(-np.vstack([NE, RE]))
    F3 = fp.reshape(m, 3)
    b = np.concatenate([np.einsum("ij,ij->i", n, F3) - f_min, np.einsum("iab,ib->ia", R, F3).ravel()])
    P = sp.csc_matrix(np.triu(Em.T @ Em))
    q = Em.T @ fp
    cones = [clarabel.NonnegativeConeT(m)] + [clarabel.SecondOrderConeT(3)] * m

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = int(max_iter)
    settings.tol_feas = settings.tol_gap_abs = settings.tol_gap_rel = float(tol)
    settings.tol_infeas_abs = settings.tol_infeas_rel = float(tol)
    try:
        sol = clarabel.DefaultSolver(P, q, A, b, cones, settings).solve()
    except Exception as exc:  # a solver crash on one problem is a verdict, not an abort
        return GFOResult("numerical_failure", float("nan"), None, None, e, 0, "clarabel", f"error: {exc}")
    return _verdict(sol.status, np.asarray(sol.x, dtype=float), int(sol.iterations), fp, Em, n, mu, f_min, "clarabel")


def _verdict(status, x, iterations, fp, Em, n, mu, f_min, solver) -> GFOResult:
    name = str(status)
    e = Em.shape[1]
    if name in ("Solved", "AlmostSolved"):
        forces = fp + Em @ x
        norm = float(np.linalg.norm(forces))
        viol = constraint_violation(forces, n, mu, f_min)
        if name == "Solved" or viol <= ALMOST_SOLVED_TOL * max(1.0, norm):
            return GFOResult("force_closure", norm, forces, x, e, iterations, solver, name, viol)
        return GFOResult("numerical_failure", float("nan"), None, None, e, iterations, solver, name, viol)
    if name in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
        return GFOResult("infeasible", float("nan"), None, None, e, iterations, solver, name)
    return GFOResult("numerical_failure", float("nan"), None, None, e, iterations, solver, name)


def solve_gfo_cvxpy(
    f_p: NDArray,
    E: NDArray,
    normals: NDArray,
    mu: float,
    f_min: float,
    *,
    solver: str = "CLARABEL",
) -> GFOResult:
    """Reference solution through cvxpy, written from the method text (tests only).

    The objective is the norm itself (cp.norm), the cones are cp.SOC on the tangential part
    f_i - (n_i.f_i) n_i (no tangent basis), and cvxpy's canonicalisation builds the conic
    problem, so this shares neither the formulation nor the matrix assembly of `solve_gfo`.
    The conic solver is cvxpy's CLARABEL unless told otherwise. Status mapping: optimal and
    optimal_inaccurate -> 'force_closure'; infeasible and infeasible_inaccurate ->
    'infeasible'; anything else -> 'numerical_failure'.
    """
    import cvxpy as cp

    fp, Em, n = _check_problem(f_p, E, normals, mu, f_min)
    m, e = n.shape[0], Em.shape[1]
    if e == 0:
        F = fp.reshape(m, 3)
        fn = np.sum(F * n, axis=1)
        ft = np.sqrt(np.maximum(np.sum(F * F, axis=1) - fn**2, 0.0))
        feasible = bool(np.all(fn >= f_min - 1e-8) and np.all(ft <= mu * fn + 1e-8))
        if feasible:
            return GFOResult("force_closure", float(np.linalg.norm(fp)), fp.copy(), np.zeros(0), 0, 0, "cvxpy:none", "direct")
        return GFOResult("infeasible", float("nan"), None, None, 0, 0, "cvxpy:none", "direct")

    normal_rows = np.zeros((m, 3 * m))
    tangent_proj = np.zeros((3 * m, 3 * m))
    for i in range(m):
        normal_rows[i, 3 * i:3 * i + 3] = n[i]
        tangent_proj[3 * i:3 * i + 3, 3 * i:3 * i + 3] = np.eye(3) - np.outer(n[i], n[i])
    y = cp.Variable(e)
    f = fp + Em @ y
    fn = normal_rows @ f
    ft = cp.reshape(tangent_proj @ f, (3, m), order="F")  # column i = tangential force of contact i
    problem = cp.Problem(cp.Minimize(cp.norm(f, 2)), [fn >= f_min, cp.SOC(mu * fn, ft, axis=0)])
    try:
        problem.solve(solver=solver)
    except cp.error.SolverError as exc:
        return GFOResult("numerical_failure", float("nan"), None, None, e, 0, f"cvxpy:{solver}", f"error: {exc}")
    status = problem.status
    iterations = int(getattr(problem.solver_stats, "num_iters", 0) or 0)
    if status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        forces = fp + Em @ y.value
        return GFOResult("force_closure", float(np.linalg.norm(forces)), forces, np.asarray(y.value), e,
                         iterations, f"cvxpy:{solver}", status, constraint_violation(forces, n, mu, f_min))
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        return GFOResult("infeasible", float("nan"), None, None, e, iterations, f"cvxpy:{solver}", status)
    return GFOResult("numerical_failure", float("nan"), None, None, e, iterations, f"cvxpy:{solver}", status)


def strict_internal_forces(
    E: NDArray,
    normals: NDArray,
    mu: float,
    shrink: float = STRICT_SHRINK,
    *,
    tol: float = DEFAULT_TOL,
    max_iter: int = 200,
) -> StrictResult:
    """Bicchi's strict test: is there y with E y strictly inside every friction cone?

    The set of such y is an open cone, so by homogeneity the test is equivalent to the
    feasibility of the GFO problem with f_p = 0, f_min = 1 N and mu (1 - shrink): a strictly
    interior direction can be scaled to n.f >= 1 and sits inside a slightly narrower cone.
    `shrink` (relative, > 0) separates strictly interior forces from forces on the cone
    boundary, far above the solver tolerance. Solved through `solve_gfo`, so every solver
    decides it with the same formulation.
    """
    if not (math.isfinite(shrink) and 0 < shrink < 1):
        raise ValueError(f"shrink must be in (0, 1), got {shrink}")
    Em = np.asarray(E, dtype=float)
    if Em.ndim == 1:
        Em = Em[:, None]
    res = solve_gfo(np.zeros(Em.shape[0]), Em, normals, mu * (1.0 - shrink), 1.0, tol=tol, max_iter=max_iter)
    return StrictResult(res.status == "force_closure", res.status, shrink, res)


def mechanics_for(grasp: Grasp, params: GFOParams) -> GraspMechanics:
    """`grasp_mechanics` with the weight, stiffnesses and rank tolerance of `params`."""
    return grasp_mechanics(grasp, params.wrench(), params.k_stru, params.k_ss, rank_rtol=params.grasp_rank_rtol)


def optimise_grasp(
    mechanics: GraspMechanics,
    synergy_subset: NDArray,
    params: GFOParams,
) -> tuple[GFOResult, StrictResult]:
    """GFO and strict test of one grasp for one synergy set.

    synergy_subset: (n, s) the enrolled synergy columns. rank(G) < 6 gives
    'rank_deficient' (e_s = 0, not solved, strict False). e_s = 0 gives f = f_p, judged
    directly.
    """
    if mechanics.rank_G < 6 or mechanics.projector is None or mechanics.f_p is None:
        res = GFOResult("rank_deficient", float("nan"), None, None, 0, 0, "none", "rank_deficient")
        return res, StrictResult(False, "rank_deficient", params.strict_shrink, None)
    E = internal_force_basis(mechanics.projector, synergy_subset, params.basis_rtol)
    res = solve_gfo(mechanics.f_p, E, mechanics.normals, params.mu, params.f_min, tol=params.tol, max_iter=params.max_iter)
    strict = strict_internal_forces(E, mechanics.normals, params.mu, params.strict_shrink, tol=params.tol,
                                    max_iter=params.max_iter)
    return res, strict
