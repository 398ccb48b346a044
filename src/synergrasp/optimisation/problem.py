"""The grasp-force optimisation (GFO) problem and its one result type.

Per problem, for the internal-force coordinates y (e_s,), forces in N:

    minimise ||f_p + E y||_2   subject to, at every contact i,
        n_i.f_i >= f_min   and   f_i in the problem's friction cone

A problem comes in one of two forms, both solved by `synergrasp.optimisation.gfo.solve_gfo`:
`GFOProblem` (one problem, its basis E given) and `GraspSets` (one grasp for several
synergy sets, E_s of each set derived by the rule of `mechanics.internal_force_basis`; the
study's unit of work). Every back end returns a `GFOSolution`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from synergrasp.optimisation.cones import FrictionCone
from synergrasp.optimisation.mechanics import BASIS_RTOL, _unit_normals, contact_frames, internal_force_basis

__all__ = [
    "ALMOST_SOLVED_TOL",
    "DEFAULT_TOL",
    "MAX_ITER",
    "GFOProblem",
    "GFOSolution",
    "GraspSets",
    "Outcome",
    "SOLVER_STATUSES",
    "STRICT_SHRINK",
    "SynergySets",
    "judge_direct",
    "linear_constraints",
]

#: Verdicts of one GFO problem (the `status` column of gfo.parquet, minus `rank_deficient`
#: and `no_grasp`, which the study gives before any solve).
SOLVER_STATUSES: tuple[str, ...] = ("feasible", "infeasible", "numerical_failure")
#: Feasibility / gap tolerance of the exact solvers unless told otherwise (Clarabel's default).
DEFAULT_TOL = 1e-8
#: Iteration limit of the exact solvers (Clarabel, PIQP) unless told otherwise.
MAX_ITER = 200
#: A reduced-accuracy optimum is accepted when its worst constraint violation is below
#: this, relative to max(1 N, ||f||) (every back end applies the same rule).
ALMOST_SOLVED_TOL = 1e-6
#: Default relative narrowing of the cone in the strict internal-force test.
STRICT_SHRINK = 1e-5


@dataclass(frozen=True)
class GFOProblem:
    """One GFO problem.

    f_p: (3m,) particular contact forces, N; E: (3m, e_s) internal-force basis (orthonormal
    for the interior-point back end; e_s may be 0); normals: (m, 3) inward unit normals;
    f_min: least normal force, N; cone: the friction-cone model (`cones`).
    """

    f_p: NDArray
    E: NDArray
    normals: NDArray
    f_min: float
    cone: FrictionCone

    def __post_init__(self) -> None:
        n = _unit_normals(self.normals, None, "normals")
        m = n.shape[0]
        fp = np.asarray(self.f_p, dtype=float)
        if fp.shape != (3 * m,):
            raise ValueError(f"f_p must have shape (3m,) = ({3 * m},), got {fp.shape}")
        E = np.asarray(self.E, dtype=float)
        if E.ndim == 1:
            E = E[:, None]
        if E.ndim != 2 or E.shape[0] != 3 * m:
            raise ValueError(f"E must have shape (3m, e_s) = ({3 * m}, e_s), got {E.shape}")
        if not (np.all(np.isfinite(fp)) and np.all(np.isfinite(E))):
            raise ValueError("f_p and E must be finite")
        _check_f_min(self.f_min)
        if not isinstance(self.cone, FrictionCone):
            raise ValueError(f"cone must be a friction-cone model of synergrasp.optimisation.cones, got {self.cone!r}")
        object.__setattr__(self, "f_p", fp)
        object.__setattr__(self, "E", E)
        object.__setattr__(self, "normals", n)
        object.__setattr__(self, "f_min", float(self.f_min))

    @property
    def n_contacts(self) -> int:
        return int(self.normals.shape[0])

    @property
    def e_s(self) -> int:
        return int(self.E.shape[1])

    def strict_test(self, shrink: float) -> GFOProblem:
        """Bicchi's strict internal-force test as a GFO problem: is some E y strictly inside
        every cone? The set of such y is an open cone, so by homogeneity the test is the
        feasibility of f_p = 0, f_min = 1 N in the cone narrowed by `shrink` (relative, far
        above the solver tolerance: forces on the cone boundary are not strict)."""
        return GFOProblem(np.zeros_like(self.f_p), self.E, self.normals, 1.0, self.cone.narrowed(shrink))


def _check_f_min(f_min: float) -> None:
    if not (isinstance(f_min, (int, float, np.floating)) and math.isfinite(f_min) and f_min >= 0):
        raise ValueError(f"f_min must be a finite number >= 0 (N), got {f_min!r}")


@dataclass(frozen=True)
class SynergySets:
    """Synergy sets enrolled in the optimisation: the synergy matrix and each set's columns.

    matrix: (n, k) synergies, rad per unit activation; sets: 1-based synergy indices per set.
    Derived once: `columns` (0-based, sorted, per set), `sizes` (synergies per set), `norms`
    (||S_set||_2 per set), `table` (n_sets, largest set) of the columns, padded with 0
    after each set's size, `within` (n_sets, n_sets) bool: within[a, b] if set a is a
    subset of set b (a != b), the nesting whose implied verdicts the kernel takes, and
    `parent` (n_sets,) the index of the set without its last column (-1: none), whose basis
    the kernel's starts from, and `order` (n_sets,) the sets by size, stable (subsets before
    their supersets: the kernel's order).
    """

    matrix: NDArray
    sets: tuple[tuple[int, ...], ...]
    columns: tuple[NDArray, ...] = field(init=False, repr=False)
    sizes: NDArray = field(init=False, repr=False)
    norms: NDArray = field(init=False, repr=False)
    table: NDArray = field(init=False, repr=False)
    within: NDArray = field(init=False, repr=False)
    parent: NDArray = field(init=False, repr=False)
    order: NDArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        S = np.asarray(self.matrix, dtype=float)
        if S.ndim != 2:
            raise ValueError(f"synergies must be an (n, k) matrix, got shape {S.shape}")
        k = S.shape[1]
        columns = []
        for s in self.sets:
            idx = np.asarray(sorted(int(v) for v in s), dtype=int)
            if idx.size == 0 or idx[0] < 1 or idx[-1] > k or np.unique(idx).size != idx.size:
                raise ValueError(f"sets: each set must hold distinct 1-based synergy indices in 1..{k}, got {tuple(s)!r}")
            columns.append(idx - 1)
        object.__setattr__(self, "matrix", S)
        object.__setattr__(self, "sets", tuple(tuple(int(v) for v in s) for s in self.sets))
        object.__setattr__(self, "columns", tuple(columns))
        object.__setattr__(self, "norms", np.array([np.linalg.norm(S[:, c], 2) for c in columns]))
        table = np.zeros((len(columns), max((c.size for c in columns), default=1)), dtype=np.int64)
        for j, c in enumerate(columns):
            table[j, : c.size] = c
        object.__setattr__(self, "table", table)
        object.__setattr__(self, "sizes", np.array([c.size for c in columns], dtype=np.int64))
        members = [set(c.tolist()) for c in columns]
        object.__setattr__(
            self,
            "within",
            np.array([[a is not b and a <= b for b in members] for a in members], dtype=bool).reshape(len(members), len(members)),
        )
        index = {tuple(c.tolist()): j for j, c in reversed(list(enumerate(columns)))}
        object.__setattr__(self, "parent", np.array([index.get(tuple(c[:-1].tolist()), -1) for c in columns], dtype=np.int64))
        object.__setattr__(self, "order", np.argsort(self.sizes, kind="stable").astype(np.int64))

    def __len__(self) -> int:
        return len(self.columns)


@dataclass(frozen=True)
class GraspSets:
    """The GFO problems of one grasp, one per synergy set.

    f_p: (c,) particular forces, N; normals: (m, 3); projector: (c, n) internal-force
    projector (I - G_K^R G) K J, N/rad; response_norm: ||K J||_2, N/rad; synergies: the
    sets; f_min: N; cone: friction model; basis_rtol: rank rule of E_s (singular values of
    projector S_set above basis_rtol ||K J||_2 ||S_set||_2, as `mechanics.internal_force_basis`);
    frames: the contact frames of the normals (`mechanics.contact_frames`) when the caller
    has them (`GraspMechanics.frames`), None: computed by the solver.
    """

    f_p: NDArray
    normals: NDArray
    projector: NDArray
    response_norm: float
    synergies: SynergySets
    f_min: float
    cone: FrictionCone
    basis_rtol: float = BASIS_RTOL
    frames: NDArray | None = None

    def __len__(self) -> int:
        return len(self.synergies)

    def problem(self, j: int) -> GFOProblem:
        """The problem of set j, with E_s from `internal_force_basis`."""
        E = internal_force_basis(
            self.projector, self.synergies.matrix[:, self.synergies.columns[j]], self.response_norm, self.basis_rtol
        )
        return GFOProblem(self.f_p, E, self.normals, self.f_min, self.cone)


class Outcome(NamedTuple):
    """What a per-problem back end returns for one problem (a row of `GFOSolution`).

    status: one of SOLVER_STATUSES; force_norm: N (NaN unless feasible); forces: (3m,) N or
    None; iterations; solver: back-end name; solver_status: the solver's own status;
    max_violation: worst constraint violation of `forces`, N (NaN when there are none).
    """

    status: str
    force_norm: float
    forces: NDArray | None
    iterations: int
    solver: str
    solver_status: str = ""
    max_violation: float = float("nan")


@dataclass(frozen=True)
class GFOSolution:
    """Outcome of `solve_gfo`, one entry per problem, in the caller's order.

    status: 'feasible' | 'infeasible' | 'numerical_failure' (the problem under its load: for
        a grasp, load feasibility, not force closure)
    force_norm: optimal ||f||_2, N (NaN unless feasible)
    forces: each problem's optimal contact forces f_p + E y, (3m,) N (None unless feasible)
    e_s: rank of each problem's internal-force basis
    iterations: interior-point iterations (those of the solver that decided it; 0 if none ran)
    strict_internal: Bicchi's strict internal-force verdict (None when not asked for)
    solver: back end that decided the problem: 'ipm', 'clarabel', 'cvxpy:<SOLVER>',
        'clarabel_fallback' (the interior-point kernel left it undecided), 'direct' (e_s = 0:
        f = f_p judged without a solver)
    max_violation: worst constraint violation of `forces`, N (NaN unless feasible)
    """

    status: NDArray
    force_norm: NDArray
    forces: NDArray
    e_s: NDArray
    iterations: NDArray
    strict_internal: NDArray | None
    solver: NDArray
    max_violation: NDArray

    @classmethod
    def empty(cls, size: int, strict: bool) -> GFOSolution:
        """`size` problems, none decided yet (status 'numerical_failure')."""
        return cls(
            status=np.full(size, "numerical_failure", dtype=object),
            force_norm=np.full(size, np.nan),
            forces=np.full(size, None, dtype=object),
            e_s=np.zeros(size, dtype=np.int32),
            iterations=np.zeros(size, dtype=np.int32),
            strict_internal=np.zeros(size, dtype=bool) if strict else None,
            solver=np.full(size, "", dtype=object),
            max_violation=np.full(size, np.nan),
        )

    def __len__(self) -> int:
        return int(self.status.size)

    def record(self, k: int, outcome: Outcome, *, solver: str | None = None) -> None:
        """Store a per-problem outcome in row k (its solver name, or `solver` if given)."""
        self.status[k], self.force_norm[k], self.forces[k] = outcome.status, outcome.force_norm, outcome.forces
        self.iterations[k] = outcome.iterations
        self.max_violation[k] = outcome.max_violation if outcome.status == "feasible" else np.nan
        self.solver[k] = outcome.solver if solver is None else solver

    @property
    def feasible(self) -> NDArray:
        return self.status == "feasible"


def judge_direct(problem: GFOProblem, tol: float = DEFAULT_TOL) -> Outcome:
    """e_s = 0: the only candidate is f = f_p; admissible when its worst violation is at
    most tol max(1 N, ||f_p||) (solver 'direct')."""
    fp = problem.f_p
    viol = problem.cone.violation(fp, problem.normals, problem.f_min)
    norm = float(np.linalg.norm(fp))
    if viol <= tol * max(1.0, norm):
        return Outcome("feasible", norm, fp.copy(), 0, "direct", "direct", viol)
    return Outcome("infeasible", float("nan"), None, 0, "direct", "direct", viol)


def linear_constraints(problem: GFOProblem) -> tuple[NDArray, NDArray]:
    """(G, h) with the constraints of a problem with a pyramid cone as G y <= h: per contact
    the normal bound -(n.E) y <= n.f_p - f_min, then per face (a_k.E) y <= -a_k.f_p."""
    m, e = problem.n_contacts, problem.e_s
    frames = contact_frames(problem.normals)
    E3 = problem.E.reshape(m, 3, e)
    F3 = problem.f_p.reshape(m, 3)
    faces = problem.cone.face_rows(frames)  # (m, sides, 3)
    G = np.vstack([-np.einsum("ij,ijk->ik", frames[:, 0], E3), np.einsum("isj,ijk->isk", faces, E3).reshape(-1, e)])
    h = np.concatenate([np.einsum("ij,ij->i", frames[:, 0], F3) - problem.f_min, -np.einsum("isj,ij->is", faces, F3).ravel()])
    return G, h


def as_problems(problems: Sequence[GFOProblem] | GraspSets) -> Sequence[GFOProblem]:
    """The problems one by one (a `GraspSets` expanded with `GraspSets.problem`)."""
    if isinstance(problems, GraspSets):
        return [problems.problem(j) for j in range(len(problems))]
    return problems
