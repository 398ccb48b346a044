"""Back end: the compiled interior-point kernel (numba) for GFO problems with circular or
pyramid friction cones (docs/batched_solver.md).

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

import numba
import numpy as np
from numpy.typing import NDArray

from synergrasp.optimisation.cones import FrictionCone

__all__ = ["INFEASIBLE", "IPMSettings", "NOT_SOLVED", "OPTIMAL", "SetsResult", "UNDECIDED", "solve_problem", "solve_sets"]

#: Codes of the kernel's verdicts.
NOT_SOLVED, OPTIMAL, INFEASIBLE, UNDECIDED = 0, 1, 2, 3


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
    """

    tol: float = 1e-8
    reduced_tol: float = 1e-6
    max_iter: int = 50
    step_fraction: float = 0.99
    stall_step: float = 1e-3
    refine: int = 0
    retry_refine: int = 1

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tol) and 0 < self.tol < 1):
            raise ValueError(f"tol must be in (0, 1), got {self.tol}")
        if not (isinstance(self.max_iter, int) and self.max_iter > 0):
            raise ValueError(f"max_iter must be a positive int, got {self.max_iter!r}")
        if not (0 < self.step_fraction < 1):
            raise ValueError(f"step_fraction must be in (0, 1), got {self.step_fraction}")
        for name in ("refine", "retry_refine"):
            value = getattr(self, name)
            if not (isinstance(value, int) and 0 <= value <= 10):
                raise ValueError(f"{name} must be an int in 0..10, got {value!r}")


# --------------------------------------------------------------------------- data layout
# Compiled with numba: one problem at a time, so a problem's numbers never depend on the
# batch it arrives in, and the ~10 iterations of a tiny problem cost microseconds instead of
# the hundreds of numpy calls a vectorised iteration needs. A cone vector v has v[0] >= ||v[1:]||.
# Flat layout of a problem's cone vectors (length N = L + 3q + e + 2): the nonnegative block
# of L linear slacks, then q Coulomb cones SOC(3) [n.f, t1.f/mu, t2.f/mu] at L + 3i, then
# the objective cone (t, r0, y + a) at o = L + 3q. x = (t, y) has length n = e + 1.
# Circular cone: q = m and L = m, the linear slack n.f - f_min of contact i (slot i) sharing
# the rows of its Coulomb cone. Pyramid: q = 0 and L = m (1 + sides), every friction
# constraint a linear row of its own (`_Problem.DL`).
# The cone functions address one cone as (array, offset k, dimension d), never as a slice.
# Every array is allocated once per pose (`_workspace`); the functions that allocate or
# return arrays are compiled with numba's reference counting (`_jit_alloc`), the iteration
# without it (`_jit`, `_jit_small`: `_nrt=False`). With it, every slice, argument and tuple
# field taken in a loop cost an atomic increment and decrement, about half of the iteration's
# time; without it the arithmetic is the same, in the same order.

_jit_alloc = numba.njit(cache=True, nogil=True, error_model="numpy")
_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_jit_small = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")

#: The settings as the compiled code takes them: `IPMSettings` and the force-check tolerance.
_Settings = namedtuple("_Settings", "tol reduced_tol max_iter step_fraction stall_step refine retry_refine violation_tol")

#: One problem as the iteration sees it: contact rows D (m, 3, >= e) applied to E, hv (m, 3)
#: the rows applied to f_p (N), a = E^T f_p (N), r0 = ||f_p - E a|| (N), mu (1 for a pyramid,
#: whose D serves only ||f||), f_min (N), m contacts, e = e_s; q Coulomb cones (m or 0) and nl linear rows of their own, DL
#: (nl, >= e) applied to E and hl (nl,) N their constant terms (the slack is hl + DL y >= 0).
#: L = q + nl is the size of the nonnegative block.
_Problem = namedtuple("_Problem", "D hv a r0 mu f_min m e q nl L DL hl")

#: Work arrays for problems of m contacts, q SOCs, nl own linear rows and e_s <= e_max
#: (`_workspace`), allocated once
#: and reused by every problem of a pose; a problem uses the leading N (cone layout) or
#: n (x layout) entries of each vector.
_Work = namedtuple("_Work", [
    "D", "hv", "a", "DL", "hl",              # the problem's data (`_Problem` refers to them)
    "h", "x", "s", "z",                      # scaled h (cone layout); the iterate
    "w", "beta", "w_lin", "s_over_z", "lam",  # NT scaling: points w (cone layout), beta per SOC (objective last)
    "H3", "H_obj", "T", "M", "L",            # (W^T W)^-1 blocks (3m, 3), (e+2, e+2); normal matrix, its factor
    "r_x", "r_z", "x1", "z1", "x2", "z2", "bx", "q", "dsv",  # residuals and right-hand sides
    "dx", "dz", "ds", "dx_a", "dz_a", "ds_a",                # corrector and predictor directions
    "wn", "wn2", "ex", "wN", "wN2", "wN3", "ez",             # scratch of the linear solves
    "R_rows",                                 # Cholesky factor of A^T A, A the constraint rows
])

#: The homogenising pair (tau, kappa), the tau-row residual and c^T x1 + h^T z1 of the tau
#: column, shared by the predictor and the corrector of an iteration.
_Homogeneous = namedtuple("_Homogeneous", "tau kappa r_tau cx1_hz1")


