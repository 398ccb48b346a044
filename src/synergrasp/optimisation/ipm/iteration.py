"""The kernel's iteration: one GFO problem by the homogeneous self-dual embedding with
Nesterov-Todd scaling and Mehrotra's predictor-corrector (`hsde`), its start point, Newton
directions, step lengths and corrector right-hand side."""

from __future__ import annotations

import math

from synergrasp.optimisation.ipm.certificates import (
    factor_rows,
    is_certificate,
    is_optimal,
    polished_certificate,
    proves_feasible,
)
from synergrasp.optimisation.ipm.compiled import jit_call, jit_inline
from synergrasp.optimisation.ipm.cone_algebra import lin_max_step, soc_apply, soc_div, soc_max_step, soc_prod
from synergrasp.optimisation.ipm.layout import INFEASIBLE, OPTIMAL, UNDECIDED, Homogeneous
from synergrasp.optimisation.ipm.linear_systems import G_mul, GT_mul, scaling, solve_kkt
from synergrasp.optimisation.ipm.polish import polish

__all__ = ["direction", "hsde"]


@jit_call
def direction(P, W, refine, hom, sigma, dsv, d_kappa, dx, dz, ds):
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
        soc_div(lam, dsv, wN, c, 3)
        soc_apply(W.w, W.beta[i], wN, q, c, 3, False)
    soc_div(lam, dsv, wN, o, e + 2)
    soc_apply(W.w, W.beta[n_soc], wN, q, o, e + 2, False)
    for k in range(N):
        q[k] -= f * W.r_z[k]
    for j in range(e + 1):
        W.bx[j] = -f * W.r_x[j]
    solve_kkt(P, W, refine, W.bx, q, W.x2, W.z2)
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
    G_mul(P, dx, ds)
    for k in range(N):
        ds[k] = -f * W.r_z[k] - ds[k] + W.h[k] * dtau
    return dtau, dkappa


@jit_inline
def max_step(P, W, ds, dz, tau, dtau, kappa, dkappa):
    """Largest step along (ds, dz, dtau, dkappa) that keeps (W.s, W.z, tau, kappa) in the cones."""
    q, L, s, z = P.q, P.L, W.s, W.z
    st = min(lin_max_step(tau, dtau), lin_max_step(kappa, dkappa))
    for i in range(q):
        st = min(st, lin_max_step(s[i], ds[i]), lin_max_step(z[i], dz[i]))
        c = L + 3 * i
        st = min(st, soc_max_step(s, ds, c, 3), soc_max_step(z, dz, c, 3))
    for k in range(q, L):
        st = min(st, lin_max_step(s[k], ds[k]), lin_max_step(z[k], dz[k]))
    o = L + 3 * q
    return min(st, soc_max_step(s, ds, o, P.e + 2), soc_max_step(z, dz, o, P.e + 2))


@jit_inline
def corrector_rhs(P, W, dtau_a, dkappa_a, tau, kappa, sm):
    """W.dsv: Mehrotra's second-order term (W^-T ds_a) o (W dz_a) and centring sigma mu
    (sm) added to lambda o lambda; returns the kappa row's counterpart."""
    q, L, e, s, z, lam, dsv = P.q, P.L, P.e, W.s, W.z, W.lam, W.dsv
    ds_a, dz_a, wN, wN2, wN3 = W.ds_a, W.dz_a, W.wN, W.wN2, W.wN3
    for k in range(L):
        dsv[k] = lam[k] * lam[k] + (math.sqrt(z[k] / s[k]) * ds_a[k]) * (math.sqrt(s[k] / z[k]) * dz_a[k]) - sm
    for i in range(q):
        c = L + 3 * i
        soc_apply(W.w, W.beta[i], ds_a, wN, c, 3, True)
        soc_apply(W.w, W.beta[i], dz_a, wN2, c, 3, False)
        soc_prod(wN, wN2, wN3, c, 3)
        soc_prod(lam, lam, dsv, c, 3)
        for r in range(3):
            dsv[c + r] += wN3[c + r]
        dsv[c] -= sm
    o, d = L + 3 * q, e + 2
    soc_apply(W.w, W.beta[q], ds_a, wN, o, d, True)
    soc_apply(W.w, W.beta[q], dz_a, wN2, o, d, False)
    soc_prod(wN, wN2, wN3, o, d)
    soc_prod(lam, lam, dsv, o, d)
    for r in range(d):
        dsv[o + r] += wN3[o + r]
    dsv[o] -= sm
    return tau * kappa + dtau_a * dkappa_a - sm


@jit_inline
def start(P, W):
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


