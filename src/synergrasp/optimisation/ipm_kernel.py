"""Back end: the compiled interior-point kernel (numba) for GFO problems with circular cones
(docs/batched_solver.md).

Per problem, forces in N: minimise ||f_p + E y||_2 subject to, per contact i,
n_i.f_i >= f_min and ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i. With E orthonormal,
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
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

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


# --------------------------------------------------------------------------- cone algebra
# Compiled with numba: one problem at a time, so a problem's numbers never depend on the
# batch it arrives in, and the ~10 iterations of a tiny problem cost microseconds instead of
# the hundreds of numpy calls a vectorised iteration needs. A cone vector v has v[0] >= ||v[1:]||.
# Flat layout of a problem's cone vectors (length 4m + e + 2): m linear slacks n.f - f_min,
# then m Coulomb cones SOC(3) [n.f, t1.f/mu, t2.f/mu], then the objective cone (t, r0, y + a).

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")
_jit_small = numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")


@_jit_small
def _soc_det(v):
    """v^T J v = v0^2 - ||v1||^2, as a product to keep relative accuracy near the boundary."""
    r = 0.0
    for i in range(1, v.size):
        r += v[i] * v[i]
    r = math.sqrt(r)
    return (v[0] - r) * (v[0] + r)


@_jit_small
def _soc_nt(s, z, w):
    """Nesterov-Todd scaling point of the interior pair (s, z): fills w (w^T J w = 1) and
    returns beta, with W z = W^-1 s = lambda and (W^T W)^-1 = beta^-2 (2 (Jw)(Jw)^T - J)."""
    sd = math.sqrt(_soc_det(s))
    zd = math.sqrt(_soc_det(z))
    dot = 0.0
    for i in range(s.size):
        dot += (s[i] / sd) * (z[i] / zd)
    gamma2 = 2.0 * math.sqrt(0.5 * (1.0 + dot))
    w[0] = (s[0] / sd + z[0] / zd) / gamma2
    for i in range(1, s.size):
        w[i] = (s[i] / sd - z[i] / zd) / gamma2
    return math.sqrt(sd / zd)


@_jit_small
def _soc_apply(w, beta, v, out, inverse):
    """out = W v (or W^-1 v) for the NT scaling (w, beta)."""
    sign = -1.0 if inverse else 1.0
    scale = 1.0 / beta if inverse else beta
    w1v1 = 0.0
    for i in range(1, v.size):
        w1v1 += w[i] * v[i]
    c = sign * v[0] + w1v1 / (1.0 + w[0])
    out[0] = (w[0] * v[0] + sign * w1v1) * scale
    for i in range(1, v.size):
        out[i] = (v[i] + w[i] * c) * scale


@_jit_small
def _soc_hessian(w, beta, H):
    """H = (W^T W)^-1 = beta^-2 (2 u u^T - J), u = J w."""
    d = w.size
    ib2 = 1.0 / (beta * beta)
    for i in range(d):
        ui = w[i] if i == 0 else -w[i]
        for j in range(d):
            uj = w[j] if j == 0 else -w[j]
            H[i, j] = 2.0 * ui * uj
        H[i, i] += -1.0 if i == 0 else 1.0
        for j in range(d):
            H[i, j] *= ib2


@_jit_small
def _soc_prod(u, v, out):
    """Jordan product u o v = (u^T v, u0 v1 + v0 u1)."""
    acc = 0.0
    for i in range(u.size):
        acc += u[i] * v[i]
    for i in range(1, u.size):
        out[i] = u[0] * v[i] + v[0] * u[i]
    out[0] = acc


@_jit_small
def _soc_div(lam, w, out):
    """out = x with lam o x = w (lam in the interior)."""
    rho = _soc_det(lam)
    nu = 0.0
    for i in range(1, lam.size):
        nu += lam[i] * w[i]
    c = (nu / lam[0] - w[0]) / rho
    out[0] = (lam[0] * w[0] - nu) / rho
    for i in range(1, lam.size):
        out[i] = c * lam[i] + w[i] / lam[0]


@_jit_small
def _soc_max_step(v, d):
    """Largest alpha >= 0 with v + alpha d in the cone (inf if unbounded); v interior."""
    a = d[0] * d[0]
    b = v[0] * d[0]
    for i in range(1, v.size):
        a -= d[i] * d[i]
        b -= v[i] * d[i]
    c = _soc_det(v)
    disc = b * b - a * c
    denom = -b + math.sqrt(max(disc, 0.0))
    if disc >= 0.0 and denom > 0.0:
        return c / denom
    return math.inf


@_jit_small
def _lin_max_step(v, d):
    return -v / d if d < 0.0 else math.inf


# --------------------------------------------------------------------------- one problem


@_jit
def _G_mul(D, m, e, x, out):
    """out = G x for x = (t, y): linear rows -D0 y, Coulomb rows -D y, objective -(t, 0, y)."""
    for i in range(m):
        for r in range(3):
            acc = 0.0
            for j in range(e):
                acc += D[i, r, j] * x[1 + j]
            out[m + 3 * i + r] = -acc
        out[i] = out[m + 3 * i]
    o = 4 * m
    out[o] = -x[0]
    out[o + 1] = 0.0
    for j in range(e):
        out[o + 2 + j] = -x[1 + j]


@_jit
def _GT_mul(D, m, e, z, out):
    """out = G^T z."""
    o = 4 * m
    out[0] = -z[o]
    for j in range(e):
        acc = 0.0
        for i in range(m):
            c = m + 3 * i
            acc += D[i, 0, j] * (z[c] + z[i]) + D[i, 1, j] * z[c + 1] + D[i, 2, j] * z[c + 2]
        out[1 + j] = -z[o + 2 + j] - acc


@_jit
def _H_mul(m, e, w_lin, H_soc, H_obj, v, out):
    """out = (W^T W)^-1 v, with the same matrices as the normal matrix (a closed form
    rounds differently, and that mismatch costs accuracy near the optimum)."""
    for i in range(m):
        out[i] = w_lin[i] * v[i]
        c = m + 3 * i
        for r in range(3):
            out[c + r] = H_soc[i, r, 0] * v[c] + H_soc[i, r, 1] * v[c + 1] + H_soc[i, r, 2] * v[c + 2]
    o = 4 * m
    for r in range(e + 2):
        acc = 0.0
        for k in range(e + 2):
            acc += H_obj[r, k] * v[o + k]
        out[o + r] = acc


@_jit
def _V_mul(m, e, s_over_z, w_soc, b_soc, w_obj, b_obj, v, tmp, out):
    """out = W^T W v through the scaling factors (iterative refinement)."""
    for i in range(m):
        out[i] = s_over_z[i] * v[i]
        c = m + 3 * i
        _soc_apply(w_soc[i], b_soc[i], v[c:c + 3], tmp[c:c + 3], False)
        _soc_apply(w_soc[i], b_soc[i], tmp[c:c + 3], out[c:c + 3], False)
    o = 4 * m
    _soc_apply(w_obj, b_obj, v[o:], tmp[o:], False)
    _soc_apply(w_obj, b_obj, tmp[o:], out[o:], False)


@_jit
def _cholesky(M, L):
    """Lower Cholesky factor L of the SPD matrix M (lower triangle read)."""
    n = M.shape[0]
    for j in range(n):
        for i in range(j, n):
            acc = M[i, j]
            for k in range(j):
                acc -= L[i, k] * L[j, k]
            if i == j:
                L[j, j] = math.sqrt(max(acc, 1e-300))
            else:
                L[i, j] = acc / L[j, j]


@_jit
def _cho_solve(L, b, x):
    """x with L L^T x = b."""
    n = L.shape[0]
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


@_jit
def _reduced(D, m, e, L, w_lin, H_soc, H_obj, bx, bz, dx, dz, wN, wn):
    """[0 G^T; G -W^T W] [dx; dz] = [bx; bz] by the normal equations."""
    _H_mul(m, e, w_lin, H_soc, H_obj, bz, wN)
    _GT_mul(D, m, e, wN, wn)
    for j in range(e + 1):
        wn[j] += bx[j]
    _cho_solve(L, wn, dx)
    _G_mul(D, m, e, dx, wN)
    for k in range(wN.size):
        wN[k] -= bz[k]
    _H_mul(m, e, w_lin, H_soc, H_obj, wN, dz)


@_jit
def _solve_kkt(D, m, e, L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj, refine,
               bx, bz, dx, dz, wN, wN2, wN3, wn, wn2):
    _reduced(D, m, e, L, w_lin, H_soc, H_obj, bx, bz, dx, dz, wN, wn)
    for _ in range(refine):
        # residual of the full system, then a correction from the same factorisation
        _G_mul(D, m, e, dx, wN2)
        _V_mul(m, e, s_over_z, w_soc, b_soc, w_obj, b_obj, dz, wN, wN3)
        for k in range(wN.size):
            wN2[k] = bz[k] - wN2[k] + wN3[k]
        _GT_mul(D, m, e, dz, wn2)
        for j in range(e + 1):
            wn2[j] = bx[j] - wn2[j]
        ex = np.empty(e + 1)
        ez = np.empty(wN.size)
        _reduced(D, m, e, L, w_lin, H_soc, H_obj, wn2, wN2, ex, ez, wN, wn)
        for j in range(e + 1):
            dx[j] += ex[j]
        for k in range(wN.size):
            dz[k] += ez[k]


@_jit
def _max_step(m, s, z, ds, dz, tau, dtau, kappa, dkappa):
    st = min(_lin_max_step(tau, dtau), _lin_max_step(kappa, dkappa))
    for i in range(m):
        st = min(st, _lin_max_step(s[i], ds[i]), _lin_max_step(z[i], dz[i]))
        c = m + 3 * i
        st = min(st, _soc_max_step(s[c:c + 3], ds[c:c + 3]), _soc_max_step(z[c:c + 3], dz[c:c + 3]))
    o = 4 * m
    return min(st, _soc_max_step(s[o:], ds[o:]), _soc_max_step(z[o:], dz[o:]))


@_jit
def _is_optimal(pres, dres, gap, pcost, eps):
    return pres <= eps and dres <= eps and (gap <= eps or gap <= eps * abs(pcost))


@_jit
def _is_certificate(hz, gtz_norm, eps):
    """The dual iterate proves infeasibility (Farkas): h^T z < 0 and ||G^T z|| <= eps |h^T z|."""
    return hz < 0.0 and gtz_norm <= eps * -hz


@_jit
def _hsde(D, hv, a, r0, f_min, m, e, tol, reduced_tol, max_iter, step_fraction, stall_step, refine, y):
    """Solve one GFO problem (contact rows D (m, 3, e), h (m, 3), a (e,), N) by the homogeneous
    self-dual embedding. Returns (code, iterations); fills y (N) when optimal."""
    N = 4 * m + e + 2
    n = e + 1
    o = 4 * m
    # Scale so that the forces are O(1): the iteration then starts well centred.
    fp_norm = r0 * r0
    for j in range(e):
        fp_norm += a[j] * a[j]
    rho = max(math.sqrt(fp_norm), max(f_min, 1e-12))
    h = np.zeros(N)
    for i in range(m):
        h[i] = (hv[i, 0] - f_min) / rho
        for r in range(3):
            h[m + 3 * i + r] = hv[i, r] / rho
    h[o + 1] = r0 / rho
    for j in range(e):
        h[o + 2 + j] = a[j] / rho
    hh = 0.0
    for k in range(N):
        if k != o + 1:
            hh += h[k] * h[k]
    h_norm = max(1.0, math.sqrt(hh))
    n_deg = 2.0 * m + 1.0

    x = np.zeros(n)
    s = np.zeros(N)
    for i in range(m):
        s[i] = 1.0
        s[m + 3 * i] = 1.0
    s[o] = 1.0
    z = s.copy()
    tau = 1.0
    kappa = 1.0

    r_x, x1, x2, dx, dx_a = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    bx, wn, wn2 = np.empty(n), np.empty(n), np.empty(n)
    r_z, z1, z2, dz, dz_a = np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    ds, ds_a, dsv, q = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    wN, wN2, wN3 = np.empty(N), np.empty(N), np.empty(N)
    lam = np.empty(N)
    w_lin = np.empty(m)
    s_over_z = np.empty(m)
    w_soc = np.empty((m, 3))
    b_soc = np.empty(m)
    w_obj = np.empty(e + 2)
    H_soc = np.empty((m, 3, 3))
    H_obj = np.empty((e + 2, e + 2))
    T = np.empty((m, 3, e))
    M = np.empty((n, n))
    L = np.zeros((n, n))
    tmp3 = np.empty(3)
    tmp_o = np.empty(e + 2)
    stalled = False

    for it in range(max_iter + 1):
        _GT_mul(D, m, e, z, r_x)
        gtz = 0.0
        for j in range(n):
            gtz += r_x[j] * r_x[j]
        gtz_norm = math.sqrt(gtz)
        r_x[0] += tau
        _G_mul(D, m, e, x, r_z)
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
        last = it == max_iter or stalled
        optimal = _is_optimal(pres, dres, gap, pcost, tol)
        infeasible = not optimal and _is_certificate(hz, gtz_norm, tol)
        if last:
            optimal = optimal or _is_optimal(pres, dres, gap, pcost, reduced_tol)
            infeasible = infeasible or (not optimal and _is_certificate(hz, gtz_norm, reduced_tol))
        if optimal:
            for j in range(e):
                y[j] = x[1 + j] / tau * rho
            return OPTIMAL, it
        if infeasible:
            return INFEASIBLE, it
        if last or not (math.isfinite(mu) and math.isfinite(tau) and tau > 0.0):
            return UNDECIDED, it

        # Nesterov-Todd scaling and the normal matrix M = G^T (W^T W)^-1 G, (e+1, e+1).
        for i in range(m):
            w_lin[i] = z[i] / s[i]
            s_over_z[i] = s[i] / z[i]
            lam[i] = math.sqrt(s[i] * z[i])
            c = m + 3 * i
            b_soc[i] = _soc_nt(s[c:c + 3], z[c:c + 3], w_soc[i])
            _soc_apply(w_soc[i], b_soc[i], z[c:c + 3], lam[c:c + 3], False)
            _soc_hessian(w_soc[i], b_soc[i], H_soc[i])
        b_obj = _soc_nt(s[o:], z[o:], w_obj)
        _soc_apply(w_obj, b_obj, z[o:], lam[o:], False)
        _soc_hessian(w_obj, b_obj, H_obj)
        M[0, 0] = H_obj[0, 0]
        for j in range(e):
            M[1 + j, 0] = H_obj[2 + j, 0]
            for k in range(j + 1):
                M[1 + j, 1 + k] = H_obj[2 + j, 2 + k]
        for i in range(m):
            # a contact's linear row is the first row of its Coulomb rows
            h00 = H_soc[i, 0, 0] + w_lin[i]
            for j in range(e):
                d0, d1, d2 = D[i, 0, j], D[i, 1, j], D[i, 2, j]
                T[i, 0, j] = h00 * d0 + H_soc[i, 0, 1] * d1 + H_soc[i, 0, 2] * d2
                T[i, 1, j] = H_soc[i, 1, 0] * d0 + H_soc[i, 1, 1] * d1 + H_soc[i, 1, 2] * d2
                T[i, 2, j] = H_soc[i, 2, 0] * d0 + H_soc[i, 2, 1] * d1 + H_soc[i, 2, 2] * d2
        for j in range(e):
            for k in range(j + 1):
                acc = 0.0
                for i in range(m):
                    acc += D[i, 0, j] * T[i, 0, k] + D[i, 1, j] * T[i, 1, k] + D[i, 2, j] * T[i, 2, k]
                M[1 + j, 1 + k] += acc
        _cholesky(M, L)

        # x1, z1: the solution for the tau column, -c and h.
        for j in range(n):
            bx[j] = -1.0 if j == 0 else 0.0
        _solve_kkt(D, m, e, L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj, refine,
                   bx, h, x1, z1, wN, wN2, wN3, wn, wn2)
        cx1_hz1 = x1[0]
        for k in range(N):
            cx1_hz1 += h[k] * z1[k]

        # Predictor (affine scaling): d_s = lambda o lambda, d_kappa = tau kappa.
        for i in range(m):
            dsv[i] = lam[i] * lam[i]
            c = m + 3 * i
            _soc_prod(lam[c:c + 3], lam[c:c + 3], dsv[c:c + 3])
        _soc_prod(lam[o:], lam[o:], dsv[o:])
        dtau_a, dkappa_a = _direction(D, m, e, 0.0, dsv, tau * kappa, s, z, lam, h, r_x, r_z, r_tau, tau, kappa,
                                      cx1_hz1, x1, z1, L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj,
                                      refine, dx_a, dz_a, ds_a, q, x2, z2, wN, wN2, wN3, bx, wn, wn2)
        alpha_a = min(1.0, _max_step(m, s, z, ds_a, dz_a, tau, dtau_a, kappa, dkappa_a))
        sigma = min(max((1.0 - alpha_a) ** 3, 0.0), 1.0)
        sm = sigma * mu

        # Corrector: Mehrotra's second-order term (W^-T ds_a) o (W dz_a) and centring sigma mu.
        for i in range(m):
            dsv[i] = lam[i] * lam[i] + (math.sqrt(z[i] / s[i]) * ds_a[i]) * (math.sqrt(s[i] / z[i]) * dz_a[i]) - sm
            c = m + 3 * i
            _soc_apply(w_soc[i], b_soc[i], ds_a[c:c + 3], wN[c:c + 3], True)
            _soc_apply(w_soc[i], b_soc[i], dz_a[c:c + 3], wN2[c:c + 3], False)
            _soc_prod(wN[c:c + 3], wN2[c:c + 3], tmp3)
            _soc_prod(lam[c:c + 3], lam[c:c + 3], dsv[c:c + 3])
            for r in range(3):
                dsv[c + r] += tmp3[r]
            dsv[c] -= sm
        _soc_apply(w_obj, b_obj, ds_a[o:], wN[o:], True)
        _soc_apply(w_obj, b_obj, dz_a[o:], wN2[o:], False)
        _soc_prod(wN[o:], wN2[o:], tmp_o)
        _soc_prod(lam[o:], lam[o:], dsv[o:])
        for r in range(e + 2):
            dsv[o + r] += tmp_o[r]
        dsv[o] -= sm
        d_kap = tau * kappa + dtau_a * dkappa_a - sm
        dtau, dkappa = _direction(D, m, e, sigma, dsv, d_kap, s, z, lam, h, r_x, r_z, r_tau, tau, kappa,
                                  cx1_hz1, x1, z1, L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj,
                                  refine, dx, dz, ds, q, x2, z2, wN, wN2, wN3, bx, wn, wn2)
        alpha = min(1.0, step_fraction * _max_step(m, s, z, ds, dz, tau, dtau, kappa, dkappa))

        # A vanishing step near the optimum means the normal equations have run out of
        # accuracy: keep the current point and judge it with the reduced tolerance.
        stalled = alpha < stall_step
        if stalled:
            alpha = 0.0
        for j in range(n):
            x[j] += alpha * dx[j]
        for k in range(N):
            s[k] += alpha * ds[k]
            z[k] += alpha * dz[k]
        tau += alpha * dtau
        kappa += alpha * dkappa
    return UNDECIDED, max_iter


@_jit
def _direction(D, m, e, sigma, dsv, d_kappa, s, z, lam, h, r_x, r_z, r_tau, tau, kappa, cx1_hz1, x1, z1,
               L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj, refine,
               dx, dz, ds, q, x2, z2, wN, wN2, wN3, bx, wn, wn2):
    """Newton direction for the complementarity right-hand side dsv (lambda \\ d_s form);
    fills dx, dz, ds and returns (dtau, dkappa)."""
    N = 4 * m + e + 2
    o = 4 * m
    f = 1.0 - sigma
    # q = W^T (lambda \ d_s) per cone
    for i in range(m):
        q[i] = math.sqrt(s[i] / z[i]) * (dsv[i] / lam[i])
        c = m + 3 * i
        _soc_div(lam[c:c + 3], dsv[c:c + 3], wN[c:c + 3])
        _soc_apply(w_soc[i], b_soc[i], wN[c:c + 3], q[c:c + 3], False)
    _soc_div(lam[o:], dsv[o:], wN[o:])
    _soc_apply(w_obj, b_obj, wN[o:], q[o:], False)
    for k in range(N):
        q[k] -= f * r_z[k]
    for j in range(e + 1):
        bx[j] = -f * r_x[j]
    _solve_kkt(D, m, e, L, w_lin, H_soc, H_obj, s_over_z, w_soc, b_soc, w_obj, b_obj, refine,
               bx, q, x2, z2, wN, wN2, wN3, wn, wn2)
    cx2_hz2 = x2[0]
    for k in range(N):
        cx2_hz2 += h[k] * z2[k]
    dtau = (d_kappa / tau - f * r_tau - cx2_hz2) / (cx1_hz1 - kappa / tau)
    for j in range(e + 1):
        dx[j] = x2[j] + dtau * x1[j]
    for k in range(N):
        dz[k] = z2[k] + dtau * z1[k]
    dkappa = -(d_kappa + kappa * dtau) / tau
    # ds from the primal row G dx + ds - h dtau = -(1 - sigma) r_z: it keeps the primal
    # residual exact where W^T W is badly conditioned near the optimum.
    _G_mul(D, m, e, dx, ds)
    for k in range(N):
        ds[k] = -f * r_z[k] - ds[k] + h[k] * dtau
    return dtau, dkappa


# --------------------------------------------------------------------------- one problem, built


@_jit
def _solve_one(rows, E, fp, mu, f_min, m, e, tol, reduced_tol, max_iter, step_fraction, stall_step, refine,
               retry_refine, violation_tol, y):
    """Build the contact rows of one GFO problem from its cone rows (m, 3, 3) (`_cone_rows`),
    basis E (3m, e) and f_p (3m,) (N) and solve it. Returns (code, ||f|| N, worst violation N, iterations); fills y.

    An optimal point whose forces violate a constraint by more than violation_tol max(1 N, ||f||)
    is 'not decided' (the rule of `solve_gfo` for reduced accuracy).
    """
    D = np.empty((m, 3, e))
    hv = np.empty((m, 3))
    a = np.zeros(e)
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
    for c in range(3 * m):
        for k in range(e):
            a[k] += E[c, k] * fp[c]
    r0 = 0.0
    for c in range(3 * m):
        acc = fp[c]
        for k in range(e):
            acc -= E[c, k] * a[k]
        r0 += acc * acc
    r0 = math.sqrt(r0)
    code, norm, viol, it = _attempt(D, hv, a, r0, mu, f_min, m, e, tol, reduced_tol, max_iter, step_fraction,
                                    stall_step, refine, violation_tol, y)
    if code == UNDECIDED and retry_refine > refine:
        # Undecided problems are mostly stalls at a degenerate optimum, where the normal
        # equations lose accuracy: a second attempt with iterative refinement decides most.
        code, norm, viol, it2 = _attempt(D, hv, a, r0, mu, f_min, m, e, tol, reduced_tol, max_iter, step_fraction,
                                         stall_step, retry_refine, violation_tol, y)
        it += it2
    return code, norm, viol, it


@_jit
def _attempt(D, hv, a, r0, mu, f_min, m, e, tol, reduced_tol, max_iter, step_fraction, stall_step, refine,
             violation_tol, y):
    """`_hsde`, then the force check of an optimal point: (code, ||f|| N, violation N, iterations)."""
    code, it = _hsde(D, hv, a, r0, f_min, m, e, tol, reduced_tol, max_iter, step_fraction, stall_step, refine, y)
    if code != OPTIMAL:
        return code, math.nan, math.nan, it
    # f = f_p + E y in the contact frames: [n.f, t1.f/mu, t2.f/mu]
    norm = 0.0
    viol = -math.inf
    fr = np.empty(3)
    for i in range(m):
        for r in range(3):
            acc = hv[i, r]
            for k in range(e):
                acc += D[i, r, k] * y[k]
            fr[r] = acc
        ft = mu * math.sqrt(fr[1] * fr[1] + fr[2] * fr[2])
        norm += fr[0] * fr[0] + ft * ft
        viol = max(viol, f_min - fr[0], ft - mu * fr[0])
    norm = math.sqrt(norm)
    if viol > violation_tol * max(1.0, norm):
        return UNDECIDED, math.nan, math.nan, it
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


@_jit
def _solve_sets(F_all, fp, frames, cols, n_cols, thresholds, mu, mu_strict, f_min, strict,
                tol, reduced_tol, max_iter, step_fraction, stall_step, refine, retry_refine, violation_tol,
                code, norm, viol, iters, e_s, strict_code, forces):
    """Every synergy set of one grasp: E_s from the SVD of F_s = F_all[:, set] (columns with a
    singular value above the set's threshold), then the GFO, its forces f_p + E_s y (N) and,
    if `strict`, the strict internal-force test (f_p = 0, f_min = 1 N, mu_strict). Sets with
    e_s = 0 get code NOT_SOLVED."""
    c = F_all.shape[0]
    m = c // 3
    rows = np.empty((m, 3, 3))
    rows_strict = np.empty((m, 3, 3))
    _cone_rows(frames, mu, rows)
    _cone_rows(frames, mu_strict, rows_strict)
    zero = np.zeros(c)
    y = np.empty(cols.shape[1])
    for j in range(cols.shape[0]):
        s = n_cols[j]
        F = np.empty((c, s))
        for q in range(s):
            F[:, q] = F_all[:, cols[j, q]]
        U, sv, _ = np.linalg.svd(F, full_matrices=False)
        rank = 0
        for q in range(sv.size):
            if sv[q] > thresholds[j]:
                rank += 1
        e_s[j] = rank
        if rank == 0:
            code[j] = NOT_SOLVED
            continue
        E = np.ascontiguousarray(U[:, :rank])
        code[j], norm[j], viol[j], iters[j] = _solve_one(
            rows, E, fp, mu, f_min, m, rank, tol, reduced_tol, max_iter, step_fraction, stall_step, refine,
            retry_refine, violation_tol, y)
        if code[j] == OPTIMAL:
            for k in range(c):
                acc = fp[k]
                for q in range(rank):
                    acc += E[k, q] * y[q]
                forces[j, k] = acc
        if strict:
            strict_code[j] = _solve_one(rows_strict, E, zero, mu_strict, 1.0, m, rank, tol, reduced_tol, max_iter,
                                        step_fraction, stall_step, refine, retry_refine, violation_tol, y)[0]


def _kernel_settings(settings: IPMSettings, violation_tol: float) -> tuple:
    return (float(settings.tol), float(settings.reduced_tol), int(settings.max_iter), float(settings.step_fraction),
            float(settings.stall_step), int(settings.refine), int(settings.retry_refine), float(violation_tol))


def solve_problem(frames: NDArray, E: NDArray, f_p: NDArray, mu: float, f_min: float, settings: IPMSettings,
                  violation_tol: float) -> tuple[int, float, NDArray, int]:
    """One problem: frames (m, 3, 3) from `mechanics.contact_frames`, E (3m, e) orthonormal
    with e >= 1, f_p (3m,) N, mu, f_min N. An optimal point whose forces violate a
    constraint by more than violation_tol max(1 N, ||f||) is UNDECIDED.
    Returns (code, ||f|| N, y (e,) N (NaN unless OPTIMAL), iterations)."""
    m, e = frames.shape[0], E.shape[1]
    rows = np.empty((m, 3, 3))
    _cone_rows(frames, float(mu), rows)
    y = np.full(e, np.nan)
    code, norm, _, iters = _solve_one(rows, np.ascontiguousarray(E, dtype=float), np.ascontiguousarray(f_p, dtype=float),
                                      float(mu), float(f_min), m, e, *_kernel_settings(settings, violation_tol), y)
    if code != OPTIMAL:
        y[:] = np.nan
    return int(code), float(norm), y, int(iters)


@dataclass(frozen=True)
class SetsResult:
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
               thresholds: NDArray, mu: float, mu_strict: float, f_min: float, strict: bool,
               settings: IPMSettings, violation_tol: float) -> SetsResult:
    """Every set of one grasp in one compiled call. F_all: (3m, k) projector @ S, N per
    unit activation; columns: (n_sets, max size) 0-based columns of F_all per set (the first
    n_columns[j] of row j); thresholds: (n_sets,) rank thresholds of the singular values."""
    n_sets = columns.shape[0]
    out = SetsResult(code=np.zeros(n_sets, dtype=np.int8), force_norm=np.full(n_sets, np.nan),
                     max_violation=np.full(n_sets, np.nan),
                     iterations=np.zeros(n_sets, dtype=np.int32), e_s=np.zeros(n_sets, dtype=np.int64),
                     strict_code=np.full(n_sets, INFEASIBLE, dtype=np.int8),
                     forces=np.full((n_sets, f_p.size), np.nan))
    _solve_sets(np.ascontiguousarray(F_all), np.ascontiguousarray(f_p, dtype=float), frames, columns, n_columns,
                thresholds, float(mu), float(mu_strict), float(f_min), bool(strict),
                *_kernel_settings(settings, violation_tol), out.code, out.force_norm, out.max_violation, out.iterations,
                out.e_s, out.strict_code, out.forces)
    return out