@_jit_alloc
def _workspace(m, q, nl, e_max):
    L = q + nl
    N, n = L + 3 * q + e_max + 2, e_max + 1
    return _Work(np.empty((m, 3, e_max)), np.empty((m, 3)), np.empty(e_max), np.empty((nl, e_max)), np.empty(nl),
                 np.empty(N), np.empty(n), np.empty(N), np.empty(N),
                 np.empty(N), np.empty(q + 1), np.empty(L), np.empty(L), np.empty(N),
                 np.empty((3 * m, 3)), np.empty((e_max + 2, e_max + 2)), np.empty((m, 3, e_max)),
                 np.empty((n, n)), np.empty((n, n)),
                 np.empty(n), np.empty(N), np.empty(n), np.empty(N), np.empty(n), np.empty(N), np.empty(n),
                 np.empty(N), np.empty(N),
                 np.empty(n), np.empty(N), np.empty(N), np.empty(n), np.empty(N), np.empty(N),
                 np.empty(n), np.empty(n), np.empty(n), np.empty(N), np.empty(N), np.empty(N), np.empty(N),
                 np.empty((n, n)))


# --------------------------------------------------------------------------- cone algebra


@_jit_small
def _soc_det(v, k, d):
    """v^T J v = v0^2 - ||v1||^2, as a product to keep relative accuracy near the boundary."""
    r = 0.0
    for i in range(k + 1, k + d):
        r += v[i] * v[i]
    r = math.sqrt(r)
    return (v[k] - r) * (v[k] + r)


@_jit_small
def _soc_nt(s, z, w, k, d):
    """Nesterov-Todd scaling point of the interior pair (s, z): fills w (w^T J w = 1) and
    returns beta, with W z = W^-1 s = lambda and (W^T W)^-1 = beta^-2 (2 (Jw)(Jw)^T - J)."""
    sd = math.sqrt(_soc_det(s, k, d))
    zd = math.sqrt(_soc_det(z, k, d))
    dot = 0.0
    for i in range(k, k + d):
        dot += (s[i] / sd) * (z[i] / zd)
    gamma2 = 2.0 * math.sqrt(0.5 * (1.0 + dot))
    w[k] = (s[k] / sd + z[k] / zd) / gamma2
    for i in range(k + 1, k + d):
        w[i] = (s[i] / sd - z[i] / zd) / gamma2
    return math.sqrt(sd / zd)


@_jit_small
def _soc_apply(w, beta, v, out, k, d, inverse):
    """out = W v (or W^-1 v) for the NT scaling (w, beta)."""
    sign = -1.0 if inverse else 1.0
    scale = 1.0 / beta if inverse else beta
    w1v1 = 0.0
    for i in range(k + 1, k + d):
        w1v1 += w[i] * v[i]
    c = sign * v[k] + w1v1 / (1.0 + w[k])
    out[k] = (w[k] * v[k] + sign * w1v1) * scale
    for i in range(k + 1, k + d):
        out[i] = (v[i] + w[i] * c) * scale


@_jit_small
def _soc_hessian(w, beta, k, d, H, r0):
    """H[r0:r0 + d, :d] = (W^T W)^-1 = beta^-2 (2 u u^T - J), u = J w."""
    ib2 = 1.0 / (beta * beta)
    for i in range(d):
        ui = w[k + i] if i == 0 else -w[k + i]
        for j in range(d):
            uj = w[k + j] if j == 0 else -w[k + j]
            H[r0 + i, j] = 2.0 * ui * uj
        H[r0 + i, i] += -1.0 if i == 0 else 1.0
        for j in range(d):
            H[r0 + i, j] *= ib2


@_jit_small
def _soc_prod(u, v, out, k, d):
    """Jordan product u o v = (u^T v, u0 v1 + v0 u1)."""
    acc = 0.0
    for i in range(k, k + d):
        acc += u[i] * v[i]
    for i in range(k + 1, k + d):
        out[i] = u[k] * v[i] + v[k] * u[i]
    out[k] = acc


@_jit_small
def _soc_div(lam, w, out, k, d):
    """out = x with lam o x = w (lam in the interior)."""
    rho = _soc_det(lam, k, d)
    nu = 0.0
    for i in range(k + 1, k + d):
        nu += lam[i] * w[i]
    c = (nu / lam[k] - w[k]) / rho
    out[k] = (lam[k] * w[k] - nu) / rho
    for i in range(k + 1, k + d):
        out[i] = c * lam[i] + w[i] / lam[k]


@_jit_small
def _soc_max_step(v, dv, k, d):
    """Largest alpha >= 0 with v + alpha dv in the cone (inf if unbounded); v interior."""
    a = dv[k] * dv[k]
    b = v[k] * dv[k]
    for i in range(k + 1, k + d):
        a -= dv[i] * dv[i]
        b -= v[i] * dv[i]
    c = _soc_det(v, k, d)
    disc = b * b - a * c
    denom = -b + math.sqrt(max(disc, 0.0))
    if disc >= 0.0 and denom > 0.0:
        return c / denom
    return math.inf


@_jit_small
def _lin_max_step(v, d):
    return -v / d if d < 0.0 else math.inf


# --------------------------------------------------------------------------- linear algebra


@_jit_small
def _G_mul(P, x, out):
    """out = G x for x = (t, y): linear rows -D0 y and -DL y, Coulomb rows -D y, objective -(t, 0, y)."""
    D, DL, L, e = P.D, P.DL, P.L, P.e
    for i in range(P.q):
        for r in range(3):
            acc = 0.0
            for j in range(e):
                acc += D[i, r, j] * x[1 + j]
            out[L + 3 * i + r] = -acc
        out[i] = out[L + 3 * i]
    for k in range(P.nl):
        acc = 0.0
        for j in range(e):
            acc += DL[k, j] * x[1 + j]
        out[P.q + k] = -acc
    o = L + 3 * P.q
    out[o] = -x[0]
    out[o + 1] = 0.0
    for j in range(e):
        out[o + 2 + j] = -x[1 + j]