@jit_call
def hsde(P, W, Q, opt, refine, y):
    """Solve one GFO problem by the homogeneous self-dual embedding with `refine` steps of
    iterative refinement per linear solve, Q the polish's work arrays (`layout.PolishWork`).
    Returns (code, iterations); fills y (N) when optimal.
    With opt.feasibility only whether the problem is feasible matters (the strict
    internal-force test): OPTIMAL as soon as an iterate proves it (`proves_feasible`; y is
    then that point, not the optimum)."""
    q, L, e, h, x, s, z = P.q, P.L, P.e, W.h, W.x, W.s, W.z
    o = L + 3 * q
    N, n = o + e + 2, e + 1
    rho, h_norm = start(P, W)
    Q.last[0] = -1  # no failed polish yet
    n_deg = float(L + q) + 1.0  # degree: L linear, q + 1 second-order cones
    tau = 1.0
    kappa = 1.0
    r_x, r_z, dsv = W.r_x, W.r_z, W.dsv
    stalled = False
    rows_factored = False

    for it in range(opt.max_iter + 1):
        GT_mul(P, z, r_x)
        gtz = 0.0
        for j in range(n):
            gtz += r_x[j] * r_x[j]
        gtz_norm = math.sqrt(gtz)
        r_x[0] += tau
        G_mul(P, x, r_z)
        if opt.feasibility and tau > 0.0 and proves_feasible(P, h, r_z, tau):
            for j in range(e):
                y[j] = x[1 + j] / tau * rho
            return OPTIMAL, it
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
        optimal = is_optimal(pres, dres, gap, pcost, opt.tol)
        infeasible = not optimal and is_certificate(hz, gtz_norm, opt.tol)
        if not (optimal or infeasible) and hz < 0.0:
            if not rows_factored:
                factor_rows(P, W)
                rows_factored = True
            infeasible = polished_certificate(P, W, opt.tol)
        # The active-set polish: where the iteration stalls, and early once it is near.
        near = max(pres, dres, gap / max(1.0, abs(pcost))) <= opt.polish_from
        if (
            ((last and opt.polish_from >= 0.0) or near)
            and not (optimal or infeasible)
            and polish(P, W, Q, tau, opt.tol, h_norm, y)
        ):
            for j in range(e):
                y[j] *= rho
            return OPTIMAL, it
        if last:
            optimal = optimal or is_optimal(pres, dres, gap, pcost, opt.reduced_tol)
            infeasible = infeasible or (not optimal and is_certificate(hz, gtz_norm, opt.reduced_tol))
        if optimal:
            for j in range(e):
                y[j] = x[1 + j] / tau * rho
            return OPTIMAL, it
        if infeasible:
            return INFEASIBLE, it
        if last or not (math.isfinite(mu) and math.isfinite(tau) and tau > 0.0):
            return UNDECIDED, it

        scaling(P, W)
        # x1, z1: the solution for the tau column, -c and h.
        for j in range(n):
            W.bx[j] = -1.0 if j == 0 else 0.0
        solve_kkt(P, W, refine, W.bx, h, W.x1, W.z1)
        cx1_hz1 = W.x1[0]
        for k in range(N):
            cx1_hz1 += h[k] * W.z1[k]
        hom = Homogeneous(tau, kappa, r_tau, cx1_hz1)

        # Predictor (affine scaling): d_s = lambda o lambda, d_kappa = tau kappa.
        for k in range(L):
            dsv[k] = W.lam[k] * W.lam[k]
        for i in range(q):
            soc_prod(W.lam, W.lam, dsv, L + 3 * i, 3)
        soc_prod(W.lam, W.lam, dsv, o, e + 2)
        # The predictor (sigma = 0, into the _a arrays), then the corrector with Mehrotra's
        # second-order term: one call of `direction` and `max_step` (each call site is
        # compiled again).
        sigma, d_kap, alpha, dtau, dkappa = 0.0, tau * kappa, 0.0, 0.0, 0.0
        dx, dz, ds = W.dx_a, W.dz_a, W.ds_a
        for corrector in range(2):
            if corrector:
                sigma = min(max((1.0 - alpha) ** 3, 0.0), 1.0)
                d_kap = corrector_rhs(P, W, dtau, dkappa, tau, kappa, sigma * mu)
                dx, dz, ds = W.dx, W.dz, W.ds
            dtau, dkappa = direction(P, W, refine, hom, sigma, dsv, d_kap, dx, dz, ds)
            step = max_step(P, W, ds, dz, tau, dtau, kappa, dkappa)
            alpha = min(1.0, opt.step_fraction * step if corrector else step)

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
