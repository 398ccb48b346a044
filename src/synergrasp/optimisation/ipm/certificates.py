"""The kernel's stopping tests and infeasibility certificates: an optimal point by its
residuals and gap, a Farkas certificate from the dual iterate, and the polished
certificate (the dual iterate moved onto G^T z = 0 and checked in the cones)."""

from __future__ import annotations

import math

from synergrasp.optimisation.ipm.compiled import jit_call, jit_inline
from synergrasp.optimisation.ipm.linear_systems import cho_solve, cholesky, rows_T_col

__all__ = ["factor_rows", "is_certificate", "is_optimal", "polished_certificate", "proves_feasible"]


@jit_call
def is_optimal(pres, dres, gap, pcost, eps):
    return pres <= eps and dres <= eps and (gap <= eps or gap <= eps * abs(pcost))


@jit_call
def is_certificate(hz, gtz_norm, eps):
    """The dual iterate proves infeasibility (Farkas): h^T z < 0 and ||G^T z|| <= eps |h^T z|."""
    return hz < 0.0 and gtz_norm <= eps * -hz


@jit_inline
def inside(P, h, Gx, tau):
    """Whether the slack h tau - G x lies strictly inside the nonnegative block and every
    Coulomb cone (the objective cone aside: t can grow). Gx: G x in the cone layout."""
    for k in range(P.L):
        if not h[k] * tau - Gx[k] > 0.0:
            return False
    for i in range(P.q):
        c = P.L + 3 * i
        v0, v1, v2 = h[c] * tau - Gx[c], h[c + 1] * tau - Gx[c + 1], h[c + 2] * tau - Gx[c + 2]
        if not v0 > math.sqrt(v1 * v1 + v2 * v2):
            return False
    return True


@jit_call
def proves_feasible(P, h, Gx, tau):
    """Whether x = (t, y) proves the problem feasible: y / tau satisfies every constraint
    strictly, or y is a strictly interior direction (-G x = A y inside every cone, so
    h + lambda A y is inside them for lambda large enough, whatever h). The second is what
    the strict internal-force test asks (some E y strictly inside every cone). Needs tau > 0."""
    return inside(P, h, Gx, tau) or inside(P, h, Gx, 0.0)


@jit_inline
def factor_rows(P, W):
    """W.R_rows: Cholesky factor of A^T A (e, e) for the constraint rows A = D, DL of y (a
    contact's linear row is its D row 0, hence the 2). Scratch: W.M (refilled by `scaling`)."""
    D, DL, A = P.D, P.DL, W.M
    for j in range(P.e):
        for l in range(j + 1):
            acc = 0.0
            for i in range(P.q):
                acc += 2.0 * D[i, 0, j] * D[i, 0, l] + D[i, 1, j] * D[i, 1, l] + D[i, 2, j] * D[i, 2, l]
            for k in range(P.nl):
                acc += DL[k, j] * DL[k, l]
            A[j, l] = acc
    cholesky(A, W.R_rows, P.e)


@jit_inline
def polished_certificate(P, W, eps):
    """Whether the dual iterate's constraint part, moved to the nearest point (Euclidean)
    with G^T z = 0 and its objective part set to 0, is a Farkas certificate: inside the
    cones, h^T z < 0 and ||G^T z|| <= eps |h^T z| recomputed on the moved point. Such a
    point proves infeasibility on its own (z^T s = h^T z < 0 for every s = h - G x is
    impossible with z and s in the self-dual cones), so the iteration can stop as soon as
    the dual iterate is that close to one instead of when the homogeneous iterate has
    converged. Needs `factor_rows`; scratch: W.wn, W.ex, W.wN2."""
    q, L, e, D, DL, z = P.q, P.L, P.e, P.D, P.DL, W.z
    g, u, zc = W.wn, W.ex, W.wN2
    for j in range(e):
        g[j] = rows_T_col(P, z, j)
    cho_solve(W.R_rows, e, g, u)
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
        acc = rows_T_col(P, zc, j)
        gtz += acc * acc
    return is_certificate(hz, math.sqrt(gtz), eps)