@_jit_small
def _rows_T_col(P, z, j):
    """Entry j of A^T z for the constraint rows A = D, DL of y (G is -A on them)."""
    D, DL, q, L = P.D, P.DL, P.q, P.L
    acc = 0.0
    for i in range(q):
        c = L + 3 * i
        acc += D[i, 0, j] * (z[c] + z[i]) + D[i, 1, j] * z[c + 1] + D[i, 2, j] * z[c + 2]
    for k in range(P.nl):
        acc += DL[k, j] * z[q + k]
    return acc


@_jit_small
def _GT_mul(P, z, out):
    """out = G^T z."""
    o = P.L + 3 * P.q
    out[0] = -z[o]
    for j in range(P.e):
        out[1 + j] = -z[o + 2 + j] - _rows_T_col(P, z, j)


@_jit_small
def _H_mul(P, W, v, out):
    """out = (W^T W)^-1 v, with the same matrices as the normal matrix (a closed form
    rounds differently, and that mismatch costs accuracy near the optimum)."""
    L, e, H3, H_obj = P.L, P.e, W.H3, W.H_obj
    for k in range(L):
        out[k] = W.w_lin[k] * v[k]
    for i in range(P.q):
        c = L + 3 * i
        for r in range(3):
            out[c + r] = H3[3 * i + r, 0] * v[c] + H3[3 * i + r, 1] * v[c + 1] + H3[3 * i + r, 2] * v[c + 2]
    o = L + 3 * P.q
    for r in range(e + 2):
        acc = 0.0
        for k in range(e + 2):
            acc += H_obj[r, k] * v[o + k]
        out[o + r] = acc


@_jit_small
def _V_mul(P, W, v, tmp, out):
    """out = W^T W v through the scaling factors (iterative refinement)."""
    q, L = P.q, P.L
    for k in range(L):
        out[k] = W.s_over_z[k] * v[k]
    for i in range(q):
        c = L + 3 * i
        _soc_apply(W.w, W.beta[i], v, tmp, c, 3, False)
        _soc_apply(W.w, W.beta[i], tmp, out, c, 3, False)
    o = L + 3 * q
    _soc_apply(W.w, W.beta[q], v, tmp, o, P.e + 2, False)
    _soc_apply(W.w, W.beta[q], tmp, out, o, P.e + 2, False)


@_jit_small
def _cholesky(M, L, n):
    """Lower Cholesky factor L of the leading (n, n) SPD block of M (lower triangle read)."""
    for j in range(n):
        for i in range(j, n):
            acc = M[i, j]
            for k in range(j):
                acc -= L[i, k] * L[j, k]
            if i == j:
                L[j, j] = math.sqrt(max(acc, 1e-300))
            else:
                L[i, j] = acc / L[j, j]


@_jit_small
def _cho_solve(L, n, b, x):
    """x with L L^T x = b (leading n entries)."""
    for i in range(n):
        acc = b[i]
        for k in range(i):
            acc -= L[i, k] * x[k]
        x[i] = acc / L[i, i]
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for k in range(i + 1, n):
            acc -= L[k, i] * x[k]
        x[i] = acc / L[i, i]


@_jit_small
def _reduced(P, W, bx, bz, dx, dz):
    """[0 G^T; G -W^T W] [dx; dz] = [bx; bz] by the normal equations."""
    wN, wn = W.wN, W.wn
    _H_mul(P, W, bz, wN)
    _GT_mul(P, wN, wn)
    for j in range(P.e + 1):
        wn[j] += bx[j]
    _cho_solve(W.L, P.e + 1, wn, dx)
    _G_mul(P, dx, wN)
    for k in range(P.L + 3 * P.q + P.e + 2):
        wN[k] -= bz[k]
    _H_mul(P, W, wN, dz)


@_jit_small
def _solve_kkt(P, W, refine, bx, bz, dx, dz):
    """The Newton system for (bx, bz), with `refine` steps of iterative refinement."""
    _reduced(P, W, bx, bz, dx, dz)
    n, N = P.e + 1, P.L + 3 * P.q + P.e + 2
    wN2, wN3, wn2 = W.wN2, W.wN3, W.wn2
    for _ in range(refine):
        # residual of the full system, then a correction from the same factorisation
        _G_mul(P, dx, wN2)
        _V_mul(P, W, dz, W.wN, wN3)
        for k in range(N):
            wN2[k] = bz[k] - wN2[k] + wN3[k]
        _GT_mul(P, dz, wn2)
        for j in range(n):
            wn2[j] = bx[j] - wn2[j]
        _reduced(P, W, wn2, wN2, W.ex, W.ez)
        for j in range(n):
            dx[j] += W.ex[j]
        for k in range(N):
            dz[k] += W.ez[k]


# --------------------------------------------------------------------------- one problem


@_jit_small
def _scaling(P, W):
    """NT scaling of the iterate (W.s, W.z), lambda = W z, and the Cholesky factor of the
    normal matrix M = G^T (W^T W)^-1 G, (e+1, e+1)."""
    q, L, e, D, DL, s, z = P.q, P.L, P.e, P.D, P.DL, W.s, W.z
    H3, H_obj, T, M = W.H3, W.H_obj, W.T, W.M
    o = L + 3 * q
    for k in range(L):
        W.w_lin[k] = z[k] / s[k]
        W.s_over_z[k] = s[k] / z[k]
        W.lam[k] = math.sqrt(s[k] * z[k])
    for i in range(q):
        c = L + 3 * i
        W.beta[i] = _soc_nt(s, z, W.w, c, 3)
        _soc_apply(W.w, W.beta[i], z, W.lam, c, 3, False)
        _soc_hessian(W.w, W.beta[i], c, 3, H3, 3 * i)
    W.beta[q] = _soc_nt(s, z, W.w, o, e + 2)
    _soc_apply(W.w, W.beta[q], z, W.lam, o, e + 2, False)
    _soc_hessian(W.w, W.beta[q], o, e + 2, H_obj, 0)
    M[0, 0] = H_obj[0, 0]
    for j in range(e):
        M[1 + j, 0] = H_obj[2 + j, 0]
        for k in range(j + 1):
            M[1 + j, 1 + k] = H_obj[2 + j, 2 + k]
    for i in range(q):
        # a contact's linear row is the first row of its Coulomb rows
        r = 3 * i
        h00 = H3[r, 0] + W.w_lin[i]
        for j in range(e):
            d0, d1, d2 = D[i, 0, j], D[i, 1, j], D[i, 2, j]
            T[i, 0, j] = h00 * d0 + H3[r, 1] * d1 + H3[r, 2] * d2
            T[i, 1, j] = H3[r + 1, 0] * d0 + H3[r + 1, 1] * d1 + H3[r + 1, 2] * d2
            T[i, 2, j] = H3[r + 2, 0] * d0 + H3[r + 2, 1] * d1 + H3[r + 2, 2] * d2
    for j in range(e):
        for k in range(j + 1):
            acc = 0.0
            for i in range(q):
                acc += D[i, 0, j] * T[i, 0, k] + D[i, 1, j] * T[i, 1, k] + D[i, 2, j] * T[i, 2, k]
            for r in range(P.nl):
                acc += DL[r, j] * (W.w_lin[q + r] * DL[r, k])
            M[1 + j, 1 + k] += acc
    _cholesky(M, W.L, e + 1)


