"""Back end: the compiled interior-point kernel (numba) for GFO problems with circular or
pyramid friction cones (docs/ipm_solver.md); its compiled parts, by concern, are the
package `synergrasp.optimisation.ipm`.

Per problem, forces in N: minimise ||f_p + E y||_2 subject to, per contact i,
n_i.f_i >= f_min and ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i (circular cone) or the pyramid's
face rows a_k.f_i <= 0 (`cones.PyramidCone.face_rows`). With E orthonormal,
||f_p + E y||^2 = ||f_p - E a||^2 + ||y + a||^2 (a = E^T f_p), so the kernel minimises t
subject to (t, y + a) in a second-order cone: a linear-objective SOCP in x = (t, y), solved
through the homogeneous self-dual embedding (infeasibility ends in a certificate, not a
time-out) with Nesterov-Todd scaling and Mehrotra's predictor-corrector. Each problem is
solved on its own from its own sizes, so its numbers do not depend on what else is solved.

Results are codes (`OPTIMAL`, `INFEASIBLE`, `UNDECIDED`, `NOT_SOLVED` for e_s = 0); the
front door `synergrasp.optimisation.gfo.solve_gfo` turns them into verdicts and sends the
undecided problems to Clarabel.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from synergrasp.optimisation.cones import FrictionCone
from synergrasp.optimisation.ipm import sets
from synergrasp.optimisation.ipm.layout import INFEASIBLE, NOT_SOLVED, OPTIMAL, UNDECIDED, Nesting, Settings

__all__ = [
    "INFEASIBLE",
    "IPMSettings",
    "NOT_SOLVED",
    "Nesting",
    "OPTIMAL",
    "SetsResult",
    "UNDECIDED",
    "solve_problem",
    "solve_sets",
]


@dataclass(frozen=True, kw_only=True)
class IPMSettings:
    """Tolerances of the compiled interior-point method.

    tol: relative primal/dual residual and duality-gap tolerance of an optimal point, and the
        residual tolerance of an infeasibility certificate (dimensionless; the data are
        scaled so that max(||f_p||, f_min) = 1)
    reduced_tol: the same tests, applied when the iteration stalls (step below
        `stall_step`) or reaches `max_iter`; failing them the problem is 'not decided'
    max_iter: iteration cap; a problem not decided by then goes to the Clarabel fallback
    step_fraction: fraction of the step to the cone boundary taken each iteration
    stall_step: a step below this ends the iteration (judged with `reduced_tol`)
    refine: iterative-refinement steps on the full KKT system per linear solve (0: none)
    retry_refine: refinement steps of a second attempt on a problem the first attempt leaves
        undecided (no second attempt unless it exceeds `refine`); problems still undecided
        fall back to the per-problem exact solver
    polish_from: the active-set polish (`ipm.polish`) is tried at every iterate whose residuals
        and relative gap are below this, and where the iteration stalls or ends; 0: only
        there; negative: never. A polished point is accepted only if it passes the optimality
        test at `tol`
    nested: the sets of one grasp (`solve_sets`) take the verdicts their nesting implies
        instead of solving them (`ipm.sets.solve_sets`: a subset of an infeasible set is
        infeasible, a superset of a strictly feasible one strictly feasible, a subset of
        equal rank the same problem, an infeasible set not strictly feasible) and start the
        basis of a set from its parent's (`ipm.sets.set_bases`); False solves every set from
        scratch, to compare the solver with itself
    """

    tol: float = 1e-8
    reduced_tol: float = 1e-6
    max_iter: int = 50
    step_fraction: float = 0.99
    stall_step: float = 1e-3
    refine: int = 0
    retry_refine: int = 1
    polish_from: float = 1e-2
    nested: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tol) and 0 < self.tol < 1):
            raise ValueError(f"tol must be in (0, 1), got {self.tol}")
        if not (isinstance(self.max_iter, int) and self.max_iter > 0):
            raise ValueError(f"max_iter must be a positive int, got {self.max_iter!r}")
        if not (0 < self.step_fraction < 1):
            raise ValueError(f"step_fraction must be in (0, 1), got {self.step_fraction}")
        if not math.isfinite(self.polish_from):
            raise ValueError(f"polish_from must be a finite number, got {self.polish_from}")
        for name in ("refine", "retry_refine"):
            value = getattr(self, name)
            if not (isinstance(value, int) and 0 <= value <= 10):
                raise ValueError(f"{name} must be an int in 0..10, got {value!r}")


def _kernel_settings(settings: IPMSettings, violation_tol: float, feasibility: bool = False) -> Settings:
    return Settings(
        float(settings.tol),
        float(settings.reduced_tol),
        int(settings.max_iter),
        float(settings.step_fraction),
        float(settings.stall_step),
        int(settings.refine),
        int(settings.retry_refine),
        float(settings.polish_from),
        float(violation_tol),
        bool(feasibility),
    )


#: A friction cone as the compiled code takes it: mu dividing the tangent rows of the contact
#: frames (1 for a pyramid, whose D rows serve only ||f||) and the linear rows lin (m, p, 3)
#: per contact, p = 0 for the circular cone (see `ipm.sets.build`).
ConeData = namedtuple("ConeData", "mu lin")


def cone_data(cone: FrictionCone, frames: NDArray) -> ConeData:
    """The kernel's form of a cone model on the contact frames (m, 3, 3): the circular cone's
    mu; a pyramid's rows n (the normal bound) and -a_k (`PyramidCone.face_rows`, a_k.f <= 0)."""
    if cone.kind == "circular":
        return ConeData(float(cone.mu), np.empty((frames.shape[0], 0, 3)))
    lin = np.concatenate([frames[:, None, 0], -cone.face_rows(frames)], axis=1)
    return ConeData(1.0, np.ascontiguousarray(lin))


