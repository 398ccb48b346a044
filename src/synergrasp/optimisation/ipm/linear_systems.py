"""The kernel's linear systems: the products with G, G^T and the NT scaling (W^T W)^-1 and
W^T W, the normal matrix G^T (W^T W)^-1 G with its Cholesky factor (`scaling`), and the
Newton system solved by the normal equations with optional iterative refinement
(`solve_kkt`). G maps x = (t, y) to the cone layout of `layout`."""

from __future__ import annotations

import math

from synergrasp.optimisation.ipm.compiled import jit_call, jit_inline
from synergrasp.optimisation.ipm.cone_algebra import soc_apply, soc_hessian, soc_nt

__all__ = ["GT_mul", "G_mul", "H_mul", "V_mul", "cho_solve", "cholesky", "reduced", "rows_T_col", "scaling", "solve_kkt"]


@jit_inline
def G_mul(P, x, out):
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


@jit_inline
def rows_T_col(P, z, j):
    """Entry j of A^T z for the constraint rows A = D, DL of y (G is -A on them)."""
    D, DL, q, L = P.D, P.DL, P.q, P.L
    acc = 0.0
    for i in range(q):
        c = L + 3 * i
        acc += D[i, 0, j] * (z[c] + z[i]) + D[i, 1, j] * z[c + 1] + D[i, 2, j] * z[c + 2]
    for k in range(P.nl):
        acc += DL[k, j] * z[q + k]
    return acc


@jit_inline
def GT_mul(P, z, out):
    """out = G^T z."""
    o = P.L + 3 * P.q
    out[0] = -z[o]
    for j in range(P.e):
        out[1 + j] = -z[o + 2 + j] - rows_T_col(P, z, j)


@jit_inline
def H_mul(P, W, v, out):
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


@jit_inline
def V_mul(P, W, v, tmp, out):
    """out = W^T W v through the scaling factors (iterative refinement)."""
    q, L = P.q, P.L
    for k in range(L):
        out[k] = W.s_over_z[k] * v[k]
    for i in range(q):
        c = L + 3 * i
        soc_apply(W.w, W.beta[i], v, tmp, c, 3, False)
        soc_apply(W.w, W.beta[i], tmp, out, c, 3, False)
    o = L + 3 * q
    soc_apply(W.w, W.beta[q], v, tmp, o, P.e + 2, False)
    soc_apply(W.w, W.beta[q], tmp, out, o, P.e + 2, False)


@jit_call
def cholesky(M, L, n):
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


@jit_call
def cho_solve(L, n, b, x):
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


@jit_inline
def reduced(P, W, bx, bz, dx, dz):
    """[0 G^T; G -W^T W] [dx; dz] = [bx; bz] by the normal equations."""
    wN, wn = W.wN, W.wn
    H_mul(P, W, bz, wN)
    GT_mul(P, wN, wn)
    for j in range(P.e + 1):
        wn[j] += bx[j]
    cho_solve(W.L, P.e + 1, wn, dx)
    G_mul(P, dx, wN)
    for k in range(P.L + 3 * P.q + P.e + 2):
        wN[k] -= bz[k]
    H_mul(P, W, wN, dz)


@jit_call
def solve_kkt(P, W, refine, bx, bz, dx, dz):
    """The Newton system for (bx, bz), with `refine` steps of iterative refinement. One call
    of `reduced` (inlined): each inlined copy is compiled again."""
    n, N = P.e + 1, P.L + 3 * P.q + P.e + 2
    wN2, wN3, wn2 = W.wN2, W.wN3, W.wn2
    for step in range(refine + 1):
        rx, rz, ox, oz = bx, bz, dx, dz
        if step > 0:
            # residual of the full system, then a correction from the same factorisation
            G_mul(P, dx, wN2)
            V_mul(P, W, dz, W.wN, wN3)
            for k in range(N):
                wN2[k] = bz[k] - wN2[k] + wN3[k]
            GT_mul(P, dz, wn2)
            for j in range(n):
                wn2[j] = bx[j] - wn2[j]
            rx, rz, ox, oz = wn2, wN2, W.ex, W.ez
        reduced(P, W, rx, rz, ox, oz)
        if step > 0:
            for j in range(n):
                dx[j] += W.ex[j]
            for k in range(N):
                dz[k] += W.ez[k]


@jit_inline
def scaling(P, W):
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
        W.beta[i] = soc_nt(s, z, W.w, c, 3)
        soc_apply(W.w, W.beta[i], z, W.lam, c, 3, False)
        soc_hessian(W.w, W.beta[i], c, 3, H3, 3 * i)
    W.beta[q] = soc_nt(s, z, W.w, o, e + 2)
    soc_apply(W.w, W.beta[q], z, W.lam, o, e + 2, False)
    soc_hessian(W.w, W.beta[q], o, e + 2, H_obj, 0)
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
    cholesky(M, W.L, e + 1)