@_jit_small
def _direction(P, W, refine, hom, sigma, dsv, d_kappa, dx, dz, ds):
    """Newton direction for the complementarity right-hand side dsv (lambda \\ d_s form) and
    d_kappa, at centring sigma; fills dx, dz, ds and returns (dtau, dkappa)."""
    n_soc, L, e, s, z, lam, q, wN = P.q, P.L, P.e, W.s, W.z, W.lam, W.q, W.wN
    o = L + 3 * n_soc
    N = o + e + 2
    f = 1.0 - sigma
    # q = W^T (lambda \ d_s) per cone
    for k in range(L):
        q[k] = math.sqrt(s[k] / z[k]) * (dsv[k] / lam[k])
    for i in range(n_soc):
        c = L + 3 * i
        _soc_div(lam, dsv, wN, c, 3)
        _soc_apply(W.w, W.beta[i], wN, q, c, 3, False)
    _soc_div(lam, dsv, wN, o, e + 2)
    _soc_apply(W.w, W.beta[n_soc], wN, q, o, e + 2, False)
    for k in range(N):
        q[k] -= f * W.r_z[k]
    for j in range(e + 1):
        W.bx[j] = -f * W.r_x[j]
    _solve_kkt(P, W, refine, W.bx, q, W.x2, W.z2)
    cx2_hz2 = W.x2[0]
    for k in range(N):
        cx2_hz2 += W.h[k] * W.z2[k]
    tau, kappa = hom.tau, hom.kappa
    dtau = (d_kappa / tau - f * hom.r_tau - cx2_hz2) / (hom.cx1_hz1 - kappa / tau)
    for j in range(e + 1):
        dx[j] = W.x2[j] + dtau * W.x1[j]
    for k in range(N):
        dz[k] = W.z2[k] + dtau * W.z1[k]
    dkappa = -(d_kappa + kappa * dtau) / tau
    # ds from the primal row G dx + ds - h dtau = -(1 - sigma) r_z: it keeps the primal
    # residual exact where W^T W is badly conditioned near the optimum.
    _G_mul(P, dx, ds)
    for k in range(N):
        ds[k] = -f * W.r_z[k] - ds[k] + W.h[k] * dtau
    return dtau, dkappa


@_jit_small
def _max_step(P, W, ds, dz, tau, dtau, kappa, dkappa):
    """Largest step along (ds, dz, dtau, dkappa) that keeps (W.s, W.z, tau, kappa) in the cones."""
    q, L, s, z = P.q, P.L, W.s, W.z
    st = min(_lin_max_step(tau, dtau), _lin_max_step(kappa, dkappa))
    for i in range(q):
        st = min(st, _lin_max_step(s[i], ds[i]), _lin_max_step(z[i], dz[i]))
        c = L + 3 * i
        st = min(st, _soc_max_step(s, ds, c, 3), _soc_max_step(z, dz, c, 3))
    for k in range(q, L):
        st = min(st, _lin_max_step(s[k], ds[k]), _lin_max_step(z[k], dz[k]))
    o = L + 3 * q
    return min(st, _soc_max_step(s, ds, o, P.e + 2), _soc_max_step(z, dz, o, P.e + 2))


@_jit_small
def _corrector_rhs(P, W, dtau_a, dkappa_a, tau, kappa, sm):
    """W.dsv: Mehrotra's second-order term (W^-T ds_a) o (W dz_a) and centring sigma mu
    (sm) added to lambda o lambda; returns the kappa row's counterpart."""
    q, L, e, s, z, lam, dsv = P.q, P.L, P.e, W.s, W.z, W.lam, W.dsv
    ds_a, dz_a, wN, wN2, wN3 = W.ds_a, W.dz_a, W.wN, W.wN2, W.wN3
    for k in range(L):
        dsv[k] = lam[k] * lam[k] + (math.sqrt(z[k] / s[k]) * ds_a[k]) * (math.sqrt(s[k] / z[k]) * dz_a[k]) - sm
    for i in range(q):
        c = L + 3 * i
        _soc_apply(W.w, W.beta[i], ds_a, wN, c, 3, True)
        _soc_apply(W.w, W.beta[i], dz_a, wN2, c, 3, False)
        _soc_prod(wN, wN2, wN3, c, 3)
        _soc_prod(lam, lam, dsv, c, 3)
        for r in range(3):
            dsv[c + r] += wN3[c + r]
        dsv[c] -= sm
    o, d = L + 3 * q, e + 2
    _soc_apply(W.w, W.beta[q], ds_a, wN, o, d, True)
    _soc_apply(W.w, W.beta[q], dz_a, wN2, o, d, False)
    _soc_prod(wN, wN2, wN3, o, d)
    _soc_prod(lam, lam, dsv, o, d)
    for r in range(d):
        dsv[o + r] += wN3[o + r]
    dsv[o] -= sm
    return tau * kappa + dtau_a * dkappa_a - sm