class SetsResult(NamedTuple):
    """Kernel output for the sets of one grasp (arrays over the sets): code, ||f|| N,
    worst constraint violation N, iterations, e_s, strict_code (INFEASIBLE where not
    tested), forces (n_sets, 3m) N (rows of OPTIMAL sets only), implied (the GFO's verdict
    INFEASIBLE implied by an infeasible superset, not solved; 0 iterations)."""

    code: NDArray
    force_norm: NDArray
    max_violation: NDArray
    iterations: NDArray
    e_s: NDArray
    strict_code: NDArray
    forces: NDArray
    implied: NDArray


def solve_problem(
    frames: NDArray,
    E: NDArray,
    f_p: NDArray,
    cone: FrictionCone,
    strict_cone: FrictionCone | None,
    f_min: float,
    settings: IPMSettings,
    violation_tol: float,
) -> SetsResult:
    """One problem: frames (m, 3, 3) from `mechanics.contact_frames`, E (3m, e) orthonormal
    with e >= 1, f_p (3m,) N, the friction-cone model, that of the strict internal-force test
    (None for no strict test), f_min N. An optimal point whose forces violate a constraint by
    more than violation_tol max(1 N, ||f||) is UNDECIDED. The same compiled call as
    `solve_sets`, with E as the one set's basis; returns its one-row `SetsResult`."""
    e = E.shape[1]
    alone = Nesting(np.full(1, -1), np.zeros((1, 1), dtype=bool), np.zeros(1, dtype=np.int64))  # one set
    return _solve(
        np.ascontiguousarray(E, dtype=float),
        f_p,
        frames,
        np.arange(e)[None, :],
        np.array([e]),
        np.zeros(1),
        True,
        alone,
        cone,
        strict_cone,
        f_min,
        settings,
        violation_tol,
    )


def solve_sets(
    F_all: NDArray,
    f_p: NDArray,
    frames: NDArray,
    columns: NDArray,
    n_columns: NDArray,
    thresholds: NDArray,
    nesting: Nesting,
    cone: FrictionCone,
    strict_cone: FrictionCone | None,
    f_min: float,
    settings: IPMSettings,
    violation_tol: float,
) -> SetsResult:
    """Every set of one grasp in one compiled call. F_all: (3m, k) projector @ S, N per
    unit activation; columns: (n_sets, max size) 0-based columns of F_all per set (the first
    n_columns[j] of row j); thresholds: (n_sets,) rank thresholds of the singular values;
    nesting: the sets' parents, subsets and order (`SynergySets.parent`, `.within`, `.order`;
    ignored unless `settings.nested`: every set solved, its basis from scratch);
    cone: the friction-cone model; strict_cone: that of the strict internal-force test (the
    cone narrowed), None for no strict test."""
    if not settings.nested:
        nesting = Nesting(np.full_like(nesting.parent, -1), np.zeros_like(nesting.within), nesting.order)
    return _solve(
        np.ascontiguousarray(F_all),
        f_p,
        frames,
        columns,
        n_columns,
        thresholds,
        False,
        nesting,
        cone,
        strict_cone,
        f_min,
        settings,
        violation_tol,
    )


def _solve(
    F_all: NDArray,
    f_p: NDArray,
    frames: NDArray,
    columns: NDArray,
    n_columns: NDArray,
    thresholds: NDArray,
    given: bool,
    nesting: Nesting,
    cone: FrictionCone,
    strict_cone: FrictionCone | None,
    f_min: float,
    settings: IPMSettings,
    violation_tol: float,
) -> SetsResult:
    n_sets = columns.shape[0]
    out = SetsResult(
        code=np.zeros(n_sets, dtype=np.int8),
        force_norm=np.full(n_sets, np.nan),
        max_violation=np.full(n_sets, np.nan),
        iterations=np.zeros(n_sets, dtype=np.int32),
        e_s=np.zeros(n_sets, dtype=np.int64),
        strict_code=np.full(n_sets, INFEASIBLE, dtype=np.int8),
        forces=np.full((n_sets, f_p.size), np.nan),
        implied=np.zeros(n_sets, dtype=bool),
    )
    data = cone_data(cone, frames)
    sets.solve_sets(
        F_all,
        np.ascontiguousarray(f_p, dtype=float),
        frames,
        columns,
        n_columns,
        thresholds,
        given,
        nesting,
        data,
        data if strict_cone is None else cone_data(strict_cone, frames),
        float(f_min),
        strict_cone is not None,
        _kernel_settings(settings, violation_tol),
        _kernel_settings(settings, violation_tol, feasibility=True),
        out,
    )
    return out
