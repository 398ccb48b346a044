"""The kernel's data layout: result codes, the settings, one problem and the work arrays.

A cone vector v has v[0] >= ||v[1:]||. Flat layout of a problem's cone vectors (length
N = L + 3q + e + 2): the nonnegative block of L linear slacks, then q Coulomb cones SOC(3)
[n.f, t1.f/mu, t2.f/mu] at L + 3i, then the objective cone (t, r0, y + a) at o = L + 3q.
x = (t, y) has length n = e + 1. Circular cone: q = m and L = m, the linear slack
n.f - f_min of contact i (slot i) sharing the rows of its Coulomb cone. Pyramid: q = 0 and
L = m (1 + sides), every friction constraint a linear row of its own (`Problem.DL`).
The cone functions address one cone as (array, offset k, dimension d), never as a slice.
Every array is allocated once per pose (`workspace`) and reused by every problem of the pose.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from synergrasp.optimisation.ipm.compiled import jit_alloc

__all__ = [
    "INFEASIBLE",
    "NOT_SOLVED",
    "OPTIMAL",
    "UNDECIDED",
    "Homogeneous",
    "Nesting",
    "PolishWork",
    "Problem",
    "Settings",
    "Work",
    "polish_workspace",
    "workspace",
]

#: Codes of the kernel's verdicts.
NOT_SOLVED, OPTIMAL, INFEASIBLE, UNDECIDED = 0, 1, 2, 3

#: The settings as the compiled code takes them: `IPMSettings`, the force-check tolerance and
#: whether only feasibility is asked (the strict test; a runtime value, not a literal passed
#: down the calls: numba would compile the iteration once for each literal).
Settings = namedtuple(
    "Settings", "tol reduced_tol max_iter step_fraction stall_step refine retry_refine polish_from violation_tol feasibility"
)

#: How the synergy sets of one grasp nest (`sets.solve_sets`): parent (n_sets,) int, the set
#: without the last column (-1: none); within (n_sets, n_sets) bool, set a a subset of set b;
#: order (n_sets,) int, the sets by size, stable (subsets before their supersets).
Nesting = namedtuple("Nesting", "parent within order")

#: One problem as the iteration sees it: contact rows D (m, 3, >= e) applied to E, hv (m, 3)
#: the rows applied to f_p (N), a = E^T f_p (N), r0 = ||f_p - E a|| (N), mu (1 for a pyramid,
#: whose D serves only ||f||), f_min (N), m contacts, e = e_s; q Coulomb cones (m or 0) and nl linear rows of their own, DL
#: (nl, >= e) applied to E and hl (nl,) N their constant terms (the slack is hl + DL y >= 0).
#: L = q + nl is the size of the nonnegative block.
Problem = namedtuple("Problem", "D hv a r0 mu f_min m e q nl L DL hl")

#: Work arrays for problems of m contacts, q SOCs, nl own linear rows and e_s <= e_max
#: (`workspace`), allocated once
#: and reused by every problem of a pose; a problem uses the leading N (cone layout) or
#: n (x layout) entries of each vector.
Work = namedtuple(
    "Work",
    [
        "D",
        "hv",
        "a",
        "DL",
        "hl",  # the problem's data (`Problem` refers to them)
        "h",
        "x",
        "s",
        "z",  # scaled h (cone layout); the iterate
        "w",
        "beta",
        "w_lin",
        "s_over_z",
        "lam",  # NT scaling: points w (cone layout), beta per SOC (objective last)
        "H3",
        "H_obj",
        "T",
        "M",
        "L",  # (W^T W)^-1 blocks (3m, 3), (e+2, e+2); normal matrix, its factor
        "r_x",
        "r_z",
        "x1",
        "z1",
        "x2",
        "z2",
        "bx",
        "q",
        "dsv",  # residuals and right-hand sides
        "dx",
        "dz",
        "ds",
        "dx_a",
        "dz_a",
        "ds_a",  # corrector and predictor directions
        "wn",
        "wn2",
        "ex",
        "wN",
        "wN2",
        "wN3",
        "ez",  # scratch of the linear solves
        "R_rows",  # Cholesky factor of A^T A, A the constraint rows
    ],
)

#: Work arrays of the active-set polish (`polish`), apart from `Work` (every array of a tuple
#: is an argument of each call that takes it): the active rows, the Jacobian J, H, its
#: factor, H^-1 J^T, J H^-1 J^T and its factor (e_max, e_max); u of one cone (3); vectors (e_max);
#: the last guess that failed (its size, then its rows; e_max + 1).
PolishWork = namedtuple("PolishWork", "act J H R Y S RS u c lam v w g Hg b last")

#: The homogenising pair (tau, kappa), the tau-row residual and c^T x1 + h^T z1 of the tau
#: column, shared by the predictor and the corrector of an iteration.
Homogeneous = namedtuple("Homogeneous", "tau kappa r_tau cx1_hz1")


@jit_alloc
def workspace(m, q, nl, e_max):
    L = q + nl
    N, n = L + 3 * q + e_max + 2, e_max + 1
    return Work(
        np.empty((m, 3, e_max)),
        np.empty((m, 3)),
        np.empty(e_max),
        np.empty((nl, e_max)),
        np.empty(nl),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(N),
        np.empty(N),
        np.empty(q + 1),
        np.empty(L),
        np.empty(L),
        np.empty(N),
        np.empty((3 * m, 3)),
        np.empty((e_max + 2, e_max + 2)),
        np.empty((m, 3, e_max)),
        np.empty((n, n)),
        np.empty((n, n)),
        np.empty(n),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(N),
        np.empty(n),
        np.empty(N),
        np.empty(N),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(N),
        np.empty(N),
        np.empty(N),
        np.empty(N),
        np.empty((n, n)),
    )


@jit_alloc
def polish_workspace(e_max):
    return PolishWork(
        np.empty(e_max, dtype=np.int64),
        np.empty((e_max, e_max)),
        np.empty((e_max, e_max)),
        np.empty((e_max, e_max)),
        np.empty((e_max, e_max)),
        np.empty((e_max, e_max)),
        np.empty((e_max, e_max)),
        np.empty(3),
        np.empty(e_max),
        np.empty(e_max),
        np.empty(e_max),
        np.empty(e_max),
        np.empty(e_max),
        np.empty(e_max),
        np.empty(e_max),
        np.full(e_max + 1, -1, dtype=np.int64),
    )