@_jit
def _is_optimal(pres, dres, gap, pcost, eps):
    return pres <= eps and dres <= eps and (gap <= eps or gap <= eps * abs(pcost))


@_jit
def _is_certificate(hz, gtz_norm, eps):
    """The dual iterate proves infeasibility (Farkas): h^T z < 0 and ||G^T z|| <= eps |h^T z|."""
    return hz < 0.0 and gtz_norm <= eps * -hz


@_jit_small
def _factor_rows(P, W):
    """W.R_rows: Cholesky factor of A^T A (e, e) for the constraint rows A = D, DL of y (a
    contact's linear row is its D row 0, hence the 2). Scratch: W.M (refilled by `_scaling`)."""
    D, DL, A = P.D, P.DL, W.M
    for j in range(P.e):
        for l in range(j + 1):
            acc = 0.0
            for i in range(P.q):
                acc += 2.0 * D[i, 0, j] * D[i, 0, l] + D[i, 1, j] * D[i, 1, l] + D[i, 2, j] * D[i, 2, l]
            for k in range(P.nl):
                acc += DL[k, j] * DL[k, l]
            A[j, l] = acc
    _cholesky(A, W.R_rows, P.e)


@_jit_small
def _polished_certificate(P, W, eps):
    """Whether the dual iterate's constraint part, moved to the nearest point (Euclidean)
    with G^T z = 0 and its objective part set to 0, is a Farkas certificate: inside the
    cones, h^T z < 0 and ||G^T z|| <= eps |h^T z| recomputed on the moved point. Such a
    point proves infeasibility on its own (z^T s = h^T z < 0 for every s = h - G x is
    impossible with z and s in the self-dual cones), so the iteration can stop as soon as
    the dual iterate is that close to one instead of when the homogeneous iterate has
    converged. Needs `_factor_rows`; scratch: W.wn, W.ex, W.wN2."""
    q, L, e, D, DL, z = P.q, P.L, P.e, P.D, P.DL, W.z
    g, u, zc = W.wn, W.ex, W.wN2
    for j in range(e):
        g[j] = _rows_T_col(P, z, j)
    _cho_solve(W.R_rows, e, g, u)
    # z_c = z - A u on the constraint rows; the cone test as it goes
    for i in range(q):
        c = L + 3 * i
        for r in range(3):
            acc = 0.0
            for j in range(e):
                acc += D[i, r, j] * u[j]
            zc[c + r] = z[c + r] - acc
        zc[i] = z[i] - (z[c] - zc[c])  # the linear row is the Coulomb cone's first row
        if zc[i] < 0.0 or zc[c] < math.sqrt(zc[c + 1] * zc[c + 1] + zc[c + 2] * zc[c + 2]):
            return False
    for k in range(P.nl):
        acc = 0.0
        for j in range(e):
            acc += DL[k, j] * u[j]
        zc[q + k] = z[q + k] - acc
        if zc[q + k] < 0.0:
            return False
    hz = 0.0
    for k in range(L + 3 * q):
        hz += W.h[k] * zc[k]
    if not hz < 0.0:
        return False
    gtz = 0.0
    for j in range(e):
        acc = _rows_T_col(P, zc, j)
        gtz += acc * acc
    return _is_certificate(hz, math.sqrt(gtz), eps)


@_jit_small
def _start(P, W):
    """Scaled h (the data divided by rho = max(||f_p||, f_min), so that the forces are O(1)
    and the iteration starts well centred) and the initial point; returns (rho, h_norm)."""
    q, L, e, hv, a, h, s, z = P.q, P.L, P.e, P.hv, P.a, W.h, W.s, W.z
    o = L + 3 * q
    N = o + e + 2
    fp_norm = P.r0 * P.r0
    for j in range(e):
        fp_norm += a[j] * a[j]
    rho = max(math.sqrt(fp_norm), max(P.f_min, 1e-12))
    for i in range(q):
        h[i] = (hv[i, 0] - P.f_min) / rho
        for r in range(3):
            h[L + 3 * i + r] = hv[i, r] / rho
    for k in range(P.nl):
        h[q + k] = P.hl[k] / rho
    h[o] = 0.0
    h[o + 1] = P.r0 / rho
    for j in range(e):
        h[o + 2 + j] = a[j] / rho
    hh = 0.0
    for k in range(N):
        if k != o + 1:
            hh += h[k] * h[k]
    for j in range(e + 1):
        W.x[j] = 0.0
    for k in range(N):
        s[k] = 0.0
    for k in range(L):
        s[k] = 1.0
    for i in range(q):
        s[L + 3 * i] = 1.0
    s[o] = 1.0
    for k in range(N):
        z[k] = s[k]
    return rho, max(1.0, math.sqrt(hh))


@_jit
def _hsde(P, W, opt, refine, y):
    """Solve one GFO problem by the homogeneous self-dual embedding with `refine` steps of
    iterative refinement per linear solve. Returns (code, iterations); fills y (N) when optimal."""
    q, L, e, h, x, s, z = P.q, P.L, P.e, W.h, W.x, W.s, W.z
    o = L + 3 * q
    N, n = o + e + 2, e + 1
    rho, h_norm = _start(P, W)
    n_deg = float(L + q) + 1.0  # degree: L linear, q + 1 second-order cones
    tau = 1.0
    kappa = 1.0
    r_x, r_z, dsv = W.r_x, W.r_z, W.dsv
    stalled = False
    rows_factored = False

    for it in range(opt.max_iter + 1):
        _GT_mul(P, z, r_x)
        gtz = 0.0
        for j in range(n):
            gtz += r_x[j] * r_x[j]
        gtz_norm = math.sqrt(gtz)
        r_x[0] += tau
        _G_mul(P, x, r_z)
        hz = 0.0
        sz = 0.0
        pr = 0.0
        for k in range(N):
            r_z[k] += s[k] - h[k] * tau
            hz += h[k] * z[k]
            sz += s[k] * z[k]
            pr += r_z[k] * r_z[k]
        r_tau = kappa + x[0] + hz
        mu = (sz + tau * kappa) / (n_deg + 1.0)
        dr = 0.0
        for j in range(n):
            dr += r_x[j] * r_x[j]
        # Stopping tests on the de-homogenised point.
        pres = math.sqrt(pr) / tau / h_norm
        dres = math.sqrt(dr) / tau
        pcost = x[0] / tau
        gap = sz / (tau * tau)
        last = it == opt.max_iter or stalled
        optimal = _is_optimal(pres, dres, gap, pcost, opt.tol)
        infeasible = not optimal and _is_certificate(hz, gtz_norm, opt.tol)
        if not (optimal or infeasible) and hz < 0.0:
            if not rows_factored:
                _factor_rows(P, W)
                rows_factored = True
            infeasible = _polished_certificate(P, W, opt.tol)
        if last:
            optimal = optimal or _is_optimal(pres, dres, gap, pcost, opt.reduced_tol)
            infeasible = infeasible or (not optimal and _is_certificate(hz, gtz_norm, opt.reduced_tol))
        if optimal:
            for j in range(e):
                y[j] = x[1 + j] / tau * rho
            return OPTIMAL, it
        if infeasible:
            return INFEASIBLE, it
        if last or not (math.isfinite(mu) and math.isfinite(tau) and tau > 0.0):
            return UNDECIDED, it

        _scaling(P, W)
        # x1, z1: the solution for the tau column, -c and h.
        for j in range(n):
            W.bx[j] = -1.0 if j == 0 else 0.0
        _solve_kkt(P, W, refine, W.bx, h, W.x1, W.z1)
        cx1_hz1 = W.x1[0]
        for k in range(N):
            cx1_hz1 += h[k] * W.z1[k]
        hom = _Homogeneous(tau, kappa, r_tau, cx1_hz1)

        # Predictor (affine scaling): d_s = lambda o lambda, d_kappa = tau kappa.
        for k in range(L):
            dsv[k] = W.lam[k] * W.lam[k]
        for i in range(q):
            _soc_prod(W.lam, W.lam, dsv, L + 3 * i, 3)
        _soc_prod(W.lam, W.lam, dsv, o, e + 2)
        dtau_a, dkappa_a = _direction(P, W, refine, hom, 0.0, dsv, tau * kappa, W.dx_a, W.dz_a, W.ds_a)
        alpha_a = min(1.0, _max_step(P, W, W.ds_a, W.dz_a, tau, dtau_a, kappa, dkappa_a))
        sigma = min(max((1.0 - alpha_a) ** 3, 0.0), 1.0)

        # Corrector.
        d_kap = _corrector_rhs(P, W, dtau_a, dkappa_a, tau, kappa, sigma * mu)
        dtau, dkappa = _direction(P, W, refine, hom, sigma, dsv, d_kap, W.dx, W.dz, W.ds)
        alpha = min(1.0, opt.step_fraction * _max_step(P, W, W.ds, W.dz, tau, dtau, kappa, dkappa))

        # A vanishing step near the optimum means the normal equations have run out of
        # accuracy: keep the current point and judge it with the reduced tolerance.
        stalled = alpha < opt.stall_step
        if stalled:
            alpha = 0.0
        for j in range(n):
            x[j] += alpha * W.dx[j]
        for k in range(N):
            s[k] += alpha * W.ds[k]
            z[k] += alpha * W.dz[k]
        tau += alpha * dtau
        kappa += alpha * dkappa
    return UNDECIDED, opt.max_iter


# --------------------------------------------------------------------------- one problem, built


@_jit_alloc
def _build(rows, lin, E, fp, e, mu, f_min, W):
    """The problem of cone rows (m, 3, 3) (`_cone_rows`), linear rows lin (m, p, 3)
    (`_cone_data`: p = 0 for the circular cone, whose Coulomb cones are SOCs; a pyramid's
    [n; -a_1; ...] with the normal bound first, the kernel's nonnegative block in this
    order), basis E (3m, >= e; its first e columns) and f_p (3m,) N, its data written into W."""
    m, p = rows.shape[0], lin.shape[1]
    D, hv, a, DL, hl = W.D, W.hv, W.a, W.DL, W.hl
    for i in range(m):
        for r in range(p):
            k = i * p + r
            acc = 0.0
            for q in range(3):
                acc += lin[i, r, q] * fp[3 * i + q]
            hl[k] = acc - f_min if r == 0 else acc
            for j in range(e):
                acc = 0.0
                for q in range(3):
                    acc += lin[i, r, q] * E[3 * i + q, j]
                DL[k, j] = acc
    for i in range(m):
        for r in range(3):
            acc = 0.0
            for q in range(3):
                acc += rows[i, r, q] * fp[3 * i + q]
            hv[i, r] = acc
            for k in range(e):
                acc = 0.0
                for q in range(3):
                    acc += rows[i, r, q] * E[3 * i + q, k]
                D[i, r, k] = acc
    for k in range(e):
        a[k] = 0.0
    for c in range(3 * m):
        for k in range(e):
            a[k] += E[c, k] * fp[c]
    r0 = 0.0
    for c in range(3 * m):
        acc = fp[c]
        for k in range(e):
            acc -= E[c, k] * a[k]
        r0 += acc * acc
    q = m if p == 0 else 0
    return _Problem(D, hv, a, math.sqrt(r0), mu, f_min, m, e, q, m * p, q + m * p, DL, hl)


@_jit
def _attempt(P, W, opt, refine, y):
    """`_hsde`, then the force check of an optimal point: (code, ||f|| N, violation N, iterations).
    An optimal point whose forces violate a constraint by more than violation_tol max(1 N, ||f||)
    is 'not decided' (the rule of `solve_gfo` for reduced accuracy)."""
    code, it = _hsde(P, W, opt, refine, y)
    if code != OPTIMAL:
        return code, math.nan, math.nan, it
    # f = f_p + E y in the contact frames: [n.f, t1.f/mu, t2.f/mu]
    D, hv, DL, hl, e = P.D, P.hv, P.DL, P.hl, P.e
    norm = 0.0
    viol = -math.inf
    for i in range(P.m):
        f0, f1, f2 = hv[i, 0], hv[i, 1], hv[i, 2]
        for k in range(e):
            f0 += D[i, 0, k] * y[k]
        for k in range(e):
            f1 += D[i, 1, k] * y[k]
        for k in range(e):
            f2 += D[i, 2, k] * y[k]
        ft = P.mu * math.sqrt(f1 * f1 + f2 * f2)
        norm += f0 * f0 + ft * ft
        if i < P.q:
            viol = max(viol, P.f_min - f0, ft - P.mu * f0)
    for k in range(P.nl):
        # a linear row's slack hl + DL y (N) must be >= 0
        acc = hl[k]
        for j in range(e):
            acc += DL[k, j] * y[j]
        viol = max(viol, -acc)
    norm = math.sqrt(norm)
    if viol > opt.violation_tol * max(1.0, norm):
        return UNDECIDED, math.nan, math.nan, it
    return code, norm, viol, it


@_jit
def _solve_one(P, W, opt, y):
    """`_attempt`, and a second one with refinement if the first leaves the problem undecided.
    Returns (code, ||f|| N, worst violation N, iterations of both); fills y."""
    code, norm, viol, it = _attempt(P, W, opt, opt.refine, y)
    if code == UNDECIDED and opt.retry_refine > opt.refine:
        # Undecided problems are mostly stalls at a degenerate optimum, where the normal
        # equations lose accuracy: a second attempt with iterative refinement decides most.
        code, norm, viol, it2 = _attempt(P, W, opt, opt.retry_refine, y)
        it += it2
    return code, norm, viol, it


@_jit
def _cone_rows(frames, mu, rows):
    """Kernel form of the circular cone from the contact frames (m, 3, 3) [n; t1; t2]:
    rows [n; t1/mu; t2/mu], so that the cone is rows @ f_i in SOC(3) and the linear row
    n.f - f_min >= 0 is its first row."""
    for i in range(frames.shape[0]):
        for q in range(3):
            rows[i, 0, q] = frames[i, 0, q]
            rows[i, 1, q] = frames[i, 1, q] / mu
            rows[i, 2, q] = frames[i, 2, q] / mu


@_jit_alloc
def _solve_single(frames, cone, E, fp, f_min, opt, y):
    """One problem (`solve_problem`; cone: `_ConeData`): (code, ||f|| N, iterations); fills y."""
    m, p, e = frames.shape[0], cone.lin.shape[1], E.shape[1]
    rows = np.empty((m, 3, 3))
    _cone_rows(frames, cone.mu, rows)
    W = _workspace(m, m if p == 0 else 0, m * p, e)
    code, norm, _, it = _solve_one(_build(rows, cone.lin, E, fp, e, cone.mu, f_min, W), W, opt, y)
    return code, norm, it


@_jit
def _range_basis(F_all, cols, s, threshold, U):
    """E_s of one set: an orthonormal basis of the range of F = F_all[:, cols[:s]] from its
    singular vectors whose singular value exceeds `threshold` (the rule of
    `mechanics.internal_force_basis`), written into the leading columns of U; returns their
    number. One-sided Jacobi (Hestenes): plane rotations of pairs of F's columns until every
    pair is orthogonal to ~1e-15 relative; the columns are then U Sigma, and their norms the
    singular values, to high relative accuracy. Sets hold 1 to 15 synergies, so this is a
    few sweeps of short loops, without LAPACK's copies, workspace query and allocations."""
    c = F_all.shape[0]
    for q in range(s):
        for k in range(c):
            U[k, q] = F_all[k, cols[q]]
    tol = 1e-15 * c
    for _ in range(60):
        rotated = False
        for a in range(s - 1):
            for b in range(a + 1, s):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for k in range(c):
                    alpha += U[k, a] * U[k, a]
                    beta += U[k, b] * U[k, b]
                    gamma += U[k, a] * U[k, b]
                if abs(gamma) <= tol * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for k in range(c):
                    ua, ub = U[k, a], U[k, b]
                    U[k, a] = cs * ua - sn * ub
                    U[k, b] = sn * ua + cs * ub
        if not rotated:
            break
    rank = 0
    for q in range(s):
        norm = 0.0
        for k in range(c):
            norm += U[k, q] * U[k, q]
        norm = math.sqrt(norm)
        if norm > threshold:
            for k in range(c):
                U[k, rank] = U[k, q] / norm
            rank += 1
    return rank


@_jit_alloc
def _solve_sets(F_all, fp, frames, cols, n_cols, thresholds, cone, cone_strict, f_min, strict, opt, out):
    """Every synergy set of one grasp into `out` (`SetsResult`): E_s from the singular vectors
    of F_s = F_all[:, set] whose singular value is above the set's threshold (`_range_basis`), then the
    GFO, its forces f_p + E_s y (N) and, if `strict`, the strict internal-force test
    (f_p = 0, f_min = 1 N, cone_strict). cone, cone_strict: `_ConeData` of the same kind.
    Sets with e_s = 0 get code NOT_SOLVED."""
    c = F_all.shape[0]
    m, p = c // 3, cone.lin.shape[1]
    rows = np.empty((m, 3, 3))
    rows_strict = np.empty((m, 3, 3))
    _cone_rows(frames, cone.mu, rows)
    _cone_rows(frames, cone_strict.mu, rows_strict)
    zero = np.zeros(c)
    W = _workspace(m, m if p == 0 else 0, m * p, cols.shape[1])
    y = np.empty(cols.shape[1])
    U = np.empty((c, cols.shape[1]))
    for j in range(cols.shape[0]):
        rank = _range_basis(F_all, cols[j], n_cols[j], thresholds[j], U)
        out.e_s[j] = rank
        if rank == 0:
            out.code[j] = NOT_SOLVED
            continue
        # E_s is the first `rank` columns of U
        code, out.force_norm[j], out.max_violation[j], out.iterations[j] = _solve_one(
            _build(rows, cone.lin, U, fp, rank, cone.mu, f_min, W), W, opt, y)
        out.code[j] = code
        if code == OPTIMAL:
            for k in range(c):
                acc = fp[k]
                for q in range(rank):
                    acc += U[k, q] * y[q]
                out.forces[j, k] = acc
        if strict:
            out.strict_code[j] = _solve_one(_build(rows_strict, cone_strict.lin, U, zero, rank, cone_strict.mu, 1.0, W),
                                            W, opt, y)[0]


def _kernel_settings(settings: IPMSettings, violation_tol: float) -> _Settings:
    return _Settings(float(settings.tol), float(settings.reduced_tol), int(settings.max_iter),
                     float(settings.step_fraction), float(settings.stall_step), int(settings.refine),
                     int(settings.retry_refine), float(violation_tol))


#: A friction cone as the compiled code takes it: mu dividing the tangent rows of the contact
#: frames (1 for a pyramid, whose D rows serve only ||f||) and the linear rows lin (m, p, 3)
#: per contact, p = 0 for the circular cone (see `_build`).
_ConeData = namedtuple("_ConeData", "mu lin")


def _cone_data(cone: FrictionCone, frames: NDArray) -> _ConeData:
    """The kernel's form of a cone model on the contact frames (m, 3, 3): the circular cone's
    mu; a pyramid's rows n (the normal bound) and -a_k (`PyramidCone.face_rows`, a_k.f <= 0)."""
    if cone.kind == "circular":
        return _ConeData(float(cone.mu), np.empty((frames.shape[0], 0, 3)))
    lin = np.concatenate([frames[:, None, 0], -cone.face_rows(frames)], axis=1)
    return _ConeData(1.0, np.ascontiguousarray(lin))


def solve_problem(frames: NDArray, E: NDArray, f_p: NDArray, cone: FrictionCone, f_min: float,
                  settings: IPMSettings, violation_tol: float) -> tuple[int, float, NDArray, int]:
    """One problem: frames (m, 3, 3) from `mechanics.contact_frames`, E (3m, e) orthonormal
    with e >= 1, f_p (3m,) N, the friction-cone model, f_min N. An optimal point whose forces
    violate a constraint by more than violation_tol max(1 N, ||f||) is UNDECIDED.
    Returns (code, ||f|| N, y (e,) N (NaN unless OPTIMAL), iterations)."""
    y = np.full(E.shape[1], np.nan)
    code, norm, iters = _solve_single(frames, _cone_data(cone, frames), np.ascontiguousarray(E, dtype=float),
                                      np.ascontiguousarray(f_p, dtype=float), float(f_min),
                                      _kernel_settings(settings, violation_tol), y)
    if code != OPTIMAL:
        y[:] = np.nan
    return int(code), float(norm), y, int(iters)


class SetsResult(NamedTuple):
    """Kernel output for the sets of one grasp (arrays over the sets): code, ||f|| N,
    worst constraint violation N, iterations, e_s, strict_code (INFEASIBLE where not
    tested), forces (n_sets, 3m) N (rows of OPTIMAL sets only)."""

    code: NDArray
    force_norm: NDArray
    max_violation: NDArray
    iterations: NDArray
    e_s: NDArray
    strict_code: NDArray
    forces: NDArray


def solve_sets(F_all: NDArray, f_p: NDArray, frames: NDArray, columns: NDArray, n_columns: NDArray,
               thresholds: NDArray, cone: FrictionCone, strict_cone: FrictionCone | None, f_min: float,
               settings: IPMSettings, violation_tol: float) -> SetsResult:
    """Every set of one grasp in one compiled call. F_all: (3m, k) projector @ S, N per
    unit activation; columns: (n_sets, max size) 0-based columns of F_all per set (the first
    n_columns[j] of row j); thresholds: (n_sets,) rank thresholds of the singular values;
    cone: the friction-cone model; strict_cone: that of the strict internal-force test (the
    cone narrowed), None for no strict test."""
    n_sets = columns.shape[0]
    out = SetsResult(code=np.zeros(n_sets, dtype=np.int8), force_norm=np.full(n_sets, np.nan),
                     max_violation=np.full(n_sets, np.nan),
                     iterations=np.zeros(n_sets, dtype=np.int32), e_s=np.zeros(n_sets, dtype=np.int64),
                     strict_code=np.full(n_sets, INFEASIBLE, dtype=np.int8),
                     forces=np.full((n_sets, f_p.size), np.nan))
    data = _cone_data(cone, frames)
    _solve_sets(np.ascontiguousarray(F_all), np.ascontiguousarray(f_p, dtype=float), frames, columns, n_columns,
                thresholds, data, data if strict_cone is None else _cone_data(strict_cone, frames), float(f_min),
                strict_cone is not None, _kernel_settings(settings, violation_tol), out)
    return out
